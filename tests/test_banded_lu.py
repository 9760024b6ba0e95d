"""The compiled steps' banded LU (solvers/banded_lu.py) against numpy's dense solve, and
its renumbering of J against the dofs' own band."""

import numpy as np

from rawehelix.solvers import banded_lu


def test_banded_lu_solves_like_numpy_with_pivoting():
    """A banded matrix whose diagonal is small (so rows are swapped), renumbered by a
    permutation: x from the factors equals numpy's to 1e-12 relative."""
    rng = np.random.default_rng(5)
    n, kl = 40, 4
    A = np.zeros((n, n))
    for i in range(n):
        for j in range(max(0, i - kl), min(n, i + kl + 1)):
            A[i, j] = rng.standard_normal()
        A[i, i] *= 1e-3  # partial pivoting must swap
    b = rng.standard_normal(n)
    LU, LT, UT = A.copy(), np.zeros((n, kl)), np.zeros((n, 2 * kl))
    piv, x = np.zeros(n, np.int64), np.zeros(n)
    assert banded_lu.factor(LU, piv, kl, LT, UT) == 0
    assert np.any(piv != np.arange(n))
    banded_lu.solve(LU, LT, UT, piv, kl, b, x)
    ref = np.linalg.solve(A, b)
    assert np.abs(x - ref).max() <= 1e-12 * np.abs(ref).max()
    perm = rng.permutation(n)
    P = np.zeros((n, n))
    banded_lu.permute(A, perm, P)
    assert np.array_equal(P, A[np.ix_(perm, perm)])


def test_ordering_narrows_a_scattered_band():
    """Entities coupling neighbours of a chain numbered at random: the renumbering finds
    the chain's band (1), the dofs' own numbering is kept when it is as narrow."""
    rng = np.random.default_rng(2)
    n = 30
    label = rng.permutation(n)
    pairs = [np.array([label[i], label[i + 1]]) for i in range(n - 1)]
    perm, kl = banded_lu.ordering([np.array(pairs)], n)
    assert kl == 1 and sorted(perm) == list(range(n))
    chain = [np.array([[i, i + 1] for i in range(n - 1)])]
    perm, kl = banded_lu.ordering(chain, n)
    assert kl == 1 and np.array_equal(perm, np.arange(n))
