"""Hill's method for the Floquet exponents of a linear time-periodic second-order system

    M(t) x'' + C(t) x' + K(t) x = 0,     period T = 2 pi / omega,  x in R^n,

from the matrices at N equally spaced samples t_j = j T / N (N >= 4H + 1).

The Floquet ansatz x = exp(lambda t) sum_{l=-H..H} c_l exp(i l omega t) turns the
equation into an eigenproblem of a truncated block-Toeplitz ("Hill") matrix
(Hill 1886; Deconinck & Kutz 2006, J. Comput. Phys. 219: 296-321).  Each physical
exponent appears in it 2H + 1 times, as lambda + i j omega; the copy that belongs
to the physical exponent is picked by the symmetry of its eigenvector: its
energy-weighted mean harmonic index (its centre) is the one nearest zero
(Bentvelsen & Lazarus 2018, Nonlinear Dyn. 94: 2447-2455; Lazarus & Thomas 2010,
C. R. Mecanique 338: 510-517).  At period doubling (multiplier real and negative) two
copies, lambda = a +- i omega / 2, tie at |centre| = 1/2; they are each other's
mirror copy (conjugate, harmonics reversed), an exact symmetry of the truncated matrix
of a real system, and one of them is kept.  The exponent reported is the centred copy:
its imaginary part may exceed omega / 2 (a natural frequency); its multiplier is the same.

Limitations: where two physical exponents differ by exactly i j omega (a tongue's tip at
zero forcing, e.g. Mathieu delta = 1/4, eps = 0) the Hill eigenvectors mix their copies
and the count check fails; shift-invert mode has no count to check (it keeps the physical
candidates among those it found, at the tightest realness tolerance).  numpy and scipy only.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import scipy.linalg
import scipy.sparse as sp
import scipy.sparse.linalg as spla

#: |Im mu| / |mu| below which a multiplier counts as real (its copies then tie at |c| = 1/2);
#: dense mode loosens it step by step until 2m exponents are found (truncation at small H
#: moves the copies of a real negative multiplier off the real axis)
REAL_TOLS = (1e-9, 1e-6, 1e-3, 1e-1)
#: how far beyond |c| = 1/2 the copies of a real negative multiplier may lie (truncation)
CENTRE_TOL = 0.25
#: relative distance below which two exponents are one (mirror copies, two shifts)
SAME_TOL = 1e-7
DENSE_MASS = 16  # the largest non-diagonal constant mass inverted for the standard form
PAIR_TOL = 1e-10  # an eigenpair of shift-invert kept only with this backward error (1-norms)


@dataclasses.dataclass
class HillResult:
    """The physical Floquet exponents found by Hill's method."""

    exponents: np.ndarray  # lambda (complex), by decreasing real part
    multipliers: np.ndarray  # mu = exp(lambda T), by decreasing modulus
    centres: np.ndarray  # per exponent: its eigenvector's mean harmonic index
    method: str  # one sentence naming the method
    H: int
    candidates: int  # how many Hill eigenvalues were examined


def _as_list(samples) -> list:
    """The samples as a list of 2-D matrices (a 3-D array is split along its first axis)."""
    if isinstance(samples, np.ndarray) and samples.ndim == 3:
        return list(samples)
    return [s if sp.issparse(s) else np.atleast_2d(np.asarray(s)) for s in samples]


def _same_pattern(samples) -> bool:
    """Whether all sparse samples are CSR with identical indptr and indices."""
    if not all(sp.issparse(s) for s in samples):
        return False
    first = samples[0]
    return all(s.format == "csr" and s.nnz == first.nnz and np.array_equal(s.indptr, first.indptr)
               and np.array_equal(s.indices, first.indices) for s in samples)


def fourier_coefficients(samples, H: int) -> list:
    """Complex Fourier coefficients A_k, k = -2H..2H (a list of 4H+1 entries, index k + 2H),
    of A(t) = sum_k A_k exp(i k omega t) from its N samples (dense arrays or scipy.sparse
    matrices, all of one sparsity pattern); A_k = (1/N) sum_j A(t_j) exp(-i k omega t_j).

    The discrete Fourier transform (numpy.fft) of the samples: of the ``.data`` arrays when
    the samples are CSR matrices of one pattern, else of the dense arrays; sparse samples of
    differing patterns are summed term by term.  Exact for trigonometric polynomials of
    degree < N - 2H; N >= 4H + 1 is required."""
    samples = _as_list(samples)
    N = len(samples)
    if N < 4 * H + 1:
        raise ValueError(f"{N} samples are too few for H = {H}: N >= 4H + 1 = {4 * H + 1}")
    ks = np.arange(-2 * H, 2 * H + 1)
    if _same_pattern(samples):
        data = np.fft.fft(np.array([s.data for s in samples]), axis=0) / N
        s = samples[0]
        return [sp.csr_matrix((data[k % N], s.indices.copy(), s.indptr.copy()), shape=s.shape)
                for k in ks]
    if any(sp.issparse(s) for s in samples):
        phases = np.exp(-2j * np.pi * np.outer(ks, np.arange(N)) / N) / N
        return [sum(p * sp.csr_matrix(s) for p, s in zip(row, samples)).tocsr()
                for row in phases]
    data = np.fft.fft(np.array(samples, dtype=float), axis=0) / N
    return [data[k % N] for k in ks]


