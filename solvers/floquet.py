"""Periodic orbits by shooting, scheme-independent: the shooting Newton, the
twist's rotation per period and the Floquet multipliers of an orbit.

A scheme supplies the period map (:meth:`PeriodMap.period`: the state after
one forcing period, the tension at s = 0 over it and, on request, the
monodromy dP/dX), ``e_alpha`` (a uniform unit twist in its state),
``controller``, ``q_base`` (the scene's normalised parameters, the torque at
its final value), ``q`` (at the current f1) and ``steps_per_period``:

- the FE generalised-alpha map, :class:`rawehelix.solvers.orbits.AlphaMap`;
- the paper's spline-Galerkin flow,
  :class:`rawehelix.solvers.spline_galerkin.orbits.SplineMap`.

Here, with Delta the rotation per period:

    G(X) = P(X) - X - Delta e_alpha = 0                          (shooting)

No FE code (numpy only), so that the spline reference stays free of it.
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np

from rawehelix.errors import SolverError

BACKTRACK_MIN = 1.0 / 32  # the shortest fraction of a Newton step the shooting tries


@dataclasses.dataclass
class Orbit:
    """A periodic orbit at one f1 (normalised state, SI outputs)."""

    f1_Hz: float
    X: np.ndarray  # (U, V, A) at the start of the period, phase 0
    delta: float  # twist rotation per period (normalised)
    tension_max_N: float
    tension_min_N: float
    multipliers: np.ndarray  # Floquet multipliers, by decreasing modulus (the
    # free twist rotation's pair without a controller set aside: symmetry_multiplier)
    newton_iterations: int
    residual: float  # |G| / |X| at the orbit
    steps: int  # steps per period
    wall_s: float
    monodromy: np.ndarray | None = dataclasses.field(default=None, repr=False)  # dP/dX at X
    symmetry_multiplier: complex | None = None  # the free rotation's pair (no controller)

    @property
    def max_multiplier(self) -> float:
        return float(np.abs(self.multipliers[0]))

    @property
    def stable(self) -> bool:
        return self.max_multiplier < 1.0

    def entry(self) -> dict:
        return {"f1_Hz": self.f1_Hz, "tension_max_N": self.tension_max_N,
                "tension_min_N": self.tension_min_N, "stable": self.stable,
                "max_multiplier": self.max_multiplier,
                "newton_iterations": self.newton_iterations, "residual": self.residual,
                "steps_per_period": self.steps, "wall_s": self.wall_s}


class PeriodMap:
    """Shooting on a scheme's period map (see the module's docstring)."""

    def period(self, X, f1_Hz: float, tangent: bool = False, steps: int | None = None,
               on_step=None):
        raise NotImplementedError

    def rotation(self, f1_Hz: float) -> float:
        """Delta = alpha_dot* T1: the twist's rotation per period fixed by the
        controller (k1 > 0, Eq. 40); T1 = 1 / (f1 t_scale), normalised."""
        return self.q_base.spin_target / (f1_Hz * self.q_base.t_scale)

    def shooting_residual(self, X, f1_Hz: float, delta: float, tangent: bool = False,
                          steps: int | None = None):
        """G(X) = P(X) - X - Delta e_alpha, the tension over the period and (with
        ``tangent``) the monodromy."""
        PX, tension, Phi = self.period(X, f1_Hz, tangent=tangent, steps=steps)
        return PX - X - delta * self.e_alpha, tension, Phi

    # -- shooting ----------------------------------------------------------------
    def orbit(self, X0, f1_Hz: float, tol: float = 1e-7, max_it: int = 12, lead_in: int = 0,
              steps: int | None = None) -> Orbit:
        """Newton on G(X) = P(X) - X - Delta e_alpha = 0 (chord: the monodromy is
        refreshed when an iteration contracts |G| by less than 10x), backtracking:
        where |G| does not fall after a step (or the period map fails), a chord step
        is redone from its start with a fresh monodromy and a Newton step is
        halved, down to BACKTRACK_MIN of itself."""
        start = time.perf_counter()
        self.newton_iterations = 0
        X = X0.copy()
        for _ in range(lead_in):
            X, _, _ = self.period(X, f1_Hz)
        e = self.e_alpha
        delta = self.rotation(f1_Hz) if self.controller else 0.0
        mono, last, its = None, np.inf, 0
        back = None  # (X, delta, step, fraction, fresh monodromy) of the last step taken
        for its in range(1, max_it + 1):
            need = mono is None
            try:
                G, _, Phi = self.shooting_residual(X, f1_Hz, delta, tangent=need, steps=steps)
                res = np.linalg.norm(G) / max(1.0, np.linalg.norm(X))
            except SolverError:  # the step's Newton failed from this X
                G, res = None, np.inf
            if back is not None and not res < last:  # no descent
                X0_, d0, step, frac, fresh = back
                if not fresh:  # the chord's monodromy was stale: Newton from there
                    X, delta, mono, back, last = X0_, d0, None, None, np.inf
                    continue
                if frac < BACKTRACK_MIN:  # half the Newton step, down to this
                    raise SolverError(f"orbits: shooting at f1 = {f1_Hz} Hz found no descent "
                                      f"along its Newton step (|G|/|X| = {last:.3g}); start "
                                      f"nearer the orbit (a lower f1, or more lead-in periods)")
                frac /= 2
                X, delta = X0_ - frac * step[:-1], d0 - frac * step[-1]
                back = (X0_, d0, step, frac, fresh)
                continue
            if G is None:
                raise SolverError(f"orbits: the period map failed from the shooting's "
                                  f"start at f1 = {f1_Hz} Hz")
            if need:
                mono = Phi
            if res <= tol:
                break
            A = mono - np.eye(X.size)
            if res > 0.1 * last and not need:
                mono = None  # slow: a fresh monodromy at the next iteration
            last = res
            if self.controller:
                step = np.append(np.linalg.solve(A, G), 0.0)
            else:  # unknowns (X, Delta); phase: e . (X - X_prev) = 0.  Without torque
                # the spin is free too (a family of orbits): the least-squares step
                K = np.block([[A, -e[:, None]], [e[None, :], np.zeros((1, 1))]])
                step = np.linalg.lstsq(K, np.concatenate([G, [0.0]]), rcond=None)[0]
            back = (X, delta, step, 1.0, need)
            X, delta = X - step[:-1], delta - step[-1]
        else:
            raise SolverError(f"orbits: shooting did not converge at f1 = {f1_Hz} Hz in "
                              f"{max_it} iterations (|G|/|X| = {res:.3g} > {tol:g})")
        return self.finish(X, f1_Hz, delta, its, res, start, steps)

    def finish(self, X, f1_Hz, delta, its, res, start, steps=None) -> Orbit:
        """The orbit through X: one more period with the tangent gives the
        Floquet multipliers at the orbit itself, and the tension over it."""
        _, tension, Phi = self.period(X, f1_Hz, tangent=True, steps=steps)
        mu = np.linalg.eigvals(Phi)
        symmetry = None
        if not self.controller:
            # the free rotation alpha -> alpha + c and the uniform spin that drives it
            # form a Jordan block of the multiplier 1; round-off eps splits it into
            # 1 +- sqrt(eps): the pair is set aside, and reported by its mean
            pair = np.argsort(np.abs(mu - 1.0))[:2]
            symmetry = complex(np.mean(mu[pair]))
            mu = np.delete(mu, pair)
        mu = mu[np.argsort(-np.abs(mu))]
        T = self.q.tension_N(tension)
        orbit = Orbit(f1_Hz=f1_Hz, X=X, delta=delta, tension_max_N=float(T.max()),
                      tension_min_N=float(T.min()), multipliers=mu, newton_iterations=its,
                      residual=float(res), steps=steps or self.steps_per_period(f1_Hz),
                      wall_s=time.perf_counter() - start, monodromy=Phi,
                      symmetry_multiplier=symmetry)
        return orbit
