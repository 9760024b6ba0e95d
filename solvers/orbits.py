"""Periodic orbits of the forced rod (Sec. 5.3, Eq. 70) by shooting, with Floquet stability.

The period map P advances the state X = (U, V, A) of the generalised-alpha
integrator (Chung and Hulbert 1993, the scheme of TSALPHA2, same rho_inf)
over one forcing period T1 = 1/f1 in M equal steps.  A periodic orbit is a
fixed point of P modulo the twist's steady rotation:

    G(X) = P(X) - X - Delta e_alpha = 0,                         (shooting)

e_alpha: a uniform unit twist (U's alpha dofs).  With the controller's
integral action (k1 > 0, Eq. 40) the rotation per period is fixed,
Delta = alpha_dot* T1; without it, the rigid rotation is a symmetry, Delta
is free and one phase condition (the mean twist of X) closes the system.
The torque ramp (69) is taken at its final value (``Normalised.steady_torque``).

One step solves R(z) = F(t_n + alpha_f h, z, V_a(z), A_a(z)) = 0 for the
stage value z = U_{n+alpha_f} (the unknown of TSALPHA2 up to the factor
alpha_f); U_{n+1}, V_{n+1}, A_{n+1}, V_a, A_a are linear in (z, X_n)
(:meth:`AlphaMap.newmark`).  The monodromy dP/dX comes from tangent
propagation through the steps: at a converged step

    J dz = -(F_V dV_a + F_A dA_a)|_{z fixed},  J = F_U + s_V F_V + s_A F_A,

with the step's own factored Jacobian J (NLvib does this for Newmark).
Dirichlet rows (35)-(37) read z - g(t), so their rows of J are unit rows
and they do not depend on X_n.  The Floquet multipliers are the
eigenvalues of the monodromy at the orbit; the n spurious roots of the
scheme (about -rho_inf per step) give multipliers near 0.

Dense linear algebra on one rank: the state has 3 n entries (n dofs), the
monodromy (3n)^2; refused past ``MAX_STATE`` (N = 8, p = 3: 3n = 300).
"""

from __future__ import annotations

import math
import time

import numpy as np
import scipy.linalg
import ufl
from mpi4py import MPI

import dolfinx.fem
import dolfinx.fem.petsc

from rawehelix import compat
from rawehelix.parameters import Parameters
from rawehelix.solvers.dynamics import DynamicsSolver
from rawehelix.solvers.floquet import Orbit, PeriodMap  # noqa: F401  (Orbit re-exported)
from rawehelix.solvers.snes import SolverError

MAX_STATE = 3000  # dense monodromy: (3n)^2 doubles, an LU of n per step


