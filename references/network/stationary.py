"""The network's stationary state: Newton on the energy's gradient with its analytic
Hessian (:mod:`.energy`) and a backtracking (Armijo) line search on the energy, from
the straight elongated chord (Newton's step is a descent direction where the Hessian
is positive definite; elsewhere, at slack or a buckled bar, it is shifted by a
multiple of its diagonal until it is one).

Converged: the largest free force below ``FORCE_TOL`` n k (moments counted as forces
at the radius R, M / R).  :func:`solve` raises :class:`.NetworkError` naming why it
did not converge and what to try.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from rawehelix.references.network import energy as en
from rawehelix.references.network.network import Network, NetworkError

#: converged: the largest free force [N] (moment / R) below FORCE_TOL x n k
FORCE_TOL = 1e-11
#: Armijo's sufficient decrease, and the most halvings of a step
ARMIJO, HALVINGS = 1e-4, 40
#: the energy's round-off, relative to its terms: a step that changes it by less is
#: taken whole (near convergence Newton's decrease, ~ r^2 / k, is below it)
ENERGY_NOISE = 1e-13


@dataclass
class StationaryNetwork:
    """The network's stationary state (SI)."""

    network: Network
    state: en.State  # ring centres X [m], rotations R, top turn theta [rad]
    tether_forces_N: np.ndarray  # (bays, n) [N]
    bar_forces_N: np.ndarray  # (bays,) [N], tension positive
    iterations: int
    residual_N: float  # the largest free force at the end [N]

    @property
    def positions_m(self) -> np.ndarray:
        return self.state.X

    @property
    def rotations(self) -> np.ndarray:
        return self.state.R

    @property
    def smallest_tether_force(self) -> tuple[float, int, int]:
        """(f_min [N], its bay (0: at the ground), its tether)."""
        b, m = np.unravel_index(int(np.argmin(self.tether_forces_N)), self.tether_forces_N.shape)
        return float(self.tether_forces_N[b, m]), int(b), int(m)

    @property
    def slack(self) -> list[tuple[int, int]]:
        """(bay, tether) of every slack tether (force 0)."""
        return [tuple(int(i) for i in x) for x in np.argwhere(self.tether_forces_N <= 0)]

    def bay_forces_N(self) -> np.ndarray:
        """(bays, 3) [N]: the force the upper part pulls each bay's lower ring with
        (every tether's and the bar's), in the fixed frame."""
        pa, pb, d = en.tether_chords(self.network, self.state)
        u = d / np.linalg.norm(d, axis=-1)[..., None]
        ub = self.state.X[1:] - self.state.X[:-1]
        ub /= np.linalg.norm(ub, axis=-1)[:, None]
        return (self.tether_forces_N[..., None] * u).sum(axis=1) + self.bar_forces_N[:, None] * ub

    def tension_N(self) -> np.ndarray:
        """(bays,) [N]: each bay's axial force, its force along the line of its ring
        centres (the continuum's T at the bay's middle)."""
        ub = self.state.X[1:] - self.state.X[:-1]
        ub /= np.linalg.norm(ub, axis=-1)[:, None]
        return np.einsum("bi,bi->b", self.bay_forces_N(), ub)

    def sag_m(self) -> float:
        """The largest distance of a ring centre from the chord [m]."""
        e = self.network.chord_m / np.linalg.norm(self.network.chord_m)
        X = self.state.X
        return float(np.max(np.linalg.norm(X - np.outer(X @ e, e), axis=1)))

    def summary(self) -> dict:
        f_min, bay, tether = self.smallest_tether_force
        T = self.tension_N()
        return {"rings": self.network.count, "spacing_m": self.network.spacing_m,
                "sag_m": self.sag_m(), "tension_ground_N": float(T[0]),
                "tension_top_N": float(T[-1]), "smallest_tether_force_N": f_min,
                "smallest_at_bay": bay, "smallest_at_tether": tether,
                "slack_tethers": len(self.slack), "iterations": self.iterations}


