"""Hill's method for Floquet exponents (rawehelix.solvers.harmonic_balance.hill), without scenes:
the Mathieu equation's Ince-Strutt transition curves against their classical expansions and
against a monodromy integrated by solve_ivp, the damped Mathieu equation's multipliers
(period doubling included), convergence in H, a 2-dof system given as sparse samples with a
fixed dof, shift-invert against dense, and the Fourier coefficients of the samples."""

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from rawehelix.solvers.harmonic_balance.hill import (fourier_coefficients, hill_exponents,
                                            hill_matrix)

N = 64  # samples per period (>= 4H + 1 for every H used here)
TIMES = 2.0 * np.pi * np.arange(N) / N
UNSTABLE = 1.0 + 1e-6  # max |mu| above this: unstable


def mathieu(delta, eps, zeta=0.0):
    """Samples of x'' + 2 zeta x' + (delta + eps cos t) x = 0 (omega = 1) as (N, 1, 1)."""
    ones = np.ones((N, 1, 1))
    return ones, 2.0 * zeta * ones, (delta + eps * np.cos(TIMES))[:, None, None]


def mathieu_monodromy(delta, eps, zeta=0.0):
    """The monodromy over t = 0..2 pi by solve_ivp (the independent reference)."""
    def rhs(t, y):
        return [y[1], -2.0 * zeta * y[1] - (delta + eps * np.cos(t)) * y[0]]
    return _monodromy(rhs, 2)


def _monodromy(rhs, size, period=2.0 * np.pi):
    columns = [solve_ivp(rhs, (0.0, period), e, method="DOP853", rtol=1e-11, atol=1e-12).y[:, -1]
               for e in np.eye(size)]
    return np.array(columns).T


def _max_mu(delta, eps, H=10):
    return np.abs(hill_exponents(*mathieu(delta, eps), 1.0, H).multipliers).max()


def _bisect(stable, unstable, eps, tol=1e-10):
    """The delta between a stable and an unstable one where max |mu| crosses 1."""
    assert _max_mu(stable, eps) <= UNSTABLE < _max_mu(unstable, eps)
    while abs(unstable - stable) > tol:
        mid = 0.5 * (stable + unstable)
        if _max_mu(mid, eps) > UNSTABLE:
            unstable = mid
        else:
            stable = mid
    return 0.5 * (stable + unstable)


def _match(found, expected, tol):
    """Match two multisets of complex numbers one to one (greedily) within tol."""
    assert len(found) == len(expected), (found, expected)
    rest = list(expected)
    for mu in found:
        j = int(np.argmin([abs(mu - e) for e in rest]))
        assert abs(mu - rest[j]) < tol, (found, expected)
        rest.pop(j)


# The Ince-Strutt boundaries: (stable, unstable) brackets, the classical expansion to the
# order given, its first neglected term (Abramowitz & Stegun 20.2.25 with a = 4 delta,
# q = -2 eps), and the sign of trace(monodromy) there.
BOUNDARIES = {
    "first, lower": (lambda e: (0.25 - e, 0.25), lambda e: 0.25 - e / 2 - e**2 / 8 + e**3 / 32,
                     lambda e: -e**4 / 384, -2.0),
    "first, upper": (lambda e: (0.25 + e, 0.25), lambda e: 0.25 + e / 2 - e**2 / 8 - e**3 / 32,
                     lambda e: -e**4 / 384, -2.0),
    "second, lower": (lambda e: (1 - e**2 / 2, 1 + e**2 / 6), lambda e: 1 - e**2 / 12,
                      lambda e: 5 * e**4 / 3456, 2.0),
    "second, upper": (lambda e: (1 + e**2, 1 + e**2 / 6), lambda e: 1 + 5 * e**2 / 12,
                      lambda e: -763 * e**4 / 3456, 2.0),
}


@pytest.mark.parametrize("eps", [0.1, 0.2])
@pytest.mark.parametrize("name", list(BOUNDARIES))
def test_ince_strutt_boundaries(name, eps):
    """Hill's transition curve against the expansion (to within its first neglected term, and
    closer with it) and against |trace| = 2 of the solve_ivp monodromy (1e-6 in delta)."""
    bracket, expansion, next_term, trace = BOUNDARIES[name]
    delta = _bisect(*bracket(eps), eps)
    error = delta - expansion(eps)
    assert abs(error) <= 1.5 * abs(next_term(eps)), (delta, error)
    assert abs(error - next_term(eps)) <= 0.3 * abs(next_term(eps)), (delta, error)
    reference = brentq(lambda d: np.trace(mathieu_monodromy(d, eps)) - trace,
                       *sorted(bracket(eps)), xtol=1e-12)
    assert abs(delta - reference) < 1e-6


