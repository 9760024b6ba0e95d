"""The first-order system (61), M xdot = g(x, t), of the spline-Galerkin scheme.

State, Eqs. (59)-(60), normalised:

    q = [r_1 .. r_{N-1} (3 each, x y z), alpha_0 .. alpha_N]
    x = [q, qdot, m0]            (k2 = 0: the paper's state)
    x = [q, qdot, m0, w]         (k2 > 0: w = dm0/dt is added, see below)

Rows of M xdot = g: qdot = qdot; Eq. (55) for the centre line; Eq. (56) for
the twist; the controller, Eq. (40).

Frenet torsion.  gamma of Eq. (34) divides by |r''|^2, which vanishes on
straight and planar stretches, and gamma' needs r''''.  As the paper's code does,
gamma is dropped: tau = alpha' in F_NL (Eq. 32) and in Eq. (56).  For the
planar states studied here (stationary, Sec. 5.1; spinning, Sec. 5.2) gamma is
zero anyway; it only matters for non-planar, curved configurations.

End torques.  The lifting m(s, t) = m0 psi_0 + mN psi_N of Eq. (47) puts the
second derivatives of the end torques into Eq. (56) through Eq. (54).  mN'' is
known exactly from the ramp (69).  The controller (40) gives
m0' = mN' + k1 (alpha_0' - alpha*') + k2 alpha_0'', hence
m0'' = mN'' + k1 alpha_0'' + k2 alpha_0''': the paper takes alpha_0''' by
backward differences.  Here it is exact instead:

* k2 = 0: m0'' = mN'' + k1 alpha_0'' is linear in the accelerations and goes
  into M (row of Eq. 56 gets k1 c0 in column alpha_0);
* k2 > 0: w = m0' becomes a state; Eq. (56) has c0 w' on its left-hand side
  and the controller (40) is the row k2 alpha_0'' = w - mN' - k1 (alpha_0' - alpha*').
  M stays constant and invertible, so xdot = f(x) is an ordinary ODE, the
  continuous-time limit of the paper's finite differences.

The controller acts on the ground node, alpha_0 ("alpha_1" of Eq. (40) is the
first node).  Everything in :meth:`SplineGalerkin.g` is complex-safe (no abs,
no norms), so Jacobians can be taken by complex step.
"""

from __future__ import annotations

import numpy as np

from rawehelix.parameters import Normalised

from .basis import SplineBasis, natural_second_derivatives, shape_functions
from .matrices import GalerkinMatrices

I_E, K_E = np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.0, 1.0])


def _cross(a, b):
    """Row-wise cross product, complex-safe."""
    return np.stack([a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1],
                     a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2],
                     a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]], axis=1)


def _dot(a, b):
    return np.sum(a * b, axis=1)


