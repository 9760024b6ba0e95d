"""The rod equations (30)-(31) as PETSc TS residuals: second- and first-order forms.

Second order (TSALPHA2), unknown U = (r, alpha) on the mixed space W:

    F(t, U, V, A) = model.residual(U, V, A)               (30)-(31), models/unshearable.py
    J = dF/dU + v_shift dF/dV + a_shift dF/dA             (I2Jacobian)

First order (theta, bdf, arkimex, ... : IFunction), unknown X = (r, alpha,
r_t, alpha_t) on a doubled mixed space:

    G(t, X, X_t) = int (r_t - v_r).w + (alpha_t - omega) chi + model.residual(r, alpha; v_r, v_r_t, omega_t)
    J = dG/dX + shift dG/dX_t                            (IJacobian)

Both put the ground torque of the controller into the form as a UFL
expression of the state at s = 0 (Eq. 40 integrated once in time):

    m0 = mN + k1 (alpha(0) - alpha_dot* t) + k2 alpha_t(0) + C,

with C fixed by the initial state, so the Jacobian contains dm0/dU and
dm0/dV.  The alpha and alpha_t in the boundary term -delta m0 psi ds are
evaluated on the end point s = 0 (the term is weighted by 1 - s).

Mixed bending form (``discretisation.bending = "mixed"``, U = (r, alpha,
kappa)): kappa has no inertia or damping, so its rows of dF/dV and dF/dA
are zero and TSALPHA2 integrates an index-1 DAE.  alpha2 enforces the kappa
equation at U_{n+alpha_f} = (1 - alpha_f) U_n + alpha_f U_{n+1}; since it is
linear in (r, kappa), a consistent U_n (the stationary state, or any state
after :meth:`RodDiscretisation.update_curvature`) gives a consistent
U_{n+1}, and an inconsistency g_n is mapped to g_{n+1} = -(1 - alpha_f) /
alpha_f g_n = -rho_inf g_n (alpha_f = 1 / (1 + rho_inf)): it decays, with
alternating sign.  The V and A that alpha2 carries for kappa are never read.
The first-order form is refused with the mixed form.

Hysteretic torsion (``[torsion_hysteresis]``, U = (r, alpha, z)): z's rows
are the Bouc-Wen ODE on V_z (forms/hysteresis.py), a first-order equation
that alpha2 integrates through its Newmark relations; the first-order form
is refused with it too.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import ufl
from petsc4py import PETSc

import dolfinx.cpp
import dolfinx.fem

from rawehelix import compat
from rawehelix.solvers.fields import set_constant
from rawehelix.forms import rod
from rawehelix.models.base import PAIR_ROLES
from rawehelix.solvers.discrete import RodDiscretisation
from rawehelix.solvers.end_torques import EndTorques, end_weights


class Fields:
    """UFL views (r, alpha, r_t, alpha_t) of a formulation's state, the
    curvature field ``kappa`` of the mixed bending form (None: r'') and the
    Bouc-Wen twist ``z`` of the hysteretic torsion (None: elastic)."""

    def __init__(self, r, alpha, r_t, alpha_t, kappa=None, z=None, n=None, n_t=None,
                 alpha_tt=None, r_tt=None):
        self.r, self.alpha, self.r_t, self.alpha_t = r, alpha, r_t, alpha_t
        # the accelerations: the twist's (a rotor's inertia), the centre line's (a lifted top)
        self.alpha_tt, self.r_tt = alpha_tt, r_tt
        self.kappa, self.z = kappa, z
        self.n, self.n_t = n, n_t  # the shearable rod's director and its rate

    @classmethod
    def of(cls, model, u, v, a=None):
        """The views of the state ``u``, its rate ``v`` (and acceleration ``a``) on
        ``model``'s space (models/base.py): the roles' fields under the paper's names."""
        f, f_t = model.split(u), model.split(v)
        f_tt = {"twist": None, "centre_line": None} if a is None else model.split(a)
        return cls(f["centre_line"], f["twist"], f_t["centre_line"], f_t["twist"],
                   f["curvature"], f["internal_twist"], f["director"], f_t["director"],
                   f_tt["twist"], f_tt["centre_line"])

    def roles(self) -> tuple[dict, dict]:
        """(fields, rates) by role, as the model's forms take them."""
        return ({"centre_line": self.r, "twist": self.alpha, "curvature": self.kappa,
                 "internal_twist": self.z, "director": self.n},
                {"centre_line": self.r_t, "twist": self.alpha_t, "director": self.n_t})


