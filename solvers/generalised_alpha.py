"""The generalised-alpha stepper of the FE rod (Chung and Hulbert 1993, the scheme of
TSALPHA2, same rho_inf), with chord Newton on the stage value and tangent propagation.

One step solves R(z) = F(t_n + alpha_f h, z, V_a(z), A_a(z)) = 0 for the stage
value z = U_{n+alpha_f} (the unknown of TSALPHA2 up to the factor alpha_f);
U_{n+1}, V_{n+1}, A_{n+1}, V_a, A_a are linear in (z, X_n)
(:meth:`AlphaStepper.newmark`).  The tangent of a step comes from the step's own
Jacobian at the converged stage (NLvib does this for Newmark):

    J dz = -(F_V dV_a + F_A dA_a)|_{z fixed},  J = F_U + s_V F_V + s_A F_A.

Dirichlet rows (35)-(37) read z - g(t), so their rows of J are unit rows and
they do not depend on X_n.

How a step is solved (docs/explanation/orbits.md, "Cost of a point"):

- chord Newton (:meth:`AlphaStepper.solve_stage`, described in solvers/chord.py's
  docstring): the dense LU of J (the formulation's Jacobian form, one assembly)
  held across iterations and steps, refreshed when an iteration contracts by
  less than ``rate``; the predictor extrapolates the last three stage values;
  Hairer's stopping test at ``tol`` (1e-14 for the orbits, which puts P(X)
  within 2.4e-10 of the steps solved to round-off; 1e-11 for plain stepping);
- the tangent (:meth:`AlphaStepper.tangent`): F_U, F_V, F_A assembled once at
  the converged stage into scipy CSR matrices on their fixed patterns, J = F_U +
  s_V F_V + s_A F_A on F_U's pattern, SuperLU, the 3n right-hand sides by sparse
  products, newmark's map as axpys;
- ``newton="full"``: the former step, full Newton with three dense matrices and
  a dense LU per iteration and a dense tangent (the tests' reference).

The operator F and the state's layout are :class:`~rawehelix.solvers.rod_operator.RodOperator`'s.
Dense LU of n on one rank: refused past ``MAX_STATE`` (3n).
"""

from __future__ import annotations

import math

import numpy as np
import scipy.linalg
import scipy.linalg.blas
import scipy.sparse
import scipy.sparse.linalg

from rawehelix.solvers.rod_operator import RodOperator
from rawehelix.solvers.snes import SolverError

AXPY = scipy.linalg.blas.get_blas_funcs("axpy", (np.zeros(1),))
MAX_STATE = 3000  # dense monodromy: (3n)^2 doubles, an LU of n per step
TOL = 1e-14  # the steps' chord Newton (max norm of z, normalised): see docs/explanation/orbits.md
ROUNDOFF = 1e-14  # |dz| / max(1, |z|) at which an iterate is round-off, not a correction
#: weights of the newest-first stage values in the extrapolation of order k
EXTRAPOLATION = {0: (1.0,), 1: (2.0, -1.0), 2: (3.0, -3.0, 1.0), 3: (4.0, -6.0, 4.0, -1.0)}
STALL = 100.0  # |dz| within STALL round-offs that stops contracting: at R's floor
NEWTON = ("chord", "full")  # the steps' Newton: chord (held LU), or full (the reference)


def check_newton(newton: str):
    """Refuse a Newton other than NEWTON's (before anything is built)."""
    if newton not in NEWTON:
        raise SolverError(f"orbits: newton {newton!r} is not one of {NEWTON}")


