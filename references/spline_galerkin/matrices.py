"""The constant Galerkin matrices and vectors of Eqs. (50)-(58).

Test functions: phi_i, i = 1..N-1, for the centre line (Eq. 48) and
varphi_i, i = 0..N, for the twist (Eq. 49).  Integrals use the Gauss rule of
:class:`SplineBasis` (exact here: the integrands are polynomials of degree <= 6).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .basis import SplineBasis


@dataclass(frozen=True)
class GalerkinMatrices:
    P0: np.ndarray  # (N-1, N-1), Eq. (50)
    P0N: np.ndarray  # (N-1,), int phi_i phi_N: a_iN = -r''_N(t) P0N, Eq. (51)
    p0: np.ndarray  # (N-1,), int phi_i: p_i = k_E p0_i, Eq. (52)
    P4: np.ndarray  # (N-1, N), j = 1..N, Eq. (58)
    Q0: np.ndarray  # (N+1, N+1), Eq. (53)
    Q1: np.ndarray  # (N+1, N+1), Eq. (57)
    c0: np.ndarray  # (N+1,), int psi_0 varphi_i: Eq. (54) is -(m0'' c0 + mN'' cN)
    cN: np.ndarray  # (N+1,)

    @classmethod
    def build(cls, basis: SplineBasis) -> "GalerkinMatrices":
        N, w = basis.N, basis.w
        phi, phi2 = basis.D[0][:, 1:N], basis.D[2][:, 1:N]
        var0, var1 = basis.A[0], basis.A[1]

        def inner(a, b):
            return a.T @ (w[:, None] * b) if b.ndim == 2 else a.T @ (w * b)

        return cls(
            P0=inner(phi, phi),  # (50)
            P0N=inner(phi, basis.D[0][:, N]),  # (51)
            p0=phi.T @ w,  # (52)
            P4=inner(phi2, basis.D[2][:, 1:]),  # (58)
            Q0=inner(var0, var0),  # (53)
            Q1=inner(var1, var1),  # (57)
            c0=inner(var0, basis.b0[0]),  # (54)
            cN=inner(var0, basis.bN[0]),
        )