def _scaled(net: Network, r: np.ndarray, P: sp.csr_matrix) -> float:
    """The largest free force [N], moments / R."""
    scale = P.T @ np.tile([1, 1, 1, 1 / net.radius_m, 1 / net.radius_m, 1 / net.radius_m],
                          net.count)
    return float(np.max(np.abs(r * scale), initial=0.0))


def _descent_step(H: sp.csr_matrix, r: np.ndarray) -> np.ndarray:
    """-H^-1 r, or -(H + lambda diag(H))^-1 r with the smallest tried lambda (1e-8 up
    by 10) that makes it a descent direction; None when none does."""
    D = sp.diags(np.abs(H.diagonal()) + 1e-300)
    for shift in [0.0] + [10.0 ** e for e in range(-8, 3)]:
        try:
            with np.errstate(all="raise"), warnings.catch_warnings():
                warnings.simplefilter("error", spla.MatrixRankWarning)  # singular: next shift
                step = -spla.spsolve((H + shift * D).tocsc(), r)
        except (RuntimeError, FloatingPointError, ValueError, spla.MatrixRankWarning):
            continue
        with np.errstate(all="ignore"):  # a near-singular shift's step may overflow
            if np.all(np.isfinite(step)) and np.isfinite(step @ r) and step @ r < 0:
                return step
    return None


def solve(net: Network, state: en.State | None = None, max_iterations: int = 100) -> StationaryNetwork:
    """The stationary state from ``state`` (default: the straight chord,
    :meth:`Network.reference`).  NetworkError when Newton does not converge."""
    s = state.copy() if state is not None else en.State(*net.reference())
    P = en.free_basis(net)
    tol = FORCE_TOL * net.n * net.k_N
    E = en.energy(net, s)
    for it in range(max_iterations + 1):
        g, H = en.gradient_hessian(net, s)
        r = P.T @ g
        res = _scaled(net, r, P)
        if res <= tol:
            return StationaryNetwork(net, s, en.tether_forces(net, s), en.bar_forces(net, s),
                                     it, res)
        if it == max_iterations:
            break
        step = _descent_step((P.T @ H @ P).tocsr(), r)
        if step is None:
            raise NetworkError(
                f"the network's Newton found no descent direction at iteration {it} (largest "
                f"force {res:.3g} N): its stiffness is singular, a ring held by slack tethers "
                "only; give the ends more elongation (ends.elongation) or the tethers a "
                "self-stress (section.self_stress_N with section.bar_EA_N)")
        slope, alpha = float(step @ r), 1.0
        noise = ENERGY_NOISE * (abs(E) + float(np.abs(net.loads_N * s.X).sum()))  # round-off [J]
        for _ in range(HALVINGS):
            with np.errstate(all="ignore"):  # a long step's energy may overflow: halve it
                trial = en.moved(net, s, P @ (alpha * step))
                E_trial = en.energy(net, trial)
            if E_trial <= E + ARMIJO * alpha * slope + noise:  # False for nan
                break
            alpha /= 2
        else:
            raise NetworkError(
                f"the network's line search found no decrease of the energy at iteration {it} "
                f"(largest force {res:.3g} N): its tethers go slack along the step, the load "
                "past what they carry near the straight chord (a top torque that unwinds the "
                "lay collapses it); lower torque.top_Nm or the wind, or give the tethers a "
                "self-stress (section.self_stress_N with section.bar_EA_N)")
        s, E = trial, E_trial
    raise NetworkError(
        f"the network's Newton did not converge in {max_iterations} iterations (largest force "
        f"{res:.3g} N against {tol:.3g} N): the end torque, or the lay's turn per bay "
        "(l tan(beta) / R against Tulloch's collapse angle), may be near the bays' collapse; "
        "lower torque.top_Nm or give more rings (section.rings)")
