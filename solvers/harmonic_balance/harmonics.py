"""The real Fourier basis of harmonic balance and its alternating frequency-time
(AFT) evaluation (Cameron & Griffin 1989; NLvib's HB_residual), for any
second-order system F(t, U, U_t, U_tt) = 0 of n unknowns.

A periodic U of period T = 2 pi / w up to harmonic H is

    U(t) = U_0 + sum_{k=1..H} (U_ck cos(k w t) + U_sk sin(k w t)),

P = 2H + 1 coefficients per unknown, stored unknown by unknown: X[i P + l] is
coefficient l (0: the mean, 2k - 1: cos k, 2k: sin k) of unknown i, so that a
Jacobian on a banded dof pattern stays banded (bandwidth P times the dofs').
The residual's Galerkin projection onto the basis,

    G_l = (c_l / N) sum_j phi_l(t_j) F(t_j),   c_0 = 1, c_l = 2,

is exact for F up to harmonic N - H - 1 on N equally spaced samples t_j; a
cubic F of U needs N >= 4H + 1 to have no aliasing in G (:data:`OVERSAMPLE`).
Its Jacobian is

    dG_m/dU_l = (c_m / N) sum_j phi_m(t_j) [F_U phi_l + w F_V phi'_l + w^2 F_A phi''_l](t_j),

assembled here from the entries of F_U, F_V, F_A at the samples on one sparse
pattern (:class:`BlockPattern`).  No FE code (numpy and scipy).
"""

from __future__ import annotations

import math

import numpy as np
import scipy.sparse

OVERSAMPLE = 4  # N = OVERSAMPLE H + 2 samples: no aliasing of a cubic F (N >= 4H + 1)


def samples_for(H: int) -> int:
    """The default number of samples per period at H harmonics."""
    return OVERSAMPLE * H + 2


