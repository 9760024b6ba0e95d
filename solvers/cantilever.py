"""The lab tests' cantilever (Sec. 4, Fig. 2 a-c) by Newton's method (PETSc SNES).

A rod of the scene's helix clamped at s = 0: r(0) = 0 and alpha(0) = 0 as
Dirichlet conditions, the slope r'(0) along the axis e by the Nitsche term of
:mod:`rawehelix.forms.cantilever`; at s = 1 a dead force P (SI, any
direction) and a torque M_t about the tangent (Eq. 39).  The residual is the
stationary one of Eqs. (30)-(31) plus the variations of the clamp energy and
of the load potential.  No file IO; loads and the bending stiffness are
constants, so one compiled solver serves every load of a test.  With the
helix's EI law (``helix.EI_law``, extensible kinematics) the rod's EI is the
law's at the local tension, and :meth:`CantileverSolver.set_bending_law`
changes (a, b) without compiling again; :meth:`set_bending_stiffness` then
sets the constant EI as the law (0, EI).

Each solve starts from the previous state (a load path, as in the lab); the
first (and the first after :meth:`CantileverSolver.reset`) from the straight
segment stretched by P.e / EA.  A load that Newton
does not reach in one step is approached in halved increments; if it is not
reached at all, the solver keeps the last equilibrium and raises SolverError.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import ufl
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.fem

from rawehelix import compat
from rawehelix.forms import cantilever, kinematics
from rawehelix.parameters import Parameters, schemes
from rawehelix.solvers import petsc_options
from rawehelix.solvers.discrete import RodDiscretisation
from rawehelix.solvers.snes import NewtonSolver, SolverError

AXIS = np.array([1.0, 0.0, 0.0])  # the undeformed axis, horizontal (i_E); gravity is k_E


@dataclass
class TipResult:
    """The free end of a converged cantilever, SI."""

    position_m: np.ndarray  # r(L0) [m]
    twist_rad: float  # int_0^L0 tau ds: the end's rotation about the tangent relative to the wall
    tension_wall_N: float  # T(0), Eq. (29)
    tension_tip_N: float  # T(L0)
    newton_iterations: int


class CantileverRod(RodDiscretisation):
    """:class:`RodDiscretisation` with the wall's conditions: r(0) = 0, alpha(0) = 0; s = 1 free."""

    def _set_up_end_conditions(self, pin_twist: bool, free_top: bool = False):
        # s = 1 is free whatever free_top says (the lifted top's flag of RodDiscretisation)
        wall = compat.locate_boundary_vertices(self.mesh, lambda x: np.isclose(x[0], 0.0))
        W_r, W_a = self.sub("centre_line"), self.sub("twist")  # the model's fields
        self.V_r, _ = compat.collapse(W_r)
        self.V_a, _ = compat.collapse(W_a)
        self.r_bottom = dolfinx.fem.Function(self.V_r)
        self.alpha_zero = dolfinx.fem.Function(self.V_a)
        dofs_r = dolfinx.fem.locate_dofs_topological((W_r, self.V_r), 0, wall)
        dofs_a = dolfinx.fem.locate_dofs_topological((W_a, self.V_a), 0, wall)
        self.bcs = [dolfinx.fem.dirichletbc(self.r_bottom, dofs_r, W_r),
                    dolfinx.fem.dirichletbc(self.alpha_zero, dofs_a, W_a)]
        self.twist_bcs = self.curvature_bcs = []