class AlphaMap(PeriodMap):
    """The generalised-alpha period map of the FE rod, with its tangent."""

    def __init__(self, params: Parameters, rho_inf: float = 0.9, comm=MPI.COMM_SELF,
                 solver: DynamicsSolver | None = None):
        if comm.size > 1:
            raise SolverError("orbits: the shooting solver runs on one rank (dense monodromy); "
                              "run separate frequency windows on separate ranks")
        self.params = params
        # solver: a DynamicsSolver of params to share (the chord stepper's backend)
        self.solver = solver or DynamicsSolver.from_stationary(params, comm)
        self.form = form = self.solver.form
        if not form.second_order:
            raise SolverError("orbits: needs the second-order form (alpha2)")
        self.q_base = params.normalised().steady_torque()
        am, af = (2 - rho_inf) / (1 + rho_inf), 1 / (1 + rho_inf)  # Chung-Hulbert
        self.alpha_m, self.alpha_f = am, af
        self.gamma, self.beta = 0.5 + am - af, 0.25 * (1 + am - af) ** 2
        F, trial = form.residual_ufl, self.solver.rod.trial
        self._F = form.F
        self._dF = [dolfinx.fem.form(ufl.derivative(F, f, trial)) for f in (form.u, form.v, form.a)]
        self._mats = [compat.create_matrix(a) for a in self._dF]
        self._rows = {}  # matrix -> row index of each stored entry (fixed pattern)
        self.n = n = compat.petsc_vec(form.u).getLocalSize()
        self._b = np.zeros(form.u.x.array.size)  # one rank: owned dofs only
        if 3 * n > MAX_STATE:
            raise SolverError(f"orbits: the state has 3n = {3 * n} entries; the dense "
                              f"monodromy is limited to {MAX_STATE} (fewer elements or a "
                              f"lower degree)")
        self.bc_dofs = form.bc_dofs  # one rank: every Dirichlet dof is owned
        _, alpha_dofs = compat.collapse(self.solver.rod.W.sub(1))
        self.e_alpha = np.zeros(3 * n)
        self.e_alpha[np.asarray(alpha_dofs)] = 1.0  # a uniform twist of U
        self.controller = self.q_base.k1 != 0.0
        self.floor = self.solver.residual_floor()
        self.newton_iterations = 0  # of the steps, since the last orbit() began
        stationary = self.solver.state()
        self.offset = stationary.offset
        w_t = stationary.w_t if stationary.w_t is not None else np.zeros(n)
        self.X_stationary = np.concatenate([stationary.w, w_t, np.zeros(n)])

    # -- the scheme -----------------------------------------------------------------
    @property
    def scheme(self) -> tuple:
        """(alpha_m, alpha_f, gamma, beta) of the scheme."""
        return self.alpha_m, self.alpha_f, self.gamma, self.beta

    def newmark(self, z, u, v, a, h, scheme=None):
        """(U_{n+1}, V_{n+1}, A_{n+1}, V_a, A_a) from the stage value z and X_n:
        U_a = z = U_n + alpha_f (U_{n+1} - U_n); Newmark's beta/gamma update
        (``scheme``: other (alpha_m, alpha_f, gamma, beta), e.g. alpha2's start)."""
        am, af, g, b = scheme or self.scheme
        u1 = (z - (1 - af) * u) / af
        a1 = (u1 - u - h * v - h * h * (0.5 - b) * a) / (b * h * h)
        v1 = v + h * ((1 - g) * a + g * a1)
        return u1, v1, a1, v + af * (v1 - v), a + am * (a1 - a)

    def set_frequency(self, f1_Hz: float):
        q = self.q_base.at_frequency(f1_Hz, 0.0)
        rod = self.solver.rod
        rod.q = q
        self.form.moving_top = q.moving_end
        self.form.offset.value = self.offset
        self.q = q

    def _load(self, z, va, aa, t):
        form = self.form
        form.set_time(t)
        for f, x in ((form.u, z), (form.v, va), (form.a, aa)):
            compat.petsc_vec(f).setArray(x)

    def _residual(self, z):
        R = compat.assemble_vector_array(self._b, self._F).copy()
        R[self.bc_dofs] = z[self.bc_dofs] - self._g
        return R

    def _dense(self, A, key) -> np.ndarray:
        """An assembled PETSc matrix as a dense array; ``key`` names its (fixed) pattern."""
        indptr, indices, data = A.getValuesCSR()
        rows = self._rows.get(key)
        if rows is None:
            rows = self._rows[key] = np.repeat(np.arange(self.n), np.diff(indptr))
        D = np.zeros((self.n, self.n))
        D[rows, indices] = data
        return D

    def _matrices(self):
        """F_U, F_V, F_A as dense arrays, without Dirichlet rows."""
        out = []
        for k, (A, a) in enumerate(zip(self._mats, self._dF)):
            A.zeroEntries()
            dolfinx.fem.petsc.assemble_matrix(A, a)
            A.assemble()
            out.append(self._dense(A, k))
        return out

    def shifts(self, h, scheme=None) -> tuple[float, float]:
        """(dV_a/dz, dA_a/dz) of :meth:`newmark`: the shifts of TSALPHA2's Jacobian."""
        am, af, g, b = scheme or self.scheme
        return g / (b * h), am / (af * b * h * h)

    def _jacobian(self, Fu, Fv, Fa, h):
        sv, sa = self.shifts(h)
        J = Fu + sv * Fv + sa * Fa
        J[self.bc_dofs, :] = 0.0
        J[self.bc_dofs, self.bc_dofs] = 1.0
        return scipy.linalg.lu_factor(J)

    def step(self, t, h, X, Phi=None):
        """One step from X at t; with Phi (3n x k): the tangent d X_{n+1} = S Phi."""
        n = self.n
        u, v, a = X[:n], X[n:2 * n], X[2 * n:]
        ta = t + self.alpha_f * h
        z = u + self.alpha_f * (h * v + 0.5 * h * h * a)  # predictor: constant acceleration
        self.form.set_time(ta)
        self._g = self.form.bc_values()
        lu = None
        for it in range(20):
            u1, v1, a1, va, aa = self.newmark(z, u, v, a, h)
            self._load(z, va, aa, ta)
            R = self._residual(z)
            norm = np.linalg.norm(R)
            if it > 0 and (norm <= self.floor or np.linalg.norm(dz) <= 1e-12 * (1 + np.linalg.norm(z))):
                break
            Fu, Fv, Fa = self._matrices()
            lu = self._jacobian(Fu, Fv, Fa, h)
            dz = scipy.linalg.lu_solve(lu, R)
            z = z - dz
        else:
            raise SolverError(f"orbits: Newton did not converge in a step at t = {t:.6g} "
                              f"(|R| = {norm:.3g}, floor {self.floor:.3g}); try a smaller step")
        self.newton_iterations += it
        X1 = np.concatenate([u1, v1, a1])
        if Phi is None:
            return X1, None
        Fu, Fv, Fa = self._matrices()  # at the converged step
        lu = self._jacobian(Fu, Fv, Fa, h)
        Pu, Pv, Pa = Phi[:n], Phi[n:2 * n], Phi[2 * n:]
        _, _, _, dva, daa = self.newmark(np.zeros_like(Pu), Pu, Pv, Pa, h)
        rhs = Fv @ dva + Fa @ daa
        rhs[self.bc_dofs] = 0.0
        dz = -scipy.linalg.lu_solve(lu, rhs)
        du1, dv1, da1, _, _ = self.newmark(dz, Pu, Pv, Pa, h)
        return X1, np.vstack([du1, dv1, da1])

    def steps_per_period(self, f1_Hz: float) -> int:
        period = 1.0 / (f1_Hz * self.q_base.t_scale)  # normalised
        return max(8, math.ceil(period / (self.params.time.dt_s / self.q_base.t_scale) - 1e-9))

    def period(self, X, f1_Hz: float, tangent: bool = False, steps: int | None = None,
               on_step=None):
        """P(X) over one period at f1 (phase 0 at t = 0), the tension at s = 0 at
        every step (normalised) and, with ``tangent``, the monodromy dP/dX.
        ``on_step(probes)`` is called after every step with the rod's probes
        (:class:`~rawehelix.solvers.probes.Probes`) at the new state."""
        self.set_frequency(f1_Hz)
        M = steps or self.steps_per_period(f1_Hz)
        T1 = 2 * math.pi / self.q.omega1
        h = T1 / M
        Phi = np.eye(3 * self.n) if tangent else None
        tension = []
        for k in range(M):
            X, Phi = self.step(k * h, h, X, Phi)
            if not np.all(np.isfinite(X)):
                raise SolverError(f"orbits: the state became NaN or Inf at f1 = {f1_Hz} Hz")
            compat.petsc_vec(self.form.u).setArray(X[:self.n])
            tension.append(self.solver.probes.value("tension0"))
            if on_step:
                on_step(self.solver.probes)
        return X, np.array(tension), Phi
