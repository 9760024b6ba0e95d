"""A banded LU with partial pivoting for the compiled steps (issue 46): LAPACK's
gbtrf/gbtrs in dense storage, numba's nopython mode, on J renumbered so that its
band is narrow (:func:`ordering`: reverse Cuthill-McKee of J's pattern, 36 -> 27
at N = 8, p = 3, 100 unknowns), with L's and U's columns kept as rows for the
solve (both triangles by column updates, contiguous).

Measured at N = 8, p = 3 (a loop in numba): the solve 8.2 us in the dofs' own
numbering with L read by columns, 6.0 us with L's columns as rows, 5.4 us with
the narrower band, 4.5 us with U by columns too (U by rows: a dot product a row,
one dependent chain; fast-math reassociation did not help: 5.7 us); the
factorisation ~ n kl^2.
"""

from __future__ import annotations

import numba
import numpy as np
import scipy.sparse
from scipy.sparse.csgraph import reverse_cuthill_mckee


def ordering(entity_dofs, n: int):
    """(perm, kl): the new numbering (row i of the renumbered J is J's row perm[i])
    and the band of J under it, from the dofs each integration entity couples."""
    rows, cols = [], []
    for dofs in entity_dofs:
        for d in dofs:
            rows.append(np.repeat(d, d.size))
            cols.append(np.tile(d, d.size))
    rows, cols = np.concatenate(rows), np.concatenate(cols)
    pattern = scipy.sparse.csr_matrix((np.ones(rows.size), (rows, cols)), shape=(n, n))
    perm = np.asarray(reverse_cuthill_mckee(pattern, symmetric_mode=True), dtype=np.int64)
    where = np.empty(n, np.int64)
    where[perm] = np.arange(n)
    kl = int(np.abs(where[rows] - where[cols]).max())
    own = int(np.abs(rows - cols).max())
    if own <= kl:  # the dofs' own numbering is as narrow
        return np.arange(n, dtype=np.int64), own
    return perm, kl


@numba.njit(cache=True)
def permute(J, perm, A):
    """A = J renumbered: A[i, j] = J[perm[i], perm[j]]."""
    n = J.shape[0]
    for i in range(n):
        for j in range(n):
            A[i, j] = J[perm[i], perm[j]]


@numba.njit(cache=True)
def factor(A, piv, kl, LT, UT):
    """A <- its LU factors in place, partial pivoting (LAPACK's gbtrf in dense
    storage): J's entries lie within ``kl`` of the diagonal, so the pivot is sought
    in kl rows and U has kl + kl off-diagonals; a swap moves the trailing columns
    only, so L's column k stays in rows k + 1 .. k + kl (a full-row swap would move
    its entries further from the diagonal than the solve reads); L's column k also
    into LT's row k and U's column i above the diagonal into UT's row i (UT[i, d] =
    U[i - 1 - d, i]: the solve reads them contiguously).  Returns the first zero
    pivot's row + 1 (0: none)."""
    n = A.shape[0]
    for k in range(n):
        last = min(n - 1, k + kl)
        p, big = k, abs(A[k, k])
        for i in range(k + 1, last + 1):
            if abs(A[i, k]) > big:
                p, big = i, abs(A[i, k])
        piv[k] = p
        if big == 0.0:
            return k + 1
        right = min(n - 1, k + 2 * kl)
        if p != k:  # the trailing columns only: L's column j stays where step j put it
            for j in range(k, right + 1):
                A[k, j], A[p, j] = A[p, j], A[k, j]
        d = A[k, k]
        for i in range(k + 1, last + 1):
            f = A[i, k] / d
            A[i, k] = f
            if f != 0.0:
                for j in range(k + 1, right + 1):
                    A[i, j] -= f * A[k, j]
        for j in range(kl):
            LT[k, j] = A[k + 1 + j, k] if k + 1 + j < n else 0.0
    for i in range(n):
        for d in range(2 * kl):
            UT[i, d] = A[i - 1 - d, i] if i - 1 - d >= 0 else 0.0
    return 0


@numba.njit(cache=True)
def solve(LU, LT, UT, piv, kl, b, x):
    """x = J^-1 b with :func:`factor`'s factors."""
    n = LU.shape[0]
    x[:] = b
    for k in range(n):  # L (unit diagonal, kl below) with the row swaps in turn (gbtrs)
        p = piv[k]
        if p != k:
            x[k], x[p] = x[p], x[k]
        xk = x[k]
        for j in range(min(kl, n - 1 - k)):
            x[k + 1 + j] -= LT[k, j] * xk
    for i in range(n - 1, -1, -1):  # U (2 kl above), by columns
        x[i] /= LU[i, i]
        xi = x[i]
        for d in range(min(2 * kl, i)):
            x[i - 1 - d] -= UT[i, d] * xi