def test_tongues_double_the_period_or_not():
    """Inside the first tongue the largest multiplier is real negative, inside the second real
    positive; between them the multipliers lie on the unit circle."""
    eps = 0.1
    first = hill_exponents(*mathieu(0.25, eps), 1.0, 10).multipliers
    second = hill_exponents(*mathieu(1 + eps**2 / 6, eps), 1.0, 10).multipliers
    between = hill_exponents(*mathieu(0.6, eps), 1.0, 10).multipliers
    assert first[0].real < -UNSTABLE and abs(first[0].imag) < 1e-10
    assert second[0].real > UNSTABLE and abs(second[0].imag) < 1e-10
    np.testing.assert_allclose(np.abs(between), 1.0, atol=1e-10)
    assert abs(between[0].imag) > 0.1


@pytest.mark.parametrize("delta, eps, zeta, kind", [
    (0.25, 0.4, 0.02, "two real negative (period doubling)"),
    (0.6, 0.3, 0.05, "complex pair"),
    (1.0, 0.5, 0.01, "two real positive"),
    (2.0, 1.5, 0.02, "complex pair, strong forcing"),
])
def test_damped_mathieu_multipliers(delta, eps, zeta, kind):
    """The Hill multipliers are the eigenvalues of the solve_ivp monodromy (as sets)."""
    result = hill_exponents(*mathieu(delta, eps, zeta), 1.0, 12)
    reference = np.linalg.eigvals(mathieu_monodromy(delta, eps, zeta))
    _match(result.multipliers, reference, 1e-8)
    assert np.all(np.abs(result.centres) <= 0.5 + 1e-6)
    if kind.startswith("two real negative"):
        assert np.all(result.multipliers.real < 0)
        assert np.all(np.abs(result.multipliers.imag) < 1e-10)
        np.testing.assert_allclose(np.abs(result.exponents.imag), 0.5, atol=1e-10)
    np.testing.assert_allclose(np.prod(result.multipliers), np.exp(-2 * zeta * 2 * np.pi),
                               rtol=1e-9)  # Liouville


def test_convergence_in_H():
    """The error of the multipliers falls with H until round-off."""
    delta, eps, zeta = 0.6, 0.3, 0.05
    reference = np.linalg.eigvals(mathieu_monodromy(delta, eps, zeta))
    errors = []
    for H in (1, 2, 3, 4, 6):
        mu = hill_exponents(*mathieu(delta, eps, zeta), 1.0, H).multipliers
        errors.append(max(min(abs(mu - r)) for r in reference))
    assert errors[0] > 1e-3 and errors[-1] < 1e-10, errors
    for coarse, fine in zip(errors, errors[1:]):
        assert fine < 0.1 * coarse or fine < 1e-10, errors


def _full_csr(a):
    """a as CSR with every entry stored (one sparsity pattern for all samples)."""
    n = a.shape[0]
    return sp.csr_matrix((a.ravel(), np.tile(np.arange(n), n), np.arange(0, n * n + 1, n)),
                         shape=a.shape)


def two_dof(varying_mass):
    """A 3-dof system, as CSR samples of one pattern, whose dof 2 is fixed (omega = 1)."""
    def matrices(t):
        M = np.array([[1.0, 0.1, 0.05], [0.1, 1.5, 0.02], [0.05, 0.02, 1.0]])
        if varying_mass:
            M[0, 0] += 0.2 * np.cos(t)
        C = np.array([[0.04, 0.01, 0.0], [0.01, 0.06, 0.0], [0.0, 0.0, 0.1]])
        k01 = -0.4 + 0.1 * np.sin(t)
        K = np.array([[0.3 + 0.2 * np.cos(t), k01, 0.3],
                      [k01, 0.9 + 0.3 * np.cos(2 * t), 0.2], [0.3, 0.2, 5.0]])
        return M, C, K
    samples = [matrices(t) for t in TIMES]
    return [[_full_csr(s[i]) for s in samples] for i in range(3)], matrices


def two_dof_monodromy(matrices, free):
    def rhs(t, y):
        M, C, K = (a[np.ix_(free, free)] for a in matrices(t))
        x, v = y[:len(free)], y[len(free):]
        return np.concatenate([v, np.linalg.solve(M, -C @ v - K @ x)])
    return _monodromy(rhs, 2 * len(free))