class Basis:
    """phi_l and its derivatives in theta = w t at N samples theta_j = 2 pi j / N."""

    def __init__(self, H: int, N: int | None = None):
        if not (isinstance(H, (int, np.integer)) and H >= 1):
            raise ValueError(f"harmonic balance: H = {H!r} must be an integer >= 1")
        N = samples_for(H) if N is None else int(N)
        if N < 2 * H + 1:
            raise ValueError(f"harmonic balance: {N} samples cannot hold {H} harmonics "
                             f"(at least 2H + 1 = {2 * H + 1})")
        self.H, self.N, self.P = int(H), N, 2 * int(H) + 1
        self.harmonic = np.concatenate([[0], np.repeat(np.arange(1, H + 1), 2)])
        self.phi, self.dphi, self.ddphi = self.values(self.theta())
        weight = np.full(self.P, 2.0 / N)
        weight[0] = 1.0 / N
        self.proj = (self.phi * weight).T  # (P, N): the Galerkin projection

    def values(self, theta: np.ndarray):
        """phi_l, phi_l' and phi_l'' (len(theta), P) at the angles theta."""
        k = self.harmonic[1:]
        cos = np.arange(1, self.P) % 2 == 1
        kt = np.outer(theta, k)
        one = np.ones((theta.size, 1))
        phi = np.hstack([one, np.where(cos, np.cos(kt), np.sin(kt))])
        dphi = np.hstack([0 * one, np.where(cos, -k * np.sin(kt), k * np.cos(kt))])
        ddphi = np.hstack([0 * one, -(k**2) * phi[:, 1:]])
        return phi, dphi, ddphi

    def theta(self) -> np.ndarray:
        return 2 * math.pi * np.arange(self.N) / self.N

    def synthesis(self, C: np.ndarray, w: float = 1.0, order: int = 0, theta=None) -> np.ndarray:
        """(N, n) samples of U (order 0), U_t (1) or U_tt (2) of coefficients C (n, P), at
        the basis' angles or at ``theta``."""
        phi = (self.phi, self.dphi, self.ddphi) if theta is None else self.values(theta)
        phi = phi[order]
        return (phi @ C.T) * w**order

    def analysis(self, F: np.ndarray) -> np.ndarray:
        """(n, P) coefficients of the projection of samples F (N, n)."""
        return (self.proj @ F).T

    def energy(self, C: np.ndarray) -> np.ndarray:
        """The energy of each harmonic k = 0..H of C (n, P): sum over unknowns of
        |U_0|^2 (k = 0) or (|U_ck|^2 + |U_sk|^2) / 2, Parseval's mean square."""
        e = np.zeros(self.H + 1)
        sq = np.sum(C**2, axis=0)
        e[0] = sq[0]
        e[1:] = 0.5 * (sq[1::2] + sq[2::2])
        return e

    def tail(self, C: np.ndarray, subtract_mean: bool = True) -> float:
        """The accuracy measure of H: the energy of the highest harmonic relative to
        that of the oscillation (harmonics 1..H; the mean left out, with
        ``subtract_mean``), 0 for a constant C."""
        e = self.energy(C)
        total = e[1:].sum() if subtract_mean else e.sum()
        return float(e[-1] / total) if total > 0 else 0.0

    def jacobian_weights(self, w: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """W_U, W_V, W_A (P*P, N): dG_m/dU_l = sum_j (W_U F_U + W_V F_V + W_A F_A)[m P + l, j]."""
        def outer(phi):
            return (self.proj[:, None, :] * phi.T[None, :, :]).reshape(self.P * self.P, self.N)
        return outer(self.phi), w * outer(self.dphi), w * w * outer(self.ddphi)


def resize(C: np.ndarray, P: int) -> np.ndarray:
    """Coefficients C (n, P0) at P = 2H + 1 columns: padded with zeros or truncated."""
    out = np.zeros((C.shape[0], P))
    m = min(P, C.shape[1])
    out[:, :m] = C[:, :m]
    return out


class BlockPattern:
    """The HB Jacobian's sparsity on an n x n CSR pattern with P coefficients per
    unknown (X[i P + l]): block (m, l) of dof pair (i, j) at row i P + m, column
    j P + l.  :meth:`matrix` turns the blocks' entries (P, P, nnz) into CSR."""

    def __init__(self, pattern: scipy.sparse.csr_matrix, P: int):
        pattern = pattern.tocsr()
        self.n, self.P, self.nnz = pattern.shape[0], P, pattern.nnz
        indptr, indices = pattern.indptr, pattern.indices
        counts = np.diff(indptr)
        rows_nnz = np.repeat(counts * P, P)  # every global row (i, m): P entries per dof entry
        self.indptr = np.concatenate([[0], np.cumsum(rows_nnz)])
        order, cols = [], []
        for i in range(self.n):
            ks = np.arange(indptr[i], indptr[i + 1])
            for m in range(P):
                # (j, l) in row order: for each dof entry k (column j), l = 0..P-1
                src = (m * P + np.arange(P))[None, :] * self.nnz + ks[:, None]
                order.append(src.ravel())
                cols.append((indices[ks][:, None] * P + np.arange(P)[None, :]).ravel())
        self.order = np.concatenate(order) if order else np.zeros(0, dtype=int)
        self.indices = np.concatenate(cols) if cols else np.zeros(0, dtype=int)
        self.position = {}  # (row, col) of the n x n pattern -> entry k, built on demand
        self._keys = (indptr, indices)

    def entries(self, matrix: scipy.sparse.csr_matrix) -> np.ndarray:
        """The entries k of the pattern that ``matrix``'s stored entries occupy (its
        pattern must be a subset), in ``matrix.data``'s order."""
        key = (matrix.indptr.tobytes(), matrix.indices.tobytes())
        got = self.position.get(key)
        if got is None:
            indptr, indices = self._keys
            lookup = scipy.sparse.csr_matrix((np.arange(1, self.nnz + 1), indices, indptr),
                                             shape=(self.n, self.n))
            coo = matrix.tocoo()
            k = np.asarray(lookup[coo.row, coo.col]).ravel() - 1
            if np.any(k < 0):
                raise ValueError("harmonic balance: a tangent's pattern is not within F_U's")
            got = self.position[key] = k
        return got

    def matrix(self, blocks: np.ndarray) -> scipy.sparse.csr_matrix:
        """CSR of size nP from blocks (P, P, nnz) (block (m, l), entry k)."""
        data = blocks.reshape(-1)[self.order]
        size = self.n * self.P
        return scipy.sparse.csr_matrix((data, self.indices, self.indptr), shape=(size, size))
