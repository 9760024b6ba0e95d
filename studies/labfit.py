"""The intrinsic bending law EI = a T + b whose simulated lab test reproduces
Eq. (64) at the paper's tensions (``rawehelix labtest bending --fit``,
docs/explanation/labtest.md): per tension a 1-D root find of a constant EI
(secant, from the closed-form inverse of solvers/analytic.py), the line through
the roots, then Gauss-Newton on (a, b) with the law in the rod.  The test itself
(``bending_test``: solver, T_e, loads -> its reading) is the caller's
(:mod:`rawehelix.studies.labtest`).
"""

from __future__ import annotations

import numpy as np

from rawehelix.solvers import analytic
from rawehelix.studies.scene import SceneError

FIT_TOLERANCE = 1e-4  # relative: the per-tension root find of the intrinsic EI
FIT_TARGET = 0.01  # the law's simulated test reproduces Eq. (64) within 1 %


def intrinsic_EI(solver, tension_N: float, target_Nm2: float, loads_N, bending_test,
                 rtol: float = FIT_TOLERANCE, max_iterations: int = 12):
    """The constant EI of the rod whose simulated bending test at T_e reads
    ``target_Nm2`` by Eq. (63): secant on log EI from the closed-form inverse."""
    L0 = solver.q.L0

    def misfit(EI):
        solver.set_bending_stiffness(EI)
        return np.log(bending_test(solver, tension_N, loads_N)["apparent_EI_Nm2"] / target_Nm2)

    guess = analytic.cantilever_intrinsic_EI(target_Nm2, tension_N, L0)
    if guess is None:
        raise SceneError("labtest --fit", f"T_e = {tension_N:g} N",
                         f"Eq. (64)'s EI = {target_Nm2:.4g} N m^2 is below the string's "
                         f"T L0^2 / 3 = {tension_N * L0**2 / 3:.4g} N m^2: no intrinsic EI")
    x0, x1 = np.log(guess), np.log(guess) + 0.01
    f0, f1 = misfit(np.exp(x0)), misfit(np.exp(x1))
    for _ in range(max_iterations):
        x0, x1, f0 = x1, x1 - f1 * (x1 - x0) / (f1 - f0), f1
        f1 = misfit(np.exp(x1))
        if abs(f1) < rtol:
            return float(np.exp(x1))
    raise SceneError("labtest --fit", f"T_e = {tension_N:g} N",
                     f"the root find of the intrinsic EI did not converge (misfit {f1:.2e})")


def fit(solver, tensions, targets, loads, bending_test):
    """The intrinsic law EI = a T + b (see the module doc) whose simulated test reads
    ``targets`` (Eq. 64) at the tensions: the roots of a constant EI per tension,
    the line through them, then (a, b) refined by Gauss-Newton on the law's own
    simulated tests (the law in the rod at the local tension).  (rows, summary)."""
    targets = np.asarray(targets, dtype=float)
    roots = [intrinsic_EI(solver, T, t, loads, bending_test) for T, t in zip(tensions, targets)]
    line = np.polyfit(tensions, roots, 1)
    law, rows, misfit, iterations = _refine_law(solver, tensions, targets, loads, line,
                                                bending_test)
    a, b = law
    apparent = np.array([r["apparent_EI_Nm2"] for r in rows])
    error = apparent / targets - 1
    intrinsic = a * np.asarray(tensions) + b
    return rows, {
        "fit": True, "tension_N": list(tensions), "load_N": list(loads),
        "law": {"a_Nm2_per_N": float(a), "b_Nm2": float(b)},
        "law_applied_as": "helix.EI_law in the rod: EI = a T + b at the local tension T = EA eps",
        "gauss_newton_iterations": iterations,
        "intrinsic_EI_Nm2": intrinsic.tolist(),
        "constant_EI_roots_Nm2": roots,
        "line_through_roots": {"a_Nm2_per_N": float(line[0]), "b_Nm2": float(line[1])},
        "apparent_EI_Nm2": apparent.tolist(), "eq64_EI_Nm2": targets.tolist(),
        "relative_error": error.tolist(),
        "within_1_percent": bool(np.all(np.abs(error) <= FIT_TARGET)),
        "eq64_over_intrinsic": (targets / intrinsic).tolist(),
    }


def _refine_law(solver, tensions, targets, loads, start, bending_test,
                max_iterations: int = 8):
    """Gauss-Newton on (a, b) for log(apparent EI / Eq. 64) at the tensions, the law
    in the rod; from ``start``, finite-difference Jacobian.  (law, rows, misfit, its)."""
    def run(law):
        solver.set_bending_law(*law)
        rows = [bending_test(solver, T, loads) for T in tensions]
        return rows, np.log(np.array([r["apparent_EI_Nm2"] for r in rows]) / targets)

    law = np.asarray(start, dtype=float)
    rows, misfit = run(law)
    for iteration in range(max_iterations):
        if np.abs(misfit).max() < FIT_TOLERANCE:
            return law, rows, misfit, iteration
        steps = 1e-3 * np.abs(law)
        J = np.column_stack([(run(law + h * np.eye(2)[k])[1] - misfit) / h
                             for k, h in enumerate(steps)])
        step = np.linalg.lstsq(J, -misfit, rcond=None)[0]
        law = law + step
        rows, misfit = run(law)
        if np.all(np.abs(step) <= 1e-6 * np.abs(law)):  # the least-squares floor
            return law, rows, misfit, iteration + 1
    return law, rows, misfit, max_iterations