def _restrict(A, free):
    """A's rows and columns of the free dofs (all when free is None), sparse or dense."""
    if free is None:
        return sp.csr_matrix(A) if sp.issparse(A) else np.asarray(A, dtype=float)
    return sp.csr_matrix(A)[free][:, free] if sp.issparse(A) else np.asarray(A)[np.ix_(free, free)]


def _harmonics_of(samples, H: int) -> dict:
    """The Fourier coefficients k -> A_k (k = -2H..2H) that are not round-off (some entry
    above 1e-14 of the largest), as complex CSR with the round-off entries removed."""
    coefficients = fourier_coefficients(samples, H)
    largest = [abs(a).max() if sp.issparse(a) else np.abs(a).max() for a in coefficients]
    threshold = 1e-14 * max(max(largest), 1e-300)
    out = {}
    for k, (a, top) in enumerate(zip(coefficients, largest)):
        if top > threshold:
            a = sp.csr_matrix(a, dtype=complex)
            a.data[np.abs(a.data) <= threshold] = 0.0
            a.eliminate_zeros()
            out[k - 2 * H] = a
    return out


def _mass_inverse(M0):
    """M_0^{-1} for the standard form: exact and sparse when M_0 is diagonal, dense when
    m <= DENSE_MASS, else None (a dense inverse of a large sparse mass fills the Hill matrix
    in: at m = 94 its shift-invert LU cost 0.24 s against the pencil's 0.02 s)."""
    if (M0 - sp.diags(M0.diagonal())).count_nonzero() == 0:
        return sp.diags(1.0 / M0.diagonal()).tocsr()
    if M0.shape[0] <= DENSE_MASS:
        return sp.csr_matrix(scipy.linalg.inv(M0.toarray()))
    return None


def _blocks(m: int, upper_left=None, upper_right=None, lower_left=None, lower_right=None):
    """The 2m x 2m matrix [[upper_left, upper_right], [lower_left, lower_right]] (None: 0)."""
    zero = sp.csr_matrix((m, m))
    return sp.bmat([[zero if b is None else b for b in row]
                    for row in ((upper_left, upper_right), (lower_left, lower_right))],
                   format="csr")


def hill_matrix(M_samples, C_samples, K_samples, omega: float, H: int, free=None):
    """The first-order Hill matrix (scipy.sparse CSC, complex) of size 2 m (2H+1), m = len(free)
    (default: all n dofs): with x = exp(lambda t) sum_{l=-H..H} c_l exp(i l omega t) and
    y = x' = exp(lambda t) sum_l d_l exp(i l omega t), d_l = (lambda + i l omega) c_l, the
    quadratic problem sum_l [(lambda + i l omega)^2 M_{p-l} + (lambda + i l omega) C_{p-l}
    + K_{p-l}] c_l = 0 (p = -H..H) is linearised in lambda (companion form):

        lambda c_p = d_p - i p omega c_p,
        lambda sum_l M_{p-l} d_l = -sum_l [K_{p-l} c_l + (C_{p-l} + i l omega M_{p-l}) d_l].

    The state is z = (x, x') per harmonic: z = (c_{-H}, d_{-H}, ..., c_H, d_H), blocks of
    2m.  Only the free dofs' rows and columns are kept (the others are held at zero).

    Returns A (lambda z = A z) when M is constant (all samples equal to within round-off)
    and M_0^{-1} is cheap (diagonal, or m <= DENSE_MASS, inverted densely); otherwise the
    generalised pencil (A, B), lambda B z = A z, B = blockdiag over p of (I, M-Toeplitz)."""
    M, C, K = ([_restrict(s, free) for s in _as_list(S)] for S in (M_samples, C_samples,
                                                                    K_samples))
    m, size = M[0].shape[0], 2 * M[0].shape[0] * (2 * H + 1)
    Mk, Ck, Kk = (_harmonics_of(S, H) for S in (M, C, K))
    zero = sp.csr_matrix((m, m), dtype=complex)
    Minv = _mass_inverse(Mk[0].real.tocsr()) if set(Mk) == {0} else None
    eye, L = sp.identity(m, format="csr"), sp.diags(np.arange(-H, H + 1).astype(float))
    ident = sp.identity(2 * H + 1, format="csr")
    ks = sorted(set(Mk) | set(Ck) | set(Kk))
    shift = {k: sp.eye(2 * H + 1, k=-k, format="csr") for k in ks}
    A = [(ident, _blocks(m, upper_right=eye))]
    if Minv is not None:
        A.append((L, _blocks(m, -1j * omega * eye, None, None, -1j * omega * eye)))
        A += [(shift[k], _blocks(m, lower_left=-(Minv @ Kk.get(k, zero)),
                                 lower_right=-(Minv @ Ck.get(k, zero)))) for k in ks]
        return _kron_sum(A, size)
    A.append((L, _blocks(m, upper_left=-1j * omega * eye)))
    B = [(ident, _blocks(m, upper_left=eye))]
    for k in ks:
        M_ = Mk.get(k, zero)
        A.append((shift[k], _blocks(m, lower_left=-Kk.get(k, zero),
                                    lower_right=-Ck.get(k, zero))))
        A.append((shift[k] @ L, _blocks(m, lower_right=-1j * omega * M_)))
        B.append((shift[k], _blocks(m, lower_right=M_)))
    return _kron_sum(A, size), _kron_sum(B, size)