class AlphaStepper:
    """Steps of the generalised-alpha scheme on a :class:`RodOperator`.

    The chord Newton (module docstring): ``tol`` Hairer's test on the stage
    value (normalised, max norm), ``rate`` the contraction above which the LU is
    refreshed, ``max_it`` per step, ``order`` of the predictor's extrapolation;
    ``newton="full"``: the former full Newton with dense matrices (a reference)."""

    def __init__(self, op: RodOperator, rho_inf: float = 0.9, tol: float = TOL,
                 rate: float = 0.03, max_it: int = 12, order: int = 2, newton: str = "chord"):
        check_newton(newton)
        self.op = op
        self.n = n = op.n
        if 3 * n > MAX_STATE:
            raise SolverError(f"orbits: the state has 3n = {3 * n} entries; the dense "
                              f"monodromy is limited to {MAX_STATE} (fewer elements or a "
                              f"lower degree)")
        am, af = (2 - rho_inf) / (1 + rho_inf), 1 / (1 + rho_inf)  # Chung-Hulbert
        self.alpha_m, self.alpha_f = am, af
        self.gamma, self.beta = 0.5 + am - af, 0.25 * (1 + am - af) ** 2
        self.bc_dofs = op.bc_dofs
        self.newton, self.tol, self.rate, self.max_it, self.order = newton, tol, rate, max_it, order
        self._lu = {}  # LU factors of J by (scheme, h)
        self.iterations = self.factorisations = self.steps = 0
        self._J = op.create_jacobian()
        self._getrs = scipy.linalg.get_lapack_funcs("getrs", (np.zeros(1),))
        self.stage = None  # the last step's stage value z
        self._J_csc, self._newmark_matrix = None, {}  # the tangent's J, newmark's matrices

    def forget(self):
        """No LU held: the next steps are a function of their start alone."""
        self._lu = {}

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

    def shifts(self, h, scheme=None) -> tuple[float, float]:
        """(dV_a/dz, dA_a/dz) of :meth:`newmark`: the shifts of TSALPHA2's Jacobian."""
        am, af, g, b = scheme or self.scheme
        return g / (b * h), am / (af * b * h * h)

    # -- one step -------------------------------------------------------------------
    def predict(self, history, u, v, a, h):
        """The stage value's predictor: the last ``order`` + 1 stage values
        (``history``, newest first) extrapolated in t, or, with fewer, constant
        acceleration from (u, v, a)."""
        if len(history) < self.order + 1:
            return u + self.alpha_f * (h * v + 0.5 * h * h * a)
        return sum(c * zk for c, zk in zip(EXTRAPOLATION[self.order], history))

    def _factor(self, key, h, scheme):
        """LU of J = F_U + s_V F_V + s_A F_A at the loaded stage."""
        J = self.op.assemble_jacobian(self._J, *self.shifts(h, scheme))
        self._lu[key] = lu = scipy.linalg.lu_factor(J, check_finite=False)
        self.factorisations += 1
        return lu

    def solve_stage(self, t, h, u, v, a, z, scheme=None):
        """One step from (u, v, a) at t with the predictor z, by chord Newton
        (module docstring): (U, V, A)_{n+1} and z."""
        scheme = scheme or self.scheme
        sv, sa = self.shifts(h, scheme)
        op = self.op
        op.set_time(t + scheme[1] * h)
        z = z.copy()
        z[self.bc_dofs] = self._g = op.bc_values()  # so R's Dirichlet rows stay 0
        _, _, _, va, aa = self.newmark(z, u, v, a, h, scheme)
        key = (scheme, h)
        lu = self._lu.get(key)
        fresh, last = False, None
        noise = ROUNDOFF * max(1.0, abs(z).max())
        x_u, x_v, x_a = op.arrays()
        for it in range(1, self.max_it + 1):
            x_u[:] = z
            x_v[:] = va
            x_a[:] = aa
            if lu is None:
                lu, fresh, last = self._factor(key, h, scheme), True, None
            R = op.residual()
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
        u1, v1, a1, self.stage = self.solve_stage(t, h, u, v, a, z)
        X1 = np.concatenate([u1, v1, a1])
        if Phi is None:
            return X1, None
        return X1, self.tangent(self.stage, u, v, a, h, Phi)

    # -- the tangent ----------------------------------------------------------------
    def _jacobian_csc(self, out):
        """J's storage on F_U's pattern (``out``: F_U, F_V, F_A), with where F_V's and
        F_A's entries and the Dirichlet rows sit in it (once: the patterns are fixed)."""
        n, Fu = self.n, out[0]
        rows = np.repeat(np.arange(n), np.diff(Fu.indptr))
        keys = rows * n + Fu.indices
        order = np.argsort(keys)
        self._into_J = []
        for S in out[1:]:
            r = np.repeat(np.arange(n), np.diff(S.indptr))
            pos = order[np.searchsorted(keys, r * n + S.indices, sorter=order)]
            if not np.array_equal(keys[pos], r * n + S.indices):
                raise SolverError("orbits: F_V or F_A has an entry outside F_U's pattern")
            self._into_J.append(pos)
        bc = np.isin(rows, self.bc_dofs)
        self._bc_entries = np.flatnonzero(bc)
        self._bc_diagonal = np.flatnonzero(bc & (rows == Fu.indices))
        # J^T in CSC is J in CSR: SuperLU factors it, and solves with trans="T"
        self._J_csc = scipy.sparse.csc_matrix((Fu.data.copy(), Fu.indices, Fu.indptr),
                                              shape=(n, n))

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

    def tangent(self, z, u, v, a, h, Phi):
        """S Phi at the converged step (module docstring), sparse: J dz = -(F_V dV_a
        + F_A dA_a) with J's Dirichlet rows unit, J by SuperLU.  The time: the step's."""
        n = self.n
        _, _, _, va, aa = self.newmark(z, u, v, a, h)
        x_u, x_v, x_a = self.op.arrays()
        x_u[:], x_v[:], x_a[:] = z, va, aa
        Fu, Fv, Fa = out = self.op.csr()
        if self._J_csc is None:
            self._jacobian_csc(out)
        sv, sa = self.shifts(h)
        J = self._J_csc
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
    def _residual(self, z):
        R = self.op.residual().copy()
        R[self.bc_dofs] = z[self.bc_dofs] - self._g
        return R

    def _jacobian(self, Fu, Fv, Fa, h):
        sv, sa = self.shifts(h)
        J = Fu + sv * Fv + sa * Fa
        J[self.bc_dofs, :] = 0.0
        J[self.bc_dofs, self.bc_dofs] = 1.0
        return scipy.linalg.lu_factor(J)

    def _step_full(self, t, h, u, v, a, z, Phi):
        """Full Newton, three dense matrices and a dense LU per iteration, the
        tangent by dense products (the solver before the chord)."""
        n, op = self.n, self.op
        ta = t + self.alpha_f * h
        op.set_time(ta)
        self._g = op.bc_values()
        lu = None
        for it in range(20):
            u1, v1, a1, va, aa = self.newmark(z, u, v, a, h)
            op.set_time(ta)
            op.load(z, va, aa)
            R = self._residual(z)
            norm = np.linalg.norm(R)
            if it > 0 and (norm <= op.floor or np.linalg.norm(dz) <= 1e-12 * (1 + np.linalg.norm(z))):
                break
            Fu, Fv, Fa = op.matrices()
            lu = self._jacobian(Fu, Fv, Fa, h)
            dz = scipy.linalg.lu_solve(lu, R)
            z = z - dz
        else:
            raise SolverError(f"orbits: Newton did not converge in a step at t = {t:.6g} "
                              f"(|R| = {norm:.3g}, floor {op.floor:.3g}); try a smaller step")
        self.iterations += it
        self.stage = z
        X1 = np.concatenate([u1, v1, a1])
        if Phi is None:
            return X1, None
        Fu, Fv, Fa = op.matrices()  # at the converged step
        lu = self._jacobian(Fu, Fv, Fa, h)
        Pu, Pv, Pa = Phi[:n], Phi[n:2 * n], Phi[2 * n:]
        _, _, _, dva, daa = self.newmark(np.zeros_like(Pu), Pu, Pv, Pa, h)
        rhs = Fv @ dva + Fa @ daa
        rhs[self.bc_dofs] = 0.0
        dz = -scipy.linalg.lu_solve(lu, rhs)
        du1, dv1, da1, _, _ = self.newmark(dz, Pu, Pv, Pa, h)
        return X1, np.vstack([du1, dv1, da1])
