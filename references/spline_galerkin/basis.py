"""Cubic-spline shape functions, Eqs. (41)-(45), and the continuity relations (A1)-(A6).

On element j (s_j <= s <= s_{j+1}, h = 1/N) a field y is written, Eqs. (41)-(42),

    y(s) = y_j N0(xi) + y_{j+1} N1(xi) + h^2 [y''_j H0(xi) + y''_{j+1} H1(xi)],

with the shape functions of Eqs. (43)-(44) and xi of Eq. (45).  The factor h^2
makes y''_j the true second derivative at node j (the paper writes the H for
unit spacing).  Continuity of y' across the nodes gives the nodal second
derivatives as linear functions of the nodal values (Appendix A):

* centre line, natural spline, r''(0) = r''(1) = 0 (Eq. 37): (A1)-(A3);
* twist, clamped spline, alpha'(0) = m0, alpha'(1) = mN (Eqs. 38-39): (A4)-(A6).

Every field and derivative at the Gauss points is then a fixed matrix times
the nodal values (plus the end torques for alpha): this module builds those
matrices.  numpy only.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def shape_functions(xi: np.ndarray):
    """N0, N1, H0, H1 of Eqs. (43)-(44) and their xi-derivatives.

    Returns a dict ``{k: (N0, N1, H0, H1)}`` for derivative order k = 0..3
    with respect to xi.
    """
    xi = np.asarray(xi, dtype=float)
    one, zero = np.ones_like(xi), np.zeros_like(xi)
    return {
        0: (1 - xi, xi, -(xi**3 - 3 * xi**2 + 2 * xi) / 6, (xi**3 - xi) / 6),  # (43)-(44)
        1: (-one, one, -(3 * xi**2 - 6 * xi + 2) / 6, (3 * xi**2 - 1) / 6),
        2: (zero, zero, 1 - xi, xi),
        3: (zero, zero, -one, one),
    }


def natural_second_derivatives(N: int) -> np.ndarray:
    """S with r''_nodes = S @ r_nodes for the natural spline, (A1)-(A3).

    B_r r''_{1..N-1} = C_r r_{0..N} / h^2 with r''_0 = r''_N = 0 (Eq. 37); one
    scalar copy of (A2)-(A3) acts on each Cartesian component.  Shape (N+1, N+1).
    """
    h = 1.0 / N
    S = np.zeros((N + 1, N + 1))
    if N < 2:
        return S
    n = N - 1
    B = np.diag(np.full(n, 2 / 3)) + np.diag(np.full(n - 1, 1 / 6), 1) \
        + np.diag(np.full(n - 1, 1 / 6), -1)  # (A2)
    C = np.zeros((n, N + 1))  # (A3)
    for i in range(n):
        C[i, i:i + 3] = (1.0, -2.0, 1.0)
    S[1:N] = np.linalg.solve(B, C / h**2)  # (A1)
    return S


def clamped_second_derivatives(N: int):
    """S, s0, sN with alpha''_nodes = S @ alpha + s0 m0 + sN mN, (A4)-(A6).

    B_alpha alpha'' = C_alpha alpha / h^2 + (-m0, 0, ..., 0, mN) / h, from
    continuity of alpha' and alpha'(0) = m0, alpha'(1) = mN (Eqs. 38-39).
    """
    h = 1.0 / N
    n = N + 1
    B = np.diag(np.r_[1 / 3, np.full(n - 2, 2 / 3), 1 / 3]) \
        + np.diag(np.full(n - 1, 1 / 6), 1) + np.diag(np.full(n - 1, 1 / 6), -1)  # (A5)
    C = np.zeros((n, n))  # (A6)
    C[0, :2] = (-1.0, 1.0)
    C[-1, -2:] = (1.0, -1.0)
    for i in range(1, n - 1):
        C[i, i - 1:i + 2] = (1.0, -2.0, 1.0)
    Binv = np.linalg.inv(B)
    e0, eN = np.zeros(n), np.zeros(n)
    e0[0], eN[-1] = -1.0 / h, 1.0 / h
    return Binv @ C / h**2, Binv @ e0, Binv @ eN  # (A4)


@dataclass(frozen=True)
class SplineBasis:
    """Values and derivatives of both splines at the Gauss points of all elements.

    Attributes
    ----------
    N : number of elements; nodes s_j = j/N.
    s, w : Gauss points and weights on [0, 1], per element, concatenated.
    D : D[k] (nq, N+1), r^(k)(s_q) = D[k] @ r_nodes (natural spline); column j
        is phi_j^(k) of Eq. (46).
    A : A[k] (nq, N+1), alpha^(k)(s_q) = A[k] @ alpha_nodes + b0[k] m0 + bN[k] mN;
        column j is varphi_j^(k) of Eq. (47) and b0 m0 + bN mN is m(s, t).
    b0, bN : (nq,) each, per k.
    """

    N: int
    s: np.ndarray
    w: np.ndarray
    D: dict
    A: dict
    b0: dict
    bN: dict

    @classmethod
    def build(cls, N: int, n_gauss: int = 6) -> "SplineBasis":
        if N < 2:
            raise ValueError("the spline scheme needs N >= 2 elements")
        xg, wg = np.polynomial.legendre.leggauss(n_gauss)
        xi, wxi = (xg + 1) / 2, wg / 2
        h = 1.0 / N
        nq = N * n_gauss
        shapes = shape_functions(xi)
        Ey = {k: np.zeros((nq, N + 1)) for k in range(4)}
        EM = {k: np.zeros((nq, N + 1)) for k in range(4)}
        for j in range(N):
            rows = slice(j * n_gauss, (j + 1) * n_gauss)
            for k, (N0, N1, H0, H1) in shapes.items():
                Ey[k][rows, j], Ey[k][rows, j + 1] = N0 / h**k, N1 / h**k  # d/ds = (1/h) d/dxi
                EM[k][rows, j], EM[k][rows, j + 1] = h**(2 - k) * H0, h**(2 - k) * H1
        s = np.concatenate([(j + xi) * h for j in range(N)])
        w = np.tile(wxi * h, N)
        Sn = natural_second_derivatives(N)
        Sc, s0, sN = clamped_second_derivatives(N)
        D = {k: Ey[k] + EM[k] @ Sn for k in range(4)}
        A = {k: Ey[k] + EM[k] @ Sc for k in range(4)}
        b0 = {k: EM[k] @ s0 for k in range(4)}
        bN = {k: EM[k] @ sN for k in range(4)}
        return cls(N=N, s=s, w=w, D=D, A=A, b0=b0, bN=bN)
