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

with the step's own Jacobian J at the converged stage (NLvib does this for
Newmark).  Dirichlet rows (35)-(37) read z - g(t), so their rows of J are
unit rows and they do not depend on X_n.  The Floquet multipliers are the
eigenvalues of the monodromy at the orbit; the n spurious roots of the
scheme (about -rho_inf per step) give multipliers near 0.

How a step is solved (docs/explanation/orbits.md, "Cost of a point"):

- chord Newton (:meth:`AlphaMap.solve_stage`, shared with the chord step loop
  of solvers/chord.py, whose docstring describes it): the dense LU of J (the
  formulation's Jacobian form, one assembly) held across iterations and
  steps of one period, refreshed when an iteration contracts by less than
  ``rate``; the predictor extrapolates the last three stage values; Hairer's
  stopping test at ``tol`` = 1e-14 (against 1e-11 for plain stepping),
  which puts P(X) within 2.4e-10 of the steps solved to round-off (the
  former full Newton: 4.6e-11; 1e-13: 3e-9, as A = (z - u) / (alpha_f beta
  h^2) magnifies z's error);
- every period starts with no LU held, so P is a function of (X, f1, M)
  (the branch store's resume is bit for bit);
- the tangent (:meth:`AlphaMap._tangent`) only in a tangent period: F_U, F_V,
  F_A assembled once at the converged stage into scipy CSR matrices on their
  fixed patterns, J = F_U + s_V F_V + s_A F_A on F_U's pattern, SuperLU, the
  3n right-hand sides by sparse products, newmark's map as axpys; a tangent
  period from the (X, f1, M) of the last plain period (the Floquet period
  after the last residual) propagates along its kept steps;
- ``newton="full"``: the former step, full Newton with three dense matrices
  and a dense LU per iteration and a dense tangent (the tests' reference).

Dense monodromy on one rank: the state has 3 n entries (n dofs), the
monodromy (3n)^2; refused past ``MAX_STATE`` (N = 8, p = 3: 3n = 300).
"""

from __future__ import annotations

import math
import time

import numpy as np
import scipy.linalg
import scipy.linalg.blas
import scipy.sparse
import scipy.sparse.linalg
import ufl
from mpi4py import MPI

import dolfinx.fem
import dolfinx.fem.petsc

from rawehelix import compat
from rawehelix.parameters import Parameters
from rawehelix.solvers.dynamics import DynamicsSolver, law_hint
from rawehelix.solvers.floquet import Orbit, PeriodMap  # noqa: F401  (Orbit re-exported)
from rawehelix.solvers.snes import SolverError

AXPY = scipy.linalg.blas.get_blas_funcs("axpy", (np.zeros(1),))
MAX_STATE = 3000  # dense monodromy: (3n)^2 doubles, an LU of n per step
TOL = 1e-14  # the steps' chord Newton (max norm of z, normalised): see docs/explanation/orbits.md
ROUNDOFF = 1e-14  # |dz| / max(1, |z|) at which an iterate is round-off, not a correction
#: weights of the newest-first stage values in the extrapolation of order k
EXTRAPOLATION = {0: (1.0,), 1: (2.0, -1.0), 2: (3.0, -3.0, 1.0), 3: (4.0, -6.0, 4.0, -1.0)}
STALL = 100.0  # |dz| within STALL round-offs that stops contracting: at R's floor
#: hysteretic torsion (floquet.py, "Carried entries"): the largest residual of the solved
#: entries once the carried ones are P's (10 x the shooting's tol), the largest drift of
#: z over a period relative to z, and the distance to 1 of a multiplier of z
CARRIED_TOL, Z_TOL, Z_MULTIPLIER = 1e-6, 1e-6, 1e-3
NEWTON = ("chord", "full")  # the steps' Newton: chord (held LU), or full (the reference)


class AlphaMap(PeriodMap):
    """The generalised-alpha period map of the FE rod, with its tangent.

    The steps' chord Newton (module docstring): ``tol`` Hairer's test on the stage
    value (normalised, max norm), ``rate`` the contraction above which the LU is
    refreshed, ``max_it`` per step, ``order`` of the predictor's extrapolation;
    ``newton="full"``: the former full Newton with dense matrices (a reference)."""

    def __init__(self, params: Parameters, rho_inf: float = 0.9, comm=MPI.COMM_SELF,
                 solver: DynamicsSolver | None = None, tol: float = TOL, rate: float = 0.03,
                 max_it: int = 12, order: int = 2, newton: str = "chord"):
        if newton not in NEWTON:
            raise SolverError(f"orbits: newton {newton!r} is not one of {NEWTON}")
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
        self.z_dofs = np.zeros(0, dtype=int)
        if params.model.torsion_hysteresis.active:  # z and its V and A: carried (floquet.py)
            _, z_dofs = compat.collapse(self.solver.rod.W.sub(2))
            self.z_dofs = np.asarray(z_dofs, dtype=int)
            self.carried = np.concatenate([self.z_dofs, n + self.z_dofs, 2 * n + self.z_dofs])
        self.controller = self.q_base.k1 != 0.0
        self.floor = self.solver.residual_floor()
        self.newton_iterations = 0  # of the steps, since the last orbit() began
        # the steps' chord Newton (module docstring): tol, rate, max_it per step, order
        # of the predictor's extrapolation; LU factors of J by (scheme, h)
        self.newton, self.tol, self.rate, self.max_it, self.order = newton, tol, rate, max_it, order
        self._lu = {}
        self.iterations = self.factorisations = self.steps = 0
        self._J = compat.create_matrix(form.J)
        self._getrs = scipy.linalg.get_lapack_funcs("getrs", (np.zeros(1),))
        interior = np.ones(n)
        interior[self.bc_dofs] = 0.0  # the tangent's J: unit Dirichlet rows
        self._interior, self._unit = scipy.sparse.diags(interior), scipy.sparse.diags(1.0 - interior)
        self.stage = None  # the last step's stage value z
        self._sparse, self._newmark_matrix = {}, {}  # the tangent's CSR matrices, newmark's
        self._kept = None  # the steps of the last period without tangent (period())
        stationary = self.solver.state()
        self.offset = stationary.offset
        w_t = stationary.w_t if stationary.w_t is not None else np.zeros(n)
        self.X_stationary = np.concatenate([stationary.w, w_t, np.zeros(n)])

    #: the defects allowed at an orbit (floquet.py, "Carried entries"; docs/explanation/orbits.md)
    defect_tolerances = {"carried": CARRIED_TOL, "z": Z_TOL}

    def defects(self, G, X, Phi) -> dict:
        """floquet's carried defect and, with the hysteretic torsion, z's own:
        |G_z| / max(1, |z|), z's drift over one period relative to z."""
        out = super().defects(G, X, Phi)
        if self.z_dofs.size:
            z = self.z_dofs
            out["z"] = float(np.linalg.norm(G[z]) / max(1.0, np.linalg.norm(X[z])))
        return out

    def defect_meaning(self, name: str) -> str:
        if name == "z":
            return ("the hysteretic torsion's internal twist z still drifts over a period "
                    "with the rod periodic (its multipliers are 1 - O(beta x twist travel), "
                    "so the shooting carries z instead of solving for it); more lead-in "
                    "periods, or 'rawehelix sweep'")
        return super().defect_meaning(name)

    @property
    def needs_vectors(self) -> bool:
        return bool(self.z_dofs.size)

    def set_aside(self, mu, vectors):
        """z's multipliers: real within Z_MULTIPLIER of 1, their eigenvector mostly
        z in U (|v_z| > |v_U| / 2); 1 - mu ~ beta x the twist's travel per period,
        how much of a change of z a period forgets (docs/explanation/orbits.md)."""
        U = vectors[:self.n]
        share = np.linalg.norm(U[self.z_dofs], axis=0) / np.maximum(
            np.linalg.norm(U, axis=0), 1e-300)
        return (np.abs(mu - 1.0) <= Z_MULTIPLIER) & (share > 0.5)

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

    # -- one step -------------------------------------------------------------------
    def predict(self, history, u, v, a, h):
        """The stage value's predictor: the last ``order`` + 1 stage values
        (``history``, newest first) extrapolated in t, or, with fewer, constant
        acceleration from (u, v, a)."""
        if len(history) < self.order + 1:
            return u + self.alpha_f * (h * v + 0.5 * h * h * a)
        return sum(c * zk for c, zk in zip(EXTRAPOLATION[self.order], history))

    def _factor(self, key, h, scheme):
        """LU of J = F_U + s_V F_V + s_A F_A at the loaded stage (the formulation's
        TSALPHA2 Jacobian form, one assembly; Dirichlet rows and columns unit)."""
        form = self.form
        form.shift_v.value, form.shift_a.value = self.shifts(h, scheme)
        form.assemble_jacobian(self._J)
        self._lu[key] = lu = scipy.linalg.lu_factor(self._dense(self._J, "J"), check_finite=False)
        self.factorisations += 1
        return lu

    def solve_stage(self, t, h, u, v, a, z, scheme=None):
        """One step from (u, v, a) at t with the predictor z, by chord Newton
        (module docstring): (U, V, A)_{n+1} and z."""
        scheme = scheme or self.scheme
        sv, sa = self.shifts(h, scheme)
        ta = t + scheme[1] * h
        form = self.form
        form.set_time(ta)
        z = z.copy()
        z[self.bc_dofs] = self._g = form.bc_values()  # so R's Dirichlet rows stay 0
        _, _, _, va, aa = self.newmark(z, u, v, a, h, scheme)
        key = (scheme, h)
        lu = self._lu.get(key)
        fresh, last = False, None
        noise = ROUNDOFF * max(1.0, abs(z).max())
        x_u, x_v, x_a = form.u.x.array, form.v.x.array, form.a.x.array
        for it in range(1, self.max_it + 1):
            x_u[:] = z
            x_v[:] = va
            x_a[:] = aa
            if lu is None:
                lu, fresh, last = self._factor(key, h, scheme), True, None
            R = compat.assemble_vector_array(self._b, self._F)
            R[self.bc_dofs] = 0.0
            dz, info = self._getrs(lu[0], lu[1], R)
            size = abs(dz).max()
            if not size < math.inf:  # NaN or Inf
                raise SolverError(f"chord alpha2: the state became NaN or Inf at t = {t:.6g} "
                                  f"(normalised)")
            at_floor = size <= noise  # at round-off: R(z) is at its floor
            theta = None if at_floor or last is None else size / last
            if theta is not None and theta >= 1.0:  # diverging: back, and a fresh Jacobian
                if size <= STALL * noise:  # no: stalled at R's round-off, z is converged
                    break
                if fresh:
                    raise SolverError(
                        f"chord alpha2: Newton diverges with a fresh Jacobian at t = {t:.6g} "
                        f"(normalised; contraction {theta:.2g}); try a smaller step (time.dt_s)")
                lu = None
                self._lu.pop(key, None)
                continue
            z -= dz
            va -= sv * dz
            aa -= sa * dz
            self.iterations += 1
            if at_floor:
                break
            if theta is not None:
                eta = theta / (1.0 - theta)  # |z - z*| <= eta |dz| while theta holds
                if eta * size <= self.tol:
                    if theta > self.rate:  # slow: a fresh LU at the next step
                        self._lu.pop(key, None)
                    break
                if theta > self.rate:  # slow: a fresh LU now
                    self._lu.pop(key, None)
                    lu, fresh = None, False
                    continue
            last = size
        else:
            raise SolverError(
                f"chord alpha2: no convergence in {self.max_it} iterations at t = {t:.6g} "
                f"(normalised; last |dz| = {size:.3g}, tol {self.tol:g}); try a smaller step "
                f"(time.dt_s)")
        self.steps += 1
        am, af = scheme[:2]  # newmark's U_a, V_a, A_a solved for the step's end
        return u + (z - u) / af, v + (va - v) / af, a + (aa - a) / am, z

    def step(self, t, h, X, Phi=None, z=None):
        """One step from X at t (``z``: the stage value's predictor, constant
        acceleration if None); with Phi (3n x k): the tangent d X_{n+1} = S Phi.
        The converged stage value is left in :attr:`stage`."""
        n = self.n
        u, v, a = X[:n], X[n:2 * n], X[2 * n:]
        if z is None:
            z = self.predict((), u, v, a, h)
        if self.newton == "full":
            return self._step_full(t, h, u, v, a, z, Phi)
        before = self.iterations
        u1, v1, a1, self.stage = self.solve_stage(t, h, u, v, a, z)
        self.newton_iterations += self.iterations - before
        X1 = np.concatenate([u1, v1, a1])
        if Phi is None:
            return X1, None
        return X1, self._tangent(self.stage, u, v, a, h, Phi)

    def _csr(self):
        """F_U, F_V, F_A at the loaded stage as scipy CSR matrices on their fixed
        patterns (Dirichlet rows included: the callers overwrite them); J's
        pattern is F_U's, which holds F_V's and F_A's."""
        out = []
        for k, (A, a) in enumerate(zip(self._mats, self._dF)):
            A.zeroEntries()
            dolfinx.fem.petsc.assemble_matrix(A, a)
            A.assemble()
            indptr, indices, data = A.getValuesCSR()
            S = self._sparse.get(k)
            if S is None or S.nnz != data.size:  # the first assembly: the pattern
                S = self._sparse[k] = scipy.sparse.csr_matrix((data, indices, indptr),
                                                              shape=(self.n, self.n))
            else:
                S.data[:] = data
            out.append(S)
        if "J" not in self._sparse:  # J = F_U + s_V F_V + s_A F_A on F_U's pattern
            Fu = out[0]
            rows = np.repeat(np.arange(self.n), np.diff(Fu.indptr))
            keys = rows * self.n + Fu.indices
            order = np.argsort(keys)
            self._into_J = []
            for S in out[1:]:
                r = np.repeat(np.arange(self.n), np.diff(S.indptr))
                pos = order[np.searchsorted(keys, r * self.n + S.indices, sorter=order)]
                if not np.array_equal(keys[pos], r * self.n + S.indices):
                    raise SolverError("orbits: F_V or F_A has an entry outside F_U's pattern")
                self._into_J.append(pos)
            bc = np.isin(rows, self.bc_dofs)
            self._bc_entries = np.flatnonzero(bc)
            self._bc_diagonal = np.flatnonzero(bc & (rows == Fu.indices))
            # J^T in CSC is J in CSR: SuperLU factors it, and solves with trans="T"
            self._sparse["J"] = scipy.sparse.csc_matrix((Fu.data.copy(), Fu.indices, Fu.indptr),
                                                        shape=(self.n, self.n))
        return out

    def _coefficients(self, h) -> np.ndarray:
        """:meth:`newmark` as a 5 x 4 matrix: (U_{n+1}, V_{n+1}, A_{n+1}, V_a, A_a)
        against (z, U_n, V_n, A_n), exact zeros where an output does not depend on
        an input."""
        C = self._newmark_matrix.get(h)
        if C is None:
            C = self._newmark_matrix[h] = np.array(
                [self.newmark(*np.eye(4)[j], h) for j in range(4)]).T
        return C

    @staticmethod
    def _combine(coefficients, blocks, out):
        """out = sum c_j blocks_j in place (BLAS axpy on contiguous blocks),
        skipping exact zero coefficients."""
        flat = out.reshape(-1)
        flat[:] = 0.0
        for c, B in zip(coefficients, blocks):
            if c != 0.0:
                AXPY(B.reshape(-1), flat, a=c)
        return out

    def _tangent(self, z, u, v, a, h, Phi):
        """S Phi at the converged step (module docstring), sparse: J dz = -(F_V dV_a
        + F_A dA_a) with J's Dirichlet rows unit, J by SuperLU."""
        n = self.n
        form = self.form
        _, _, _, va, aa = self.newmark(z, u, v, a, h)
        form.u.x.array[:], form.v.x.array[:], form.a.x.array[:] = z, va, aa  # time: the step's
        Fu, Fv, Fa = self._csr()
        sv, sa = self.shifts(h)
        J = self._sparse["J"]
        J.data[:] = Fu.data
        J.data[self._into_J[0]] += sv * Fv.data
        J.data[self._into_J[1]] += sa * Fa.data
        J.data[self._bc_entries] = 0.0
        J.data[self._bc_diagonal] = 1.0
        lu = scipy.sparse.linalg.splu(J, permc_spec="MMD_AT_PLUS_A")
        C = self._coefficients(h)
        P = (Phi[:n], Phi[n:2 * n], Phi[2 * n:])
        work = np.empty_like(P[0])
        rhs = Fv @ self._combine(C[3, 1:], P, work)  # dV_a and dA_a with z held
        rhs += Fa @ self._combine(C[4, 1:], P, work)
        rhs[self.bc_dofs] = 0.0
        dz = lu.solve(rhs, trans="T")
        dz *= -1.0
        out = np.empty_like(Phi)
        for k in range(3):  # d(U, V, A)_{n+1}
            self._combine(C[k], (dz, *P), out[k * n:(k + 1) * n])
        return out

    # -- the former step (newton="full"): the reference of the tests -----------------
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

    def _step_full(self, t, h, u, v, a, z, Phi):
        """Full Newton, three dense matrices and a dense LU per iteration, the
        tangent by dense products (the solver before the chord)."""
        n = self.n
        ta = t + self.alpha_f * h
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
        self.stage = z
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

    def linear_monodromy(self, X, f1_Hz: float, steps: int | None = None) -> np.ndarray:
        """S^M: the tangent S of the period's first step from X (at t = 0, h = T1 / M)
        to the M-th power (by squaring), the monodromy of the scheme on the
        time-invariant linearisation about that step.  A chord for the shooting
        (:meth:`PeriodMap.orbit`, ``linear``) where the orbit hardly varies over the
        period: it turns each lightly damped multiplier by that mode's angle over
        this T1, which a neighbouring orbit's monodromy does not.  Measured (N = 8,
        from the orbit at the f1 before): at 4.34 Hz it costs 0.13 s against a
        tangent period's 1.22 s, its largest multiplier 0.96502 is the exact one
        to 5 digits, and Newton takes 9 periods instead of 5; at 0.6 Hz 0.16 s
        against 8.54 s, 0.940 against 0.960, and 8 periods instead of 6."""
        self.set_frequency(f1_Hz)
        M = steps or self.steps_per_period(f1_Hz)
        self._lu = {}
        _, S = self.step(0.0, 2 * math.pi / self.q.omega1 / M, X, np.eye(3 * self.n))
        return np.linalg.matrix_power(S, M)

    def period(self, X, f1_Hz: float, tangent: bool = False, steps: int | None = None,
               on_step=None):
        """P(X) over one period at f1 (phase 0 at t = 0), the tension at s = 0 at
        every step (normalised) and, with ``tangent``, the monodromy dP/dX.
        ``on_step(probes)`` is called after every step with the rod's probes
        (:class:`~rawehelix.solvers.probes.Probes`) at the new state.  The
        steps of the last period without tangent are kept: a tangent period
        from the same (X, f1, M) (the shooting's and the continuation's
        Floquet period after their last residual) propagates the tangent along
        them instead of solving them again (the same numbers: the steps start
        from no held LU, so they are a function of (X, f1, M))."""
        self.set_frequency(f1_Hz)
        M = steps or self.steps_per_period(f1_Hz)
        T1 = 2 * math.pi / self.q.omega1
        h = T1 / M
        key = (f1_Hz, M)
        kept = self._kept
        if (tangent and on_step is None and kept is not None and kept[0] == key  # chord only
                and np.array_equal(kept[1][0], X)):
            return self._replay(kept, h)
        Phi = np.eye(3 * self.n) if tangent else None
        self._lu = {}  # no LU held from another period: P is a function of (X, f1, M)
        tension, history, n = [], [], self.n
        trajectory = [X]  # X_k, then each step's stage value and X_{k+1}
        for k in range(M):
            z = self.predict(history, X[:n], X[n:2 * n], X[2 * n:], h)
            try:
                X, Phi = self.step(k * h, h, X, Phi, z)
            except SolverError as err:
                hint = law_hint(self.params)
                if not hint:
                    raise
                raise SolverError(str(err) + hint) from err
            history = [self.stage] + history[:self.order]
            if not np.all(np.isfinite(X)):
                raise SolverError(f"orbits: the state became NaN or Inf at f1 = {f1_Hz} Hz")
            compat.petsc_vec(self.form.u).setArray(X[:self.n])
            tension.append(self.solver.probes.value("tension0"))
            if on_step:
                on_step(self.solver.probes)
            trajectory += [self.stage, X]
        tension = np.array(tension)
        self._kept = (key, trajectory, tension) if not tangent and self.newton == "chord" else None
        return X, tension, Phi

    def _replay(self, kept, h):
        """The tangent period along the kept steps (:meth:`period`)."""
        _, trajectory, tension = kept
        n, Phi = self.n, np.eye(3 * self.n)
        for k in range(len(trajectory) // 2):
            X, z = trajectory[2 * k], trajectory[2 * k + 1]
            self.form.set_time((k + self.alpha_f) * h)
            Phi = self._tangent(z, X[:n], X[n:2 * n], X[2 * n:], h, Phi)
        return trajectory[-1].copy(), tension.copy(), Phi