def _kron_sum(terms, size: int):
    """sum over terms (S, X) of kron(S, X), assembled once, as complex CSC of size x size."""
    parts = [sp.kron(S, X, format="coo") for S, X in terms]
    rows, cols = (np.concatenate([getattr(p, a) for p in parts]) for a in ("row", "col"))
    data = np.concatenate([p.data for p in parts]).astype(complex)
    return sp.csc_matrix((data, (rows, cols)), shape=(size, size))


def _harmonics(vectors, m: int, H: int) -> np.ndarray:
    """The x parts c_l of eigenvectors (columns), as an array (vector, harmonic, dof)."""
    z = np.asarray(vectors).T.reshape(-1, 2 * H + 1, 2, m)
    return z[:, :, 0, :]


def _centres(c: np.ndarray, H: int) -> np.ndarray:
    """Energy-weighted mean harmonic index sum_l l |c_l|^2 / sum_l |c_l|^2 per vector."""
    energy = np.sum(np.abs(c) ** 2, axis=2)
    return energy @ np.arange(-H, H + 1) / energy.sum(axis=1)


def _is_mirror(lam_a, c_a, lam_b, c_b) -> bool:
    """Whether (lam_b, c_b) is the mirror copy of (lam_a, c_a): lam_b = conj(lam_a),
    c_b,l = conj(c_a,-l) up to a scalar (the conjugate solution of a real system)."""
    if abs(lam_b - np.conj(lam_a)) > SAME_TOL * (1.0 + abs(lam_a)):
        return False
    u, v = np.conj(c_a[::-1]).ravel(), c_b.ravel()
    return abs(np.vdot(u, v)) >= (1.0 - 1e-6) * np.linalg.norm(u) * np.linalg.norm(v)


def _select(lams, c, T: float, H: int, real_tol: float):
    """The physical copies (Bentvelsen & Lazarus 2018, sorting by symmetry): the candidates
    whose centre lies within 1/2 of zero; a real negative multiplier's copies at
    Im lambda = +-omega/2 tie at |c| = 1/2 and are kept once per mirror pair."""
    centres = _centres(c, H)
    keep = []
    for i in np.argsort(np.abs(centres), kind="stable"):
        mu = np.exp(lams[i] * T)
        real_negative = abs(mu.imag) <= real_tol * abs(mu) and mu.real < 0
        if real_negative:
            if abs(centres[i]) >= 0.5 + CENTRE_TOL:
                continue
            if any(_is_mirror(lams[j], c[j], lams[i], c[i]) for j in keep):
                continue
        elif abs(centres[i]) >= 0.5:
            continue
        keep.append(i)
    return np.array(keep, dtype=int), centres


def _physical(lams, c, T: float, H: int, count):
    """:func:`_select` at the tightest realness tolerance of REAL_TOLS; with count given
    (dense mode), at the first that yields exactly count exponents, else RuntimeError."""
    for real_tol in REAL_TOLS if count is not None else REAL_TOLS[:1]:
        keep, centres = _select(lams, c, T, H, real_tol)
        if count is None or len(keep) == count:
            return keep, centres
    raise RuntimeError(f"Hill's method (H = {H}) found {len(keep)} physical exponents, not "
                       f"2m = {count}: H may be too small")


def _dedupe(lams):
    """Indices of the distinct eigenvalues (those found from two shifts are one)."""
    keep = []
    for i, lam in enumerate(lams):
        if not any(abs(lam - lams[j]) <= SAME_TOL * (1.0 + abs(lam)) for j in keep):
            keep.append(i)
    return np.array(keep, dtype=int)