def controller_torque(c: rod.Coefficients, q, fields: Fields, time, offset):
    """m0 = mN + k1 (alpha - alpha_dot* t) + k2 alpha_t + C: Eq. (40) integrated in time."""
    return (c.mN + q.k1 * (fields.alpha - q.spin_target * time)
            + q.k2 * fields.alpha_t + offset)


class _Formulation:
    """Shared set-up: time, torque constants, controller and energy forms."""

    second_order: bool

    def __init__(self, rod_: RodDiscretisation, bcs, end_torques: EndTorques = None, top=None):
        self.rod, self.top = rod_, top  # the lifted top (solvers/lifted_top.py); None: r(1) fixed
        # the rotor and the generator (solvers/end_torques.py); None or off: the paper's ends
        self.end_torques = end_torques if end_torques is not None and end_torques.machine.active \
            else None
        mesh = rod_.mesh
        self.time = dolfinx.fem.Constant(mesh, PETSc.ScalarType(0.0))  # t~
        self.offset = dolfinx.fem.Constant(mesh, PETSc.ScalarType(0.0))  # C of Eq. (40)
        self.moving_top = rod_.q.moving_end  # Eq. (70)
        self.bcs = bcs
        self._t_set = None  # (t, scene, moving end) of the data last set
        self.reuse = None  # a snes.ReusedJacobian: the Jacobian callbacks skip a fresh one
        self.time_data = []  # more callables t -> None for set_time (a prescribed end twist)
        # the machine's energy account (_machine_forms, the lifted top's too); None: no machine
        self.rotor_kinetic = self.power_in = self.power_generator = self.power_drag = None
        self.top_energy = None

    def _keep_jacobian(self, *shifts) -> bool:
        """True if the assembled Jacobian (and its LU) may serve again."""
        return self.reuse is not None and not self.reuse.rebuild_for(shifts)

    def _coefficients(self, fields: Fields) -> rod.Coefficients:
        c = self.rod.c
        if self.end_torques is None:  # the paper's ends, Eqs. (39)-(40)
            self.m0 = controller_torque(c, self.rod.q, fields, self.time, self.offset)
            return dataclasses.replace(c, m0=self.m0)
        ends = self.end_torques
        top, ground = end_weights(self.rod.mesh)  # each end's law on its own end only
        given = dataclasses.replace(c, mN=ends.given(c, fields, self.time))  # m_N(t) of (40)
        paper = controller_torque(given, self.rod.q, fields, self.time, self.offset)  # (40)
        self.m0 = ufl.conditional(ground, ends.ground(fields, paper), 0.0)
        self.mN = ufl.conditional(top, ends.top(c, fields, self.time), 0.0)
        # the top's work in: the torques but the rotor's inertia (its kinetic energy)
        self.m_in = ufl.conditional(top, ends.driving(c, fields, self.time), 0.0)
        return dataclasses.replace(c, m0=self.m0, mN=self.mN)

    def _compile(self, F, J, fields: Fields, c_dyn):
        self.F = dolfinx.fem.form(F)
        self.J = dolfinx.fem.form(J)
        self.fields = fields
        rod_, model = self.rod, self.rod.model
        dx = rod_.measures[0]
        f, f_t = fields.roles()
        self.kinetic = dolfinx.fem.form(model.kinetic_energy(f_t, rod_.c, dx))
        self.potential = dolfinx.fem.form(model.stored_energy(
            f, rod_.c, rod_.degree, rod_.penalty, rod_.measures))
        self.power_nv = dolfinx.fem.form(model.non_variational_power(f, f_t, rod_.c, dx))
        # the dissipated power: 2 D of the structural damping (forms/damping.py) and the
        # spin drag's (forms/spin_drag.py); None: nothing dissipates
        P = model.dissipated_power(f, f_t, rod_.c, rod_.degree, rod_.penalty, rod_.measures)
        self.dissipation = None if P is None else dolfinx.fem.form(P)
        if self.end_torques is not None:
            self._machine_forms(fields)
        self.b = compat.create_vector(self.F)
        self._scratch = self.b.duplicate()
        owned = self.b.getLocalSize()
        dofs = np.unique(np.concatenate([bc.dof_indices()[0] for bc in self.bcs] or [[]])).astype(np.int32)
        self.bc_dofs = dofs[dofs < owned]  # this rank's owned Dirichlet dofs
        self._bc_values = None  # g at bc_dofs, after each set_time
        self.A = compat.create_matrix(self.J)

    def _machine_forms(self, fields: Fields):
        """The energy account of the rotor and the generator (normalised, x beta / delta
        like forms/energy.py): the rotor's kinetic energy 1/2 beta j alpha_t(1)^2, the
        power in beta (mN + Q) alpha_t(1), the generator's power out beta m0 alpha_t(0)
        and the drag's power int F_A . r_t (Eq. 14)."""
        rod_, c = self.rod, self.rod.c
        dx, _, ds = rod_.measures
        top, _ = end_weights(rod_.mesh)
        j = self.end_torques.inertia
        self.rotor_kinetic = dolfinx.fem.form(
            ufl.conditional(top, 0.5 * c.beta * j * fields.alpha_t**2, 0.0) * ds)
        power_in = c.beta * self.m_in * fields.alpha_t * ds
        if self.top is not None:  # the thrust's work on the moving top, its stored energy
            power_in += self.top.thrust_power(fields, ds, self.end_torques.thrust(fields))
            self.top_energy = dolfinx.fem.form(self.top.stored_energy(fields, ds))
        self.power_in = dolfinx.fem.form(power_in)
        self.power_generator = dolfinx.fem.form(c.beta * self.m0 * fields.alpha_t * ds)
        # (14) at each point's height (a wind profile reads r): gravity is in U
        drag = rod.body_force(fields.r_t, c, fields.r) - c.gravity * rod.K_E
        self.power_drag = dolfinx.fem.form(ufl.inner(drag, fields.r_t) * dx)

    def set_time(self, t: float):
        """Time-dependent data: torque ramp (69), end motion (36)/(70)."""
        q = self.rod.q
        last = self._t_set
        # every residual of a Newton solve is at one time; the key holds q itself
        # (compared by identity): an id() of a freed q could be reused by a new one
        if last is not None and last[0] == t and last[1] is q and last[2] == self.moving_top:
            return
        self._t_set = (t, q, self.moving_top)
        self._bc_values = None
        self.time.value = t
        self.rod.c.mN.value = q.top_torque(t)  # (69)
        if self.moving_top:
            self._set_top(t)
        for set_data in self.time_data:
            set_data(t)

    def assemble_residual(self, x, b):
        with b.localForm() as b_local:
            b_local.set(0.0)
        dolfinx.fem.petsc.assemble_vector(b, self.F)
        # Dirichlet rows x - g, and the lifting b += J_bc (g - x), which makes the
        # first Newton step exact for a moving end (70) (the bc columns of J are
        # zero); it touches only the cells at the ends, and is zero when g = x:
        # from the second Newton iteration on, where it is skipped (it packs
        # the Jacobian's coefficients: half the cost of a residual at N = 8).
        # (a local decision: the lifting has no communication)
        if self._bc_mismatch(x) > 1e-13:
            compat.apply_lifting_and_bc(b, self.J, self.bcs, x, -1.0)
        else:
            b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
            dolfinx.fem.petsc.set_bc(b, self.bcs, x, -1.0)

    def bc_values(self) -> np.ndarray:
        """g at :attr:`bc_dofs`, the Dirichlet data of the last set_time (cached)."""
        if self._bc_values is None:
            g = self._scratch
            with g.localForm() as g_local:
                g_local.set(0.0)
            dolfinx.fem.petsc.set_bc(g, self.bcs)
            self._bc_values = g.getArray(readonly=True)[self.bc_dofs].copy()
        return self._bc_values

    def bc_sources(self):
        """(functions, index): g at :attr:`bc_dofs` is
        ``np.concatenate([f.x.array for f in functions])[index]`` after any set_time
        (found once by probing set_bc with numbered values): a gather of a few us,
        where :meth:`bc_values` goes through a PETSc vector (~15 us at N = 8)."""
        functions = [bc.value for bc in self.bcs]
        if not all(isinstance(f, (dolfinx.fem.Function, dolfinx.cpp.fem.Function_float64))
                   for f in functions):
            return None  # a Constant's value: no probing needed by the callers so far
        saved = [f.x.array.copy() for f in functions]
        start = 1.0
        try:
            for f in functions:
                f.x.array[:] = start + np.arange(f.x.array.size)
                start += f.x.array.size
            self._bc_values = None
            index = np.round(self.bc_values()).astype(np.int64) - 1
        finally:
            for f, s in zip(functions, saved):
                f.x.array[:] = s
            self._bc_values = None
        return functions, index

    def _bc_mismatch(self, x) -> float:
        """max |x - g| over this rank's owned Dirichlet dofs (g of the last set_time)."""
        g = self.bc_values()
        if not len(self.bc_dofs):
            return 0.0
        return float(np.max(np.abs(x.getArray(readonly=True)[self.bc_dofs] - g)))

    def assemble_jacobian(self, A):
        A.zeroEntries()
        dolfinx.fem.petsc.assemble_matrix(A, self.J, self.bcs)
        A.assemble()


