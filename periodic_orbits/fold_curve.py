"""Folds of periodic orbits continued in a second parameter p: the boundary of the
band where two stable responses coexist, on any periodic-orbit problem
(:class:`~rawehelix.periodic_orbits.problem.PeriodicOrbitProblem`; AUTO and
BifurcationKit continue limit points of cycles the same way).

At a fold G(X, f1) = 0 and G_X is singular.  The minimally augmented system
(Govaerts 2000, Sec. 4.1) adds one scalar g(X, f1), zero exactly there, from the
bordered system

    [[G_X, b], [c^T, 0]] [v; g] = [0; 1],   [[G_X^T, c], [b^T, 0]] [w; g] = [0; 1],

(b, c: the null vectors at the last fold, so that the border is regular), whose
gradient needs only G_X at one more state:

    g_X = -w^T G_XX v = -(G_X(X + e v)^T w - G_X(X)^T w) / e,
    g_f1 = -(w^T G_X(X, f1 + h) v - w^T G_X(X, f1) v) / h.

Newton on (G, g) = 0 in (X, f1) at fixed p (:func:`locate`); :func:`trace` steps p
from fold to fold (natural continuation, the step halved where Newton fails).
Where the two folds of a resonance meet (a cusp) the band closes and the
natural continuation ends: the trace reports where.  numpy and scipy only.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import scipy.sparse

from rawehelix.errors import SolverError

EPS = 1e-7  # the finite difference of G_X along v (relative to |X|)
STEP_TOL = 1e-10  # Newton's correction, relative to |X|, and to f1 for f1


@dataclasses.dataclass
class Fold:
    """A fold at parameter value p: f1 [Hz], the orbit X, the null vectors v, w and the
    problem's resolution."""

    p: float
    f1_Hz: float
    X: np.ndarray
    v: np.ndarray
    w: np.ndarray
    resolution: int
    iterations: int

    def entry(self) -> dict:
        return {"p": self.p, "f1_Hz": self.f1_Hz, "newton_iterations": self.iterations,
                "resolution": self.resolution}


def _bordered(J, b, c):
    if scipy.sparse.issparse(J):
        return scipy.sparse.bmat([[J, b[:, None]], [c[None, :], None]], format="csr")
    return np.block([[J, b[:, None]], [c[None, :], np.zeros((1, 1))]])


def border_function(problem, J, b, c):
    """(g, v, w) of the bordered systems at G_X = J."""
    lu = problem.factor(_bordered(J, b, c))
    e = np.zeros(J.shape[0] + 1)
    e[-1] = 1.0
    right, left = lu.solve(e), lu.solve(e, transpose=True)
    return right[-1], right[:-1], left[:-1]


def locate(problem, X, f1_Hz: float, resolution: int, b, c, p: float = 0.0,
           tol: float = 1e-9, max_it: int = 15) -> Fold:
    """The fold near (X, f1) by Newton on (G, g); SolverError if it does not converge."""
    X = X.copy()
    for its in range(1, max_it + 1):
        G, _, J = problem.residual(X, f1_Hz, jacobian=True, resolution=resolution)
        g, v, w = border_function(problem, J, b, c)
        e = EPS * max(1.0, np.linalg.norm(X)) / max(np.linalg.norm(v), 1e-300)
        J_v = problem.residual(X + e * v, f1_Hz, jacobian=True, resolution=resolution)[2]
        g_X = -(J_v.T @ w - J.T @ w) / e
        h = 1e-6 * f1_Hz
        J_f = problem.residual(X, f1_Hz + h, jacobian=True, resolution=resolution)[2]
        g_f = -(w @ (J_f @ v) - w @ (J @ v)) / h
        G_f = problem.residual_f1(X, f1_Hz, resolution)
        if scipy.sparse.issparse(J):
            K = scipy.sparse.bmat([[J, G_f[:, None]], [g_X[None, :], np.array([[g_f]])]],
                                  format="csr")
        else:
            K = np.block([[J, G_f[:, None]], [g_X[None, :], np.array([[g_f]])]])
        step = problem.factor(K).solve(np.append(G, g))
        X -= step[:-1]
        f1_Hz -= step[-1]
        if not f1_Hz > 0:
            break
        small = (np.linalg.norm(step[:-1]) <= STEP_TOL * max(1.0, np.linalg.norm(X))
                 and abs(step[-1]) <= STEP_TOL * f1_Hz)
        if small and problem.norm(G, X) <= tol * 1e2:
            return Fold(p, float(f1_Hz), X, v / np.linalg.norm(v), w / np.linalg.norm(w),
                        resolution, its)
    raise SolverError(f"fold curve: no fold found near f1 = {f1_Hz:.5g} Hz at p = {p:g}")


def trace(problem_at, fold: Fold, p_stop: float, step: float, min_step: float | None = None,
          progress=None) -> tuple[list[Fold], str]:
    """The fold curve from ``fold`` (at fold.p) to ``p_stop``: ``problem_at(p)`` gives the
    periodic-orbit problem at p; natural steps of ``step`` in p (signed by the direction),
    halved where Newton fails, down to ``min_step`` (default step / 16).  Returns
    (the folds, why the trace ended)."""
    step = abs(step) * (1.0 if p_stop >= fold.p else -1.0)
    min_step = abs(min_step or step / 16)
    folds, p = [fold], fold.p
    while (p_stop - p) * step > 0:
        to = p + step if abs(p_stop - p) > abs(step) else p_stop
        last = folds[-1]
        try:
            got = locate(problem_at(to), last.X, last.f1_Hz, last.resolution, last.w, last.v,
                         p=to)
        except SolverError:
            step /= 2
            if abs(step) < min_step:
                return folds, (f"ended at p = {p:.6g}: no fold within {abs(2 * step):.3g} "
                               f"beyond it (the two folds meet, a cusp, or the fold leaves "
                               f"the problem's reach)")
            continue
        folds.append(got)
        p = to
        if progress:
            progress(got)
    return folds, "reached the end of the window"