def _shift_invert(A, B, shifts, k: int):
    """The k eigenpairs nearest each shift: eigs of (A - sigma B)^{-1} B (shift-invert),
    lambda = sigma + 1/nu."""
    lams, vecs = [], []
    B = sp.identity(A.shape[0], format="csc") if B is None else B
    norm_A, norm_B = spla.norm(A, 1), spla.norm(B, 1)
    for sigma in shifts:
        lu = spla.splu((A - sigma * B).tocsc())
        op = spla.LinearOperator(A.shape, matvec=lambda x, lu=lu: lu.solve(B @ x),
                                 dtype=complex)
        v0 = np.ones(A.shape[0], dtype=complex)  # deterministic (ARPACK's default is random)
        nu, V = spla.eigs(op, k=min(k, A.shape[0] - 2), v0=v0)
        lam = sigma + 1.0 / nu
        # only converged pairs: the backward error |A v - lambda B v| / ((|A| + |lambda| |B|) |v|)
        Av, Bv = A @ V, B @ V
        scale = (norm_A + np.abs(lam) * norm_B) * np.linalg.norm(V, axis=0)
        good = np.linalg.norm(Av - Bv * lam, axis=0) <= PAIR_TOL * scale
        lams.append(lam[good])
        vecs.append(V[:, good])
    return np.concatenate(lams), np.concatenate(vecs, axis=1)


def hill_exponents(M_samples, C_samples, K_samples, omega: float, H: int, free=None,
                   shifts=None, k: int = 6, dense_max: int = 3000) -> HillResult:
    """The physical Floquet exponents by Hill's method, sorted by symmetry (Bentvelsen &
    Lazarus 2018).  shifts None: all eigenvalues of the Hill matrix (dense, scipy.linalg.eig,
    of the pencil when :func:`hill_matrix` returns one; refused with ValueError above
    dense_max); the result then holds exactly 2m exponents, else RuntimeError.  With shifts:
    the k eigenvalues nearest each complex shift by shift-invert, deduplicated across shifts;
    the result holds the physical ones among them."""
    Ab = hill_matrix(M_samples, C_samples, K_samples, omega, H, free)
    A, B = Ab if isinstance(Ab, tuple) else (Ab, None)
    size, m, T = A.shape[0], A.shape[0] // (2 * (2 * H + 1)), 2.0 * np.pi / omega
    form = "generalised pencil" if isinstance(Ab, tuple) else "standard"
    if shifts is None:
        if size > dense_max:
            raise ValueError(f"the Hill matrix has size {size} > dense_max = {dense_max}: "
                             "give shifts (shift-invert) or raise dense_max")
        lams, V = scipy.linalg.eig(A.toarray(), None if B is None else B.toarray())
        mode = "dense"
    else:
        lams, V = _shift_invert(A, B, np.atleast_1d(shifts).astype(complex), k)
        unique = _dedupe(lams)
        lams, V = lams[unique], V[:, unique]
        mode = f"shift-invert at {len(np.atleast_1d(shifts))} shifts, k = {k}"
    count = 2 * m if shifts is None else None
    keep, centres = _physical(lams, _harmonics(V, m, H), T, H, count)
    order = keep[np.lexsort((-lams[keep].imag, -lams[keep].real))]
    exponents = lams[order]
    return HillResult(
        exponents=exponents, multipliers=np.exp(exponents * T), centres=centres[order],
        method=f"Hill's method (H = {H}, {mode}, {form} form), exponents sorted by eigenvector "
               "symmetry (Bentvelsen & Lazarus 2018)",
        H=H, candidates=len(lams))


def averaged_exponents(M_samples, C_samples, K_samples, free, count: int) -> list:
    """The ``count`` least damped exponents (Im > 0) of the averaged system M_0 x'' + C_0 x'
    + K_0 x = 0 on ``free`` (dense): shifts for :func:`hill_exponents` near the modes whose
    multipliers are the largest on a stable orbit."""
    M, C, K = (_restrict(_mean(samples), free) for samples in (M_samples, C_samples, K_samples))
    m = M.shape[0]
    # the pencil (A, B), not B^-1 A: M is singular where unknowns carry no inertia (the
    # mixed bending's moments), whose exponents are infinite and dropped
    Z, I = np.zeros((m, m)), np.eye(m)
    lam = scipy.linalg.eigvals(np.block([[Z, I], [-K, -C]]), np.block([[I, Z], [Z, M]]))
    lam = lam[np.isfinite(lam) & (lam.imag > 1e-9)]
    return list(lam[np.argsort(-lam.real)][:count])


def _mean(samples) -> np.ndarray:
    return np.asarray(sum(sp.csr_matrix(a).toarray() if sp.issparse(a) else np.asarray(a)
                          for a in samples) / len(samples))