class CantileverSolver:
    """Newton for the clamped segment under end loads."""

    def __init__(self, params: Parameters, comm=MPI.COMM_WORLD):
        if params.discretisation.bending != "ip" or not schemes.of(params).fe_assembled:
            raise ValueError("the cantilever is implemented for the FE scheme with "
                             "discretisation.bending = 'ip' (forms/cantilever.py)")
        self.params, self.q = params, params.normalised()
        self.axis = AXIS
        self.rod = r = CantileverRod(params, comm)
        c, mesh, w = r.c, r.mesh, r.w
        _, _, ds = r.measures
        self.force = dolfinx.fem.Constant(mesh, np.zeros(3, dtype=PETSc.ScalarType))
        axis = ufl.as_vector(AXIS)
        x = r.centre_line()
        alpha = r.model.split(w)["twist"]
        tau = kinematics.twist(x, alpha, c.gamma_eps, c.gamma_coupling)  # (34)
        mu = c.kinematics.bending_modulus(x, c)  # with the EI law: mu(eps), forms/eilaw.py
        # a section law's taut modulus and wall moment dW/dt' (forms/section_law.py), or mu t'
        mu, moment = c.section.wall_moment(x, c, tau, alpha, mu)
        U = (cantilever.clamp_energy(x, axis, mu, c.kinematics, r.degree, r.penalty, ds, moment)
             + cantilever.end_load_potential(x, self.force, ds))
        F = r.stationary_residual() + ufl.derivative(U, w, r.test)
        self.newton = NewtonSolver(F, w, r.bcs, prefix=petsc_options.LABTEST_PREFIX)
        T = kinematics.tension(x, c.sigma)  # (29)
        s = ufl.SpatialCoordinate(mesh)[0]
        dx = r.measures[0]
        self.probes = {name: dolfinx.fem.form(e) for name, e in (
            ("x", x[0] * s * ds), ("y", x[1] * s * ds), ("z", x[2] * s * ds),
            ("twist", tau * dx), ("T0", T * (1 - s) * ds), ("T1", T * s * ds))}
        self.loads = None  # the (force, torque) of the current state; None: not solved yet

    def set_bending_stiffness(self, EI_Nm2: float):
        """A constant EI of the rod (and delta = beta sigma / (2 mu), Eq. 27, with it)."""
        q, c = self.q, self.rod.c
        mu = EI_Nm2 / (q.force_scale * q.L0**2)  # (26)
        c.mu.value = mu
        c.delta.value = q.beta * q.sigma / (2 * mu)
        if c.bending_law.field:
            self.set_bending_law(0.0, EI_Nm2)

    def set_bending_law(self, a_Nm2_per_N: float, b_Nm2: float):
        """The EI law EI = a T + b of a rod built with one (parameters.Normalised)."""
        q, c = self.q, self.rod.c
        if not c.bending_law.field:
            raise ValueError("set_bending_law needs a rod built with helix.EI_law")
        c.bending_law.mu_a.value = a_Nm2_per_N / q.L0**2
        c.bending_law.mu_b.value = b_Nm2 / (q.force_scale * q.L0**2)

    def _set_loads(self, force_N, torque_Nm: float):
        self.force.value[:] = np.asarray(force_N, dtype=float) / self.q.force_scale
        self.rod.c.mN.value = torque_Nm / self.q.torque_scale  # tau(1) = m_N, Eq. (39)

    def _straight(self, force_N):
        stretch = 1.0 + float(np.dot(force_N, AXIS)) / self.params.helix.EA_N
        w, model = self.rod.w, self.rod.model
        w.sub(model.index("centre_line")).interpolate(lambda x: np.outer(stretch * AXIS, x[0]))
        w.sub(model.index("twist")).interpolate(lambda x: np.zeros(x.shape[1]))
        self.rod.w.x.scatter_forward()

    def solve(self, force_N, torque_Nm: float = 0.0, halvings: int = 6) -> TipResult:
        """The equilibrium under the end force P [N] (3-vector) and torque M_t [Nm]."""
        force_N = np.asarray(force_N, dtype=float)
        if self.loads is None:
            self._straight(force_N)
            self.loads = (force_N, torque_Nm)
        its = self._reach(force_N, torque_Nm, halvings)
        return self.tip(its)

    def reset(self):
        """The next solve starts again from the straight segment (a new load path)."""
        self.loads = None

    def _reach(self, force_N, torque_Nm, halvings: int) -> int:
        start = self.rod.w.x.array.copy()
        self._set_loads(force_N, torque_Nm)
        try:
            its = self.newton.solve("the lab test's cantilever")
        except SolverError:
            self.rod.w.x.array[:] = start  # the last equilibrium, not Newton's last iterate
            self._set_loads(*self.loads)
            if halvings == 0:
                raise
            f0, m0 = self.loads
            its = self._reach(0.5 * (f0 + force_N), 0.5 * (m0 + torque_Nm), halvings - 1)
            its += self._reach(force_N, torque_Nm, halvings - 1)
        self.loads = (force_N, torque_Nm)
        return its

    def tip(self, its: int = 0) -> TipResult:
        """The free end of the current state (collective; every rank gets it)."""
        comm = self.rod.comm
        v = {k: comm.allreduce(dolfinx.fem.assemble_scalar(f), op=MPI.SUM)
             for k, f in self.probes.items()}
        q = self.q
        return TipResult(q.length_m(np.array([v["x"], v["y"], v["z"]])), float(v["twist"]),
                         float(q.tension_N(v["T0"])), float(q.tension_N(v["T1"])), its)
