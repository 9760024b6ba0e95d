"""Stationary state of Eq. (61): Newton on f(x_s) = 0 (Sec. 5.1).

The stationary state of Sec. 5.1 is planar with qdot = 0, alpha = 0 and
m0 = mN = 0, so only the interior node positions r_1..r_{N-1} are unknown;
the twist rows and the controller row vanish identically there.  Newton's
matrix is the complex-step Jacobian of the centre-line rows of g.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from .system import SplineGalerkin


@dataclass
class Stationary:
    x: np.ndarray  # state vector x_s* of Eq. (60)
    iterations: int
    residual: float  # |g(x_s*)|
    start: str  # "shooting" or "chord"


#: the wall time the shooting first guess may take [s]; past it Newton starts from the chord
FIRST_GUESS_BUDGET_S = 10.0


@functools.lru_cache(maxsize=8)
def _shooting(nd):
    """The shooting solution of Sys. (67) for ``nd`` (cached), or None where it does
    not serve as a first guess: ``rawehelix.references.shooting`` not available, a
    scene off the x-z plane or too stiff for it (more than its MAX_SEGMENTS), or a
    shooting that fails or runs past :data:`FIRST_GUESS_BUDGET_S`."""
    try:
        from rawehelix.references import shooting
    except ImportError:
        return None
    if shooting.not_applicable(nd) or shooting.default_segments(nd) > shooting.MAX_SEGMENTS:
        return None
    try:
        with shooting.budget(FIRST_GUESS_BUDGET_S):
            return shooting.solve(nd)
    except (shooting.OverBudget, RuntimeError, ValueError):
        return None


def shooting_nodes(system: SplineGalerkin):
    """Interior node positions from the shooting solution (Sys. 67), or None."""
    sol = _shooting(system.nd)
    if sol is None:
        return None
    s = np.arange(1, system.N) / system.N
    return np.asarray(sol.centre_line(s), dtype=float).reshape(-1, 3)


def chord_nodes(system: SplineGalerkin, t: float = 0.0) -> np.ndarray:
    """Interior nodes on the straight chord from r_0 = 0 to r_N (Eq. 66)."""
    s = np.arange(1, system.N) / system.N
    return np.outer(s, system.nd.top_position(t))


def residual_norm(system: SplineGalerkin, r_int, t: float = 0.0) -> float:
    """|g(x_s)| for the state with nodes r_int, qdot = 0, alpha = 0, m0 = 0."""
    return float(np.linalg.norm(system.g(system.pack(r_int, np.zeros(system.n_a)), t)))


def solve(system: SplineGalerkin, start=None, t: float = 0.0, tol: float = 1e-14,
          max_iter: int = 30) -> Stationary:
    """Newton-Raphson on the centre-line rows of g (Eq. 55 with rddot = rdot = 0).

    Parameters
    ----------
    start : (N-1, 3) interior nodes; default the shooting solution, else the chord.
    tol : stop when |g| < tol * (sigma + |g(start)|), when the Newton step is
        below 1e-13 |r|, or when |g| < 1e-9 (sigma + |g(start)|) stops falling:
        the rounding floor, since the axial stiffness sigma ~ 1e4 multiplies
        every strain.
    """
    label = "given"
    if start is None:
        start = shooting_nodes(system)
        label = "shooting"
        if start is None:
            start, label = chord_nodes(system, t), "chord"
    n_r, n_q = system.n_r, system.n_q
    rows = slice(n_q, n_q + n_r)
    zero_a = np.zeros(system.n_a)

    def res(y):
        return system.g(system.pack(y, zero_a) if np.isrealobj(y) else _pack_c(system, y), t)[rows]

    y = np.asarray(start, dtype=float).ravel().copy()
    r = res(y)
    scale = system.nd.sigma + np.linalg.norm(r)
    h = 1e-30
    for it in range(1, max_iter + 1):
        J = np.stack([res(y + 1j * h * e).imag / h for e in np.eye(n_r)], axis=1)
        step = np.linalg.solve(J, r)
        y = y - step
        r_old, r = np.linalg.norm(r), res(y)
        small = np.linalg.norm(r) < tol * scale or np.linalg.norm(step) < 1e-13 * (1 + np.linalg.norm(y))
        stalled = np.linalg.norm(r) < 1e-9 * scale and np.linalg.norm(r) > 0.5 * r_old
        if small or stalled:  # stalled: Newton has reached the rounding floor
            break
    else:
        raise RuntimeError(f"Newton did not converge: |g| = {np.linalg.norm(r):.3e}")
    x = system.pack(y, zero_a)
    return Stationary(x=x, iterations=it, residual=float(np.linalg.norm(system.g(x, t))),
                      start=label)


def _pack_c(system, y):
    x = np.zeros(system.size, dtype=complex)
    x[:system.n_r] = y
    return x