def _load(vec, u):
    """Function u <- PETSc vector vec (owned values), then update ghosts (none in serial)."""
    vec.copy(compat.petsc_vec(u))
    if u.function_space.mesh.comm.size > 1:
        u.x.scatter_forward()


class SecondOrder(_Formulation):
    """F(t, U, V, A) = 0 for TSALPHA2; U lives in ``rod.w``."""

    second_order = True

    def __init__(self, rod_: RodDiscretisation, bcs, end_torques: EndTorques = None, top=None):
        super().__init__(rod_, bcs, end_torques, top)
        W = rod_.W
        self.u = rod_.w  # (r, alpha)
        self.v = dolfinx.fem.Function(W, name="velocity")  # (r_t, alpha_t)
        self.a = dolfinx.fem.Function(W, name="acceleration")
        self.shift_v = dolfinx.fem.Constant(rod_.mesh, PETSc.ScalarType(0.0))
        self.shift_a = dolfinx.fem.Constant(rod_.mesh, PETSc.ScalarType(0.0))
        fields = Fields.of(rod_.model, self.u, self.v, self.a)
        c_dyn = self._coefficients(fields)
        F = rod_.model.residual(self.u, self.v, self.a, rod_.test, c_dyn, rod_.degree,
                                rod_.penalty, rod_.measures)
        if top is not None:  # the lifted top's mass and end forces (solvers/lifted_top.py)
            F = F + top.residual(fields, rod_.model.split(rod_.test)["centre_line"],
                                 rod_.measures[2], self.end_torques)
        J = (ufl.derivative(F, self.u, rod_.trial)
             + self.shift_v * ufl.derivative(F, self.v, rod_.trial)
             + self.shift_a * ufl.derivative(F, self.a, rod_.trial))
        self.residual_ufl = F  # F(t, U, V, A): the orbits' tangent takes its three derivatives
        self._compile(F, J, fields, c_dyn)

    def _set_top(self, t):
        self.rod.set_top_position(self.rod.q.top_position(t))

    def attach(self, ts):
        ts.setI2Function(self._f, self.b)
        ts.setI2Jacobian(self._j, self.A)

    def _update(self, t, U, V, A=None):
        self.set_time(t)
        _load(U, self.u)
        _load(V, self.v)
        if A is not None:
            _load(A, self.a)

    def _f(self, ts, t, U, V, A, F):
        self._update(t, U, V, A)
        self.assemble_residual(U, F)

    def _j(self, ts, t, U, V, A, shift_v, shift_a, J, P):
        if self._keep_jacobian(shift_v, shift_a):
            return
        self._update(t, U, V, A)
        self.shift_v.value, self.shift_a.value = shift_v, shift_a
        self.assemble_jacobian(P)
        if J != P:
            J.assemble()

    def initial_vectors(self):
        U = compat.petsc_vec(self.u).copy()
        V = compat.petsc_vec(self.v).copy()
        return U, V

    def load_solution(self, ts):
        """Functions u, v <- the TS solution (U, V)."""
        U, V = ts.getSolution2()
        _load(U, self.u)
        _load(V, self.v)


