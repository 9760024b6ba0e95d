"""The search window of the modal solve: where to shift and how many eigenvalues
to ask for, from the classical spectra (:mod:`.analytic`) with their modal damping.

Only the lowest ``per_family``
oscillating modes of each family are wanted, never the whole spectrum.
:func:`estimates` gives every eigenvalue of the classical models (solvers.
analytic) with their modal damping (the drag of Eq. 28 and the Kelvin-Voigt
shares of forms/damping.py, tests/test_damping.py): both roots of
lambda^2 + c lambda + omega^2 = 0.  Structural damping makes every mode above
omega ~ 2 / tau overdamped, and their slow roots -omega^2 / c crowd at
-1 / tau on the negative real axis (hundreds of them at N = 32: a cluster that
no Krylov method converges in reasonable time, and need not).  PETSc here is
real, so the target tau is real; shift-and-invert computes the eigenvalues
nearest it, i.e. those in a disk |lambda - tau| <= rho.  :func:`search_window`
(:meth:`ModalSolver.window`) takes tau >= omega_min / 4 (off the rigid zero, where K is singular, and away
from every eigenvalue of a stable state, Re lambda <= 0) where the disk that
holds every wanted estimate with margin (rho = WINDOW_MARGIN x the farthest,
clipped half-way to the nearest real root beyond) holds the fewest estimates;
a positive tau pushes the cluster on the negative real axis back (its distance
is tau + 1/tau_d) while the lightly damped wanted modes stay near.  Without
structural damping that is tau = omega_min / 4 and nev = the modes below
1.2 x the highest wanted one, as before.  nev is the count in the disk; ``cap``
the estimated count before the nearest real root beyond, past which the solve
(:mod:`.modal`) never widens the search.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rawehelix.models.kinematics import get as kinematics_named
from rawehelix.solvers import analytic

#: the search disk holds the farthest wanted estimate with this margin (unless a
#: real root lies nearer; then half-way to it)
WINDOW_MARGIN = 1.2
#: eigenvalues asked for beyond the estimated count when no real root is near
WINDOW_EXTRA = 4
#: targets tried between omega_min / 4 and this multiple of the highest wanted |lambda|
TARGET_SPAN, TARGET_STEPS = 4.0, 33


def estimates(q, tension: float, count: int, twist: bool = True,
              kinematics: str = "paper") -> dict:
    """Eigenvalue estimates, per family an array (count, 2) for n = 1..count:
    the roots of lambda^2 + c_n lambda + omega_n^2 = 0 (normalised), omega_n
    of the classical models (solvers.analytic) and c_n the modal damping:

    * drag (28), linearised: c = nu v_w0 (1 + (e.i_E)^2), e the direction of
      the motion (chord, j_E x chord, j_E), tests/test_modal.py;
    * Kelvin-Voigt (forms/damping.py): the retardation time x the mechanism's
      share of omega_n^2 (tests/test_damping.py): tau_a sigma k^2 + tau_b mu k^4
      (longitudinal; the bending share where the kinematics has it, the paper's:
      models/kinematics.py, ``kinematics`` its name),
      tau_b mu k^4 (lateral), tau_t delta k^2 (torsional).

    An oscillating pair is (lambda, conj lambda), an overdamped one two real roots."""
    n = np.arange(1, count + 1)
    k = n * np.pi
    mu = q.bending * q.mu
    chord = q.top_position() / np.linalg.norm(q.top_position())
    direction = {"longitudinal": chord, "lateral_in_plane": np.cross([0.0, 1.0, 0.0], chord),
                 "lateral_out_of_plane": np.array([0.0, 1.0, 0.0])}
    omega = analytic.frequencies(q, tension, count, twist)
    bending = q.tau_bending * mu * k**4
    kelvin_voigt = {"longitudinal": q.tau_axial * q.sigma * k**2
                    + (bending if kinematics_named(kinematics).bending_in_axial_damping else 0.0),
                    "lateral_in_plane": bending, "lateral_out_of_plane": bending,
                    "torsional": q.tau_torsion * q.delta * k**2}
    out = {}
    for family, w in omega.items():
        e = direction.get(family)
        c = kelvin_voigt[family] + (0.0 if e is None else q.drag * q.nu * q.v_w0 * (1 + e[0]**2))
        root = np.sqrt((c / 2) ** 2 - w**2 + 0j)
        out[family] = np.stack([-c / 2 + root, -c / 2 - root], axis=1)
    return out


@dataclass(frozen=True)
class Window:
    """Where and how much to search: shift-and-invert about ``target``, ``nev``
    eigenvalues; ``cap``: the most nev may be widened to (the estimated count
    before the nearest real root beyond the wanted ones)."""

    target: float
    nev: int
    cap: int

    def __post_init__(self):
        if not (self.target > 0 and 1 <= self.nev <= self.cap):
            raise ValueError(f"bad search window {self}")


def search_window(est: dict, finite: int, base: float, per_family: int) -> Window:
    """The target and nev that hold the lowest ``per_family`` oscillating modes of
    each family of the estimates ``est`` (:func:`estimates`) with the fewest others
    (module docstring); ``finite`` the count of finite eigenvalues, ``base`` the
    lowest target tried (omega_min / 4)."""
    wanted, every = [], [0.0, 0.0]  # the rigid rotation's Jordan pair
    for roots in est.values():
        upper = roots[:, 0]
        wanted += list(upper[upper.imag > 0][:per_family])
        every += list(roots.ravel())
    wanted, every = np.array(wanted), np.array(every)
    real = every[np.abs(every.imag) == 0]
    top = max(np.abs(wanted).max(), base) if wanted.size else base
    best = None
    for tau in base * np.geomspace(1.0, max(TARGET_SPAN * top / base, 1.0), TARGET_STEPS):
        far = np.abs(wanted - tau).max() if wanted.size else tau
        beyond = np.abs(real - tau)
        beyond = beyond[beyond > far]
        nearest = beyond.min() if beyond.size else math.inf
        rho = min(WINDOW_MARGIN * far, 0.5 * (far + nearest))
        inside = int(np.sum(np.abs(every - tau) <= rho))
        key = (inside, -rho / far)  # fewest eigenvalues, then the widest margin
        if best is None or key < best[0]:
            extra = WINDOW_EXTRA if rho == WINDOW_MARGIN * far else 0
            cap = int(np.sum(np.abs(every - tau) < nearest)) if beyond.size else finite - 2
            best = (key, tau, inside + extra, cap)
    _, tau, nev, cap = best
    cap = min(max(cap, nev), finite - 2)
    return Window(target=float(tau), nev=min(nev, cap), cap=cap)