class SplineGalerkin:
    """Eq. (61) for one scene at N elements.

    Parameters
    ----------
    nd : normalised parameters (Eqs. 25-29).
    N : number of elements (>= 2).
    n_gauss : Gauss-Legendre points per element.
    """

    def __init__(self, nd: Normalised, N: int, n_gauss: int = 6):
        self.nd, self.N = nd, N
        self.basis = SplineBasis.build(N, n_gauss)
        self.mat = GalerkinMatrices.build(self.basis)
        self.mu = nd.mu * nd.bending  # EI switch
        self.nu = nd.nu * nd.drag
        self.with_rate = nd.k2 > 0  # w = dm0/dt in the state
        n_r, n_a = 3 * (N - 1), N + 1
        self.n_r, self.n_a, self.n_q = n_r, n_a, n_r + n_a
        self.i_m0 = 2 * self.n_q
        self.size = 2 * self.n_q + 1 + int(self.with_rate)
        self.M = self._mass_matrix()
        self.Minv = np.linalg.inv(self.M)

    # -- layout ---------------------------------------------------------------
    def names(self) -> list[str]:
        """Names of the state components: x_1, ..., alpha_0, ..., xdot_1, ..., m_0."""
        pos = [f"{c}_{j}" for j in range(1, self.N) for c in "xyz"]
        pos += [f"alpha_{j}" for j in range(self.N + 1)]
        vel = [n.replace("_", "dot_", 1) for n in pos]
        return pos + vel + ["m_0"] + (["mdot_0"] if self.with_rate else [])

    def split(self, x):
        """(r_int (N-1,3), alpha (N+1), rdot_int, alphadot, m0, w-or-None)."""
        n_r, n_q = self.n_r, self.n_q
        return (x[:n_r].reshape(-1, 3), x[n_r:n_q], x[n_q:n_q + n_r].reshape(-1, 3),
                x[n_q + n_r:2 * n_q], x[self.i_m0],
                x[self.i_m0 + 1] if self.with_rate else None)

    def pack(self, r_int, alpha, rdot_int=None, alphadot=None, m0=0.0, w=0.0):
        x = np.zeros(self.size)
        x[:self.n_r] = np.asarray(r_int).ravel()
        x[self.n_r:self.n_q] = alpha
        if rdot_int is not None:
            x[self.n_q:self.n_q + self.n_r] = np.asarray(rdot_int).ravel()
        if alphadot is not None:
            x[self.n_q + self.n_r:2 * self.n_q] = alphadot
        x[self.i_m0] = m0
        if self.with_rate:
            x[self.i_m0 + 1] = w
        return x

    # -- M of Eq. (61) --------------------------------------------------------
    def _mass_matrix(self) -> np.ndarray:
        n_r, n_q, mat, nd = self.n_r, self.n_q, self.mat, self.nd
        M = np.zeros((self.size, self.size))
        M[:n_q, :n_q] = np.eye(n_q)  # qdot = qdot
        M[n_q:n_q + n_r, n_q:n_q + n_r] = np.kron(mat.P0, np.eye(3))  # (55)
        a = slice(n_q + n_r, 2 * n_q)
        M[a, a] = mat.Q0  # (56)
        if self.with_rate:
            M[a, self.i_m0 + 1] = mat.c0  # c0 m0'' = c0 w'
            M[self.i_m0, self.i_m0] = 1.0  # m0' = w
            M[self.i_m0 + 1, n_q + n_r] = nd.k2  # (40): k2 alpha_0''
        else:
            M[a, n_q + n_r] += nd.k1 * mat.c0  # c0 m0'', m0'' = mN'' + k1 alpha_0''
            M[self.i_m0, self.i_m0] = 1.0  # (40)
        return M

    # -- fields -----------------------------------------------------------------
    def nodes(self, r_int, t, rdot_int=None):
        """Nodal positions (N+1, 3) with r_0 = 0 (35) and r_N(t) (36); and velocities."""
        dtype = np.result_type(r_int, float)
        R = np.zeros((self.N + 1, 3), dtype=dtype)
        R[1:self.N] = r_int
        R[self.N] = self.nd.top_position(t)
        if rdot_int is None:
            return R
        V = np.zeros((self.N + 1, 3), dtype=np.result_type(rdot_int, float))
        V[1:self.N] = rdot_int
        V[self.N] = self.nd.top_velocity(t)
        return R, V

    def tension(self, x, t: float, s: np.ndarray | None = None):
        """T = sigma (|r'| - 1), Eq. (29), at the Gauss points or at the nodes ``s``."""
        R = self.nodes(self.split(x)[0], t)
        if s is None:
            rp = self.basis.D[1] @ R
        else:
            rp = self.derivative_at(np.atleast_1d(s), 1) @ R
        return self.nd.sigma * (np.sqrt(_dot(rp, rp)) - 1.0)

    def derivative_at(self, s: np.ndarray, k: int) -> np.ndarray:
        """Matrix E with r^(k)(s) = E @ r_nodes (natural spline) at arbitrary s."""
        N, h = self.N, 1.0 / self.N
        j = np.clip(np.floor(np.asarray(s) * N).astype(int), 0, N - 1)
        xi = np.asarray(s) * N - j
        N0, N1, H0, H1 = shape_functions(xi)[k]
        Ey, EM = np.zeros((len(s), N + 1)), np.zeros((len(s), N + 1))
        rows = np.arange(len(s))
        Ey[rows, j], Ey[rows, j + 1] = N0 / h**k, N1 / h**k
        EM[rows, j], EM[rows, j + 1] = h**(2 - k) * H0, h**(2 - k) * H1
        return Ey + EM @ natural_second_derivatives(N)

    # -- g of Eq. (61) ------------------------------------------------------------
    def g(self, x, t: float = 0.0) -> np.ndarray:
        """Right-hand side g(x, t) of Eq. (61); complex-safe."""
        nd, mat, B = self.nd, self.mat, self.basis
        r_int, alpha, rdot_int, alphadot, m0, w = self.split(x)
        R, V = self.nodes(r_int, t, rdot_int)
        mN, mN_t, mN_tt = nd.top_torque(t), nd.top_torque_rate(t), nd.top_torque_accel(t)
        wq = B.w[:, None]

        rp, rpp, v = B.D[1] @ R, B.D[2] @ R, B.D[0] @ V  # r', r'', rdot at the Gauss points
        tau = B.A[1] @ alpha + B.b0[1] * m0 + B.bN[1] * mN  # tau = alpha' (gamma dropped), (34)
        T = nd.sigma * (np.sqrt(_dot(rp, rp)) - 1.0)  # (29)
        F_NL = (T - self.mu * _dot(rpp, rpp))[:, None] * rp \
            + nd.beta * tau[:, None] * _cross(rp, rpp)  # (32)
        vA = v + nd.v_w0 * I_E  # v_A = v - v_w, v_w = -v_w0 i_E, (14)
        F_A = -self.nu * np.sqrt(_dot(vA, vA))[:, None] * vA  # (28)

        phi, phi1 = B.D[0][:, 1:self.N], B.D[1][:, 1:self.N]
        rhs_r = (-np.outer(mat.P0N, nd.top_acceleration(t))  # a_iN, (51)
                 + nd.gravity * np.outer(mat.p0, K_E)  # p_i, (52)
                 - self.mu * mat.P4 @ R[1:]  # (55), (58)
                 + phi.T @ (wq * F_A) - phi1.T @ (wq * F_NL))  # (55)

        var1 = B.A[1]
        bnd = np.zeros(self.n_a, dtype=rhs_r.dtype)
        bnd[0], bnd[-1] = -m0, mN  # [tau varphi_i]_0^1, Eqs. (38)-(39)
        # -Q1 alpha - int m_s varphi_i' = -int alpha' varphi_i' (Eq. 57 and the m-term of 56)
        rhs_a = -mat.cN * mN_tt + nd.delta * (bnd - var1.T @ (B.w * tau))  # (56)

        out = np.zeros(self.size, dtype=rhs_r.dtype)
        out[:self.n_q] = x[self.n_q:2 * self.n_q]
        out[self.n_q:self.n_q + self.n_r] = rhs_r.ravel()
        out[self.n_q + self.n_r:2 * self.n_q] = rhs_a
        err = alphadot[0] - nd.spin_target
        if self.with_rate:
            out[self.i_m0] = w  # m0' = w
            out[self.i_m0 + 1] = w - mN_t - nd.k1 * err  # (40)
        else:
            out[self.n_q + self.n_r:2 * self.n_q] -= mat.c0 * mN_tt  # m0'' = mN'' + k1 alpha_0''
            out[self.i_m0] = mN_t + nd.k1 * err  # (40)
        return out

    def f(self, x, t: float = 0.0) -> np.ndarray:
        """xdot = M^-1 g(x, t), Eq. (61)."""
        return self.Minv @ self.g(x, t)

    def jacobian(self, x, t: float = 0.0, h: float = 1e-30) -> np.ndarray:
        """df/dx by complex step: exact to rounding, no step-size trade-off."""
        n = self.size
        X = x[None, :] + 1j * h * np.eye(n)
        return np.stack([self.f(X[k], t).imag / h for k in range(n)], axis=1)
