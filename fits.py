"""When a fit's data determine its parameters: the one criterion of every
least-squares fit of rawehelix (the lab's law EI = a T + b, ``calibrate``, the
resonance peak's parabola).

A linear(ised) fit of p parameters to data points has the design matrix A (one row a
point, one column a parameter: the model's derivative by it).  Its least-squares
solution is unique only if A has rank p, and that needs at least p distinct points:
with fewer, or a rank-deficient A (a parameter that changes no point, or two that
change them alike), the data leave a direction of the parameters free, and a solver
returns one point of it as if it were the answer (numpy's polyfit with one tension
returns a line through it, with only a RankWarning).  A fit asks
:func:`undetermined` and says the reason instead of a result.
"""

from __future__ import annotations

import numpy as np

#: the rank tolerance of a Jacobian of finite differences (calibrate's, the lab law's
#: Gauss-Newton): a singular value below DIFFERENCES_RTOL x the largest (unit columns)
#: is zero.  Past a condition of 1e6, data known to u leave the parameters uncertain by
#: ~1e6 u: not determined in any use.  (A difference's own error, ~ its step times the
#: curvature, can show an exact degeneracy as a condition of only ~1 / step: the
#: condition number is reported beside the verdict.)
DIFFERENCES_RTOL = 1e-6


def undetermined(design, parameters: int, rtol: float | None = None) -> str | None:
    """Why the design matrix ``design`` (rows: the data points, columns: the parameters)
    cannot determine ``parameters`` unknowns, or None if it can.  ``rtol``: a singular
    value of the design with unit columns below rtol x the largest is zero (None:
    numpy's, max(rows, p) x eps; a design of finite differences needs their accuracy)."""
    A = np.asarray(design, dtype=float)
    A = A.reshape(len(A), -1) if A.size else np.zeros((0, parameters))
    if not np.all(np.isfinite(A)):
        return "the design has non-finite entries"
    distinct = len(np.unique(A, axis=0)) if len(A) else 0
    if distinct < parameters:
        return (f"{distinct} distinct point{'s' * (distinct != 1)} for {parameters} "
                f"parameters (at least {parameters} needed)")
    # the rank of the design with unit columns (independent of the parameters' units):
    # numpy's tolerance, max(rows, p) x eps x the largest singular value
    norms = np.linalg.norm(A, axis=0)
    unit = A / np.where(norms > 0, norms, 1.0)
    tol = None if rtol is None else rtol * np.linalg.norm(unit, 2)
    rank = int(np.linalg.matrix_rank(unit, tol=tol))
    rank = min(rank, int(np.count_nonzero(norms)))
    if rank < parameters:
        return (f"the design has rank {rank} for {parameters} parameters (a parameter the "
                f"data do not see, or two they see alike)")
    return None


def polynomial(x, degree: int):
    """The design of a polynomial of ``degree`` in x (numpy's polyfit's: x^degree ... 1)."""
    return np.vander(np.asarray(x, dtype=float), degree + 1)