@pytest.mark.parametrize("varying_mass", [False, True], ids=["constant M", "varying M"])
def test_sparse_two_dof_with_a_fixed_dof(varying_mass):
    """Dense mode on sparse samples restricted to the free dofs: the standard form (constant
    M, inverted) and the generalised pencil (varying M) give the monodromy's eigenvalues."""
    (M, C, K), matrices = two_dof(varying_mass)
    free = [0, 1]
    form = hill_matrix(M, C, K, 1.0, 10, free)
    assert isinstance(form, tuple) == varying_mass
    result = hill_exponents(M, C, K, 1.0, 10, free)
    assert len(result.exponents) == 4 and result.candidates == 4 * 21
    reference = np.linalg.eigvals(two_dof_monodromy(matrices, free))
    _match(result.multipliers, reference, 1e-8)
    assert np.all(np.diff(np.abs(result.multipliers)) <= 1e-12)
    assert np.all(np.diff(result.exponents.real) <= 1e-12)


def test_companion_form_solves_the_quadratic_problem():
    """Each Hill eigenpair satisfies sum_l [(lambda + i l omega)^2 M_{p-l} + (lambda + i l
    omega) C_{p-l} + K_{p-l}] c_l = 0 for every p (the linearisation is the right one)."""
    (M, C, K), _ = two_dof(varying_mass=True)
    free, H, omega = [0, 1], 6, 1.0
    A, B = hill_matrix(M, C, K, omega, H, free)
    lams, V = np.linalg.eig(np.linalg.solve(B.toarray(), A.toarray()))
    Mk, Ck, Kk = ([a.toarray()[np.ix_(free, free)] for a in fourier_coefficients(S, H)]
                  for S in (M, C, K))
    for lam, v in zip(lams[:8], V.T[:8]):
        c = v.reshape(2 * H + 1, 2, 2)[:, 0, :]
        for p in range(-H, H + 1):
            residual = sum(((lam + 1j * l * omega) ** 2 * Mk[p - l + 2 * H]
                            + (lam + 1j * l * omega) * Ck[p - l + 2 * H] + Kk[p - l + 2 * H])
                           @ c[l + H] for l in range(-H, H + 1))
            assert np.linalg.norm(residual) < 1e-9 * (1 + abs(lam)) ** 2


def test_shift_invert_finds_the_dense_largest_multiplier():
    (M, C, K), _ = two_dof(varying_mass=True)
    dense = hill_exponents(M, C, K, 1.0, 10, [0, 1])
    shifted = hill_exponents(M, C, K, 1.0, 10, [0, 1], shifts=[0.0, 0.5j, -0.5j], k=6)
    assert "shift-invert" in shifted.method and shifted.candidates <= 18
    assert 1 <= len(shifted.exponents) <= 4
    assert abs(abs(shifted.multipliers[0]) - abs(dense.multipliers[0])) < 1e-9
    assert min(abs(shifted.multipliers[0] - mu) for mu in dense.multipliers) < 1e-9
    for mu in shifted.multipliers:  # whatever it found is physical and found once
        assert min(abs(mu - d) for d in dense.multipliers) < 1e-9
    assert len(set(np.round(shifted.exponents, 6))) == len(shifted.exponents)


def test_refusals():
    with pytest.raises(ValueError, match="dense_max"):
        hill_exponents(*mathieu(0.6, 0.1), 1.0, 10, dense_max=20)
    with pytest.raises(RuntimeError, match="H may be too small"):
        hill_exponents(*mathieu(1.0, 0.5, 0.01), 1.0, 1)  # second tongue needs H >= 2
    with pytest.raises(ValueError, match="too few"):
        fourier_coefficients(list(mathieu(0.6, 0.1)[2][:8]), 2)


@pytest.mark.parametrize("sparse", [False, True], ids=["dense", "sparse"])
def test_fourier_coefficients_of_a_cos_sin_signal(sparse):
    """A(t) = A0 + A1 cos t + A2 sin 2t: A_0 = A0, A_{+-1} = A1/2, A_{+-2} = -+i A2/2."""
    rng = np.random.default_rng(1)
    A0, A1, A2 = rng.standard_normal((3, 3, 3))
    samples = [A0 + A1 * np.cos(t) + A2 * np.sin(2 * t) for t in TIMES[::4]]  # N = 16
    if sparse:
        samples = [_full_csr(s) for s in samples]
    coefficients = fourier_coefficients(samples, 3)
    assert len(coefficients) == 13
    dense = [a.toarray() if sp.issparse(a) else a for a in coefficients]
    expected = {0: A0, 1: A1 / 2, -1: A1 / 2, 2: -0.5j * A2, -2: 0.5j * A2}
    for k in range(-6, 7):
        np.testing.assert_allclose(dense[k + 6], expected.get(k, 0 * A0), atol=1e-14)