class FirstOrder(_Formulation):
    """G(t, X, X_t) = 0 for the first-order TS types; X = (r, alpha, r_t, alpha_t)."""

    second_order = False

    def __init__(self, rod_: RodDiscretisation, bcs_second_order,
                 end_torques: EndTorques | None = None):
        model = rod_.model
        model.refuse("first_order", rod_.params.name)  # RodModel.refusals (models/)
        mesh = rod_.mesh
        self.W2 = compat.function_space(mesh, model.pair_element(mesh.ufl_cell(), rod_.degree))
        self.x = dolfinx.fem.Function(self.W2, name="state")
        self.x_t = dolfinx.fem.Function(self.W2, name="rate")
        super().__init__(rod_, self._end_conditions(rod_), end_torques)
        self.shift = dolfinx.fem.Constant(mesh, PETSc.ScalarType(0.0))
        f, vel = model.split_pair(self.x)  # X = (fields, velocities)
        f_t, acc = model.split_pair(self.x_t)  # X_t = (rates, accelerations)
        tests, tests_v = model.split_pair(ufl.TestFunction(self.W2))
        fields = Fields(f["centre_line"], f["twist"], vel["centre_line"], vel["twist"],
                        alpha_tt=acc["twist"])
        c_dyn = self._coefficients(fields)
        dx = rod_.measures[0]
        F = sum(ufl.inner(f_t[role] - vel[role], tests[role]) for role in PAIR_ROLES) * dx \
            + model.residual_of_fields(f, vel, acc, tuple(tests_v[role] for role in PAIR_ROLES),
                                       c_dyn, rod_.degree, rod_.penalty, rod_.measures)
        trial = ufl.TrialFunction(self.W2)
        J = ufl.derivative(F, self.x, trial) + self.shift * ufl.derivative(F, self.x_t, trial)
        self._compile(F, J, fields, c_dyn)

    def _end_conditions(self, rod_):
        """r(0) = 0, r(1) = r_N(t) (35)-(36) and their rates r_t(0) = 0, r_t(1) = r_N'(t)."""
        mesh, W2 = rod_.mesh, self.W2
        ends = {"bottom": compat.locate_boundary_vertices(mesh, lambda x: np.isclose(x[0], 0.0)),
                "top": compat.locate_boundary_vertices(mesh, lambda x: np.isclose(x[0], 1.0))}
        self.V_r = rod_.V_r
        self.r_top = dolfinx.fem.Function(self.V_r)
        self.r_top_t = dolfinx.fem.Function(self.V_r)
        zero = dolfinx.fem.Function(self.V_r)
        self._set_top_functions(0.0, rod_.q)
        bcs = []
        model = rod_.model  # the fields and their rates in W2 (models/base.py::RodModel.split_pair)
        r_sub, r_t_sub = model.pair_index("centre_line"), model.pair_index("centre_line", True)
        twist_subs = (model.pair_index("twist"), model.pair_index("twist", True))
        for sub, values in ((r_sub, {"bottom": zero, "top": self.r_top}),
                            (r_t_sub, {"bottom": zero, "top": self.r_top_t})):
            for end, g in values.items():
                dofs = dolfinx.fem.locate_dofs_topological((W2.sub(sub), self.V_r), 0, ends[end])
                bcs.append(dolfinx.fem.dirichletbc(g, dofs, W2.sub(sub)))
        if not rod_.params.model.twist:  # alpha = alpha_t = 0 everywhere
            bcs += [dolfinx.fem.dirichletbc(rod_.alpha_zero, rod_.all_dofs(W2.sub(sub), rod_.V_a),
                                            W2.sub(sub)) for sub in twist_subs]
        return bcs

    def _set_top_functions(self, t, q):
        for f, value in ((self.r_top, q.top_position(t)), (self.r_top_t, q.top_velocity(t))):
            set_constant(f, value)

    def _set_top(self, t):
        self._set_top_functions(t, self.rod.q)

    def attach(self, ts):
        ts.setIFunction(self._f, self.b)
        ts.setIJacobian(self._j, self.A)

    def _update(self, t, X, X_t):
        self.set_time(t)
        _load(X, self.x)
        _load(X_t, self.x_t)

    def _f(self, ts, t, X, X_t, F):
        self._update(t, X, X_t)
        self.assemble_residual(X, F)

    def _j(self, ts, t, X, X_t, shift, J, P):
        if self._keep_jacobian(shift):
            return
        self._update(t, X, X_t)
        self.shift.value = shift
        self.assemble_jacobian(P)
        if J != P:
            J.assemble()

    def initial_vectors(self):
        """X0 = (r, alpha) of ``rod.w``, zero rates."""
        model = self.rod.model
        for role in PAIR_ROLES:
            self.x.sub(model.pair_index(role)).interpolate(self.rod.w.sub(model.index(role)))
        self.x.x.scatter_forward()
        return compat.petsc_vec(self.x).copy(), None

    def load_solution(self, ts):
        _load(ts.getSolution(), self.x)
