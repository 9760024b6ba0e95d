"""The FE rod's operator F(t, U, V, A) and its state layout, for the steppers that
do not go through PETSc TS (the generalised-alpha stepper, the periodic orbits).

F is the formulation's TSALPHA2 residual form (the second-order form, Eq. 70's
semi-discretisation) with (U, V, A) its three functions; F_U, F_V and F_A are
its derivatives by ``ufl.derivative``, assembled on their fixed sparse patterns
(as scipy CSR, or dense: the tests' reference).  The state X = (U, V, A) has 3n
entries (n dofs, one rank: the owned dofs only).

This is the one place of the orbit solvers that names the rod's fields: the
twist alpha (a uniform twist ``e_alpha``, the shooting's symmetry), the internal
twist z of the hysteretic torsion (``z_dofs``, carried by the shooting) and the
position r (the tension map T(0) = sigma (|r'(0)| - 1), Eq. 29).
"""

from __future__ import annotations

import math

import numpy as np
import scipy.sparse
import ufl

import dolfinx.fem
import dolfinx.fem.petsc

from rawehelix import compat
from rawehelix.forms import kinematics
from rawehelix.parameters import Parameters
from rawehelix.solvers.dynamics import DynamicsSolver
from rawehelix.solvers.snes import SolverError


class RodOperator:
    """F, F_U, F_V, F_A of the FE rod and the layout of its state X = (U, V, A).

    ``solver``: a DynamicsSolver of ``params`` to share (its formulation, its
    probes); a new one from the stationary state if None."""

    def __init__(self, params: Parameters, comm, solver: DynamicsSolver | None = None):
        self.params = params
        self.solver = solver or DynamicsSolver.from_stationary(params, comm)
        self.form = form = self.solver.form
        if not form.second_order:
            raise SolverError("orbits: needs the second-order form (alpha2)")
        F, trial = form.residual_ufl, self.solver.rod.trial
        self.F = form.F
        self._dF = [dolfinx.fem.form(ufl.derivative(F, f, trial)) for f in (form.u, form.v, form.a)]
        self._mats = [compat.create_matrix(a) for a in self._dF]
        self._rows = {}  # matrix -> row index of each stored entry (fixed pattern)
        self._sparse = {}  # F_U, F_V, F_A as CSR on their fixed patterns
        self.n = n = compat.petsc_vec(form.u).getLocalSize()
        self._b = np.zeros(form.u.x.array.size)  # one rank: owned dofs only
        self.bc_dofs = form.bc_dofs  # one rank: every Dirichlet dof is owned
        # -- the layout: the rod's fields in X = (U, V, A) --------------------------------
        self.e_alpha = np.zeros(3 * n)
        self.e_alpha[self.solver.rod.dofs("twist")] = 1.0  # a uniform twist of U
        # the model's internal variables (z of the hysteretic torsion) and their V and
        # A: carried by the shooting (floquet.py); none without hysteresis
        self.z_dofs = self.solver.rod.dofs("internal_twist")
        self.floor = self.solver.residual_floor()
        stationary = self.solver.state()
        self.offset = stationary.offset
        w_t = stationary.w_t if stationary.w_t is not None else np.zeros(n)
        self.X_stationary = np.concatenate([stationary.w, w_t, np.zeros(n)])
        self._D = None  # the tension map's rows (tension0)

    @property
    def carried(self) -> np.ndarray:
        """The entries of X of the internal variables: z and its V and A (or none)."""
        z, n = self.z_dofs, self.n
        return np.concatenate([z, n + z, 2 * n + z])

    def load_forcing(self, q):
        """The forcing's normalised parameters ``q`` (at one f1) into the rod and the form."""
        self.solver.rod.q = q
        self.form.moving_top = q.moving_end
        self.form.offset.value = self.offset

    # -- F and its derivatives --------------------------------------------------------
    def set_time(self, t):
        self.form.set_time(t)

    def bc_values(self):
        """The Dirichlet values g(t) (35)-(37) at the time set."""
        return self.form.bc_values()

    def arrays(self):
        """The arrays of U, V, A the forms read."""
        form = self.form
        return form.u.x.array, form.v.x.array, form.a.x.array

    def load(self, z, va, aa):
        """(U, V, A) = (z, va, aa) into the forms' functions (PETSc vectors)."""
        form = self.form
        for f, x in ((form.u, z), (form.v, va), (form.a, aa)):
            compat.petsc_vec(f).setArray(x)

    def residual(self) -> np.ndarray:
        """F at the loaded state (the operator's own array: copy to keep it)."""
        return compat.assemble_vector_array(self._b, self.F)

    def create_jacobian(self):
        return compat.create_matrix(self.form.J)

    def assemble_jacobian(self, J, sv, sa) -> np.ndarray:
        """J = F_U + s_V F_V + s_A F_A at the loaded state, dense (the formulation's
        TSALPHA2 Jacobian form, one assembly; Dirichlet rows and columns unit)."""
        form = self.form
        form.shift_v.value, form.shift_a.value = sv, sa
        form.assemble_jacobian(J)
        return self.dense(J, "J")

    def dense(self, A, key) -> np.ndarray:
        """An assembled PETSc matrix as a dense array; ``key`` names its (fixed) pattern."""
        indptr, indices, data = A.getValuesCSR()
        rows = self._rows.get(key)
        if rows is None:
            rows = self._rows[key] = np.repeat(np.arange(self.n), np.diff(indptr))
        D = np.zeros((self.n, self.n))
        D[rows, indices] = data
        return D

    def _assembled(self):
        for A, a in zip(self._mats, self._dF):
            A.zeroEntries()
            dolfinx.fem.petsc.assemble_matrix(A, a)
            A.assemble()
            yield A

    def matrices(self):
        """F_U, F_V, F_A at the loaded state as dense arrays, without Dirichlet rows."""
        return [self.dense(A, k) for k, A in enumerate(self._assembled())]

    def csr(self):
        """F_U, F_V, F_A at the loaded state as scipy CSR matrices on their fixed
        patterns (Dirichlet rows included: the callers overwrite them); F_U's
        pattern holds F_V's and F_A's."""
        out = []
        for k, A in enumerate(self._assembled()):
            indptr, indices, data = A.getValuesCSR()
            S = self._sparse.get(k)
            if S is None or S.nnz != data.size:  # the first assembly: the pattern
                S = self._sparse[k] = scipy.sparse.csr_matrix((data, indices, indptr),
                                                              shape=(self.n, self.n))
            else:
                S.data[:] = data
            out.append(S)
        return out

    # -- observables ------------------------------------------------------------------
    @property
    def probes(self):
        """The rod's probes (:class:`~rawehelix.solvers.probes.Probes`) at the loaded U."""
        return self.solver.probes

    def probe_tension(self, u) -> float:
        """T(0) (normalised) by the probe, with U = u loaded."""
        compat.petsc_vec(self.form.u).setArray(u)
        return self.solver.probes.value("tension0")

    def tension_map(self):
        """T(0) = sigma (|r'(0)| - 1) (29) with r'(0) = D U linear in the dofs: D's
        rows assembled once, checked against the probe's point form."""
        rod, u = self.solver.rod, self.form.u
        s = ufl.SpatialCoordinate(rod.mesh)[0]
        r = rod.model.split(u)["centre_line"]
        rows = [dolfinx.fem.form(ufl.derivative(kinematics.d(r)[i] * (1 - s) * ufl.ds(domain=rod.mesh),
                                                u, rod.test)) for i in range(3)]
        self._D = np.array([compat.assemble_vector_array(np.zeros(self.n), f) for f in rows])
        self._sigma = float(self.solver.q.sigma)
        probe = self.solver.probes.value("tension0")
        if not abs(self.tension0(u.x.array) - probe) <= 1e-9 * abs(probe):
            raise RuntimeError(f"chord alpha2: T(0) from r'(0) = D U ({self.tension0(u.x.array)}) "
                               f"is not the probe's ({probe})")

    def tension0(self, u) -> float:
        """T(0) (normalised) of the configuration u (one rank): Eq. (29) at s = 0."""
        return self._sigma * (math.sqrt(float(np.dot(d := self._D @ u, d))) - 1.0)
