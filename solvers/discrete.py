"""The discrete rod: mesh, mixed (r, alpha) space, constants, measures and end conditions.

Shared by the stationary, dynamic and modal solvers.  Built from validated
:class:`~rawehelix.parameters.Parameters`; reads no files.

With ``discretisation.bending = "mixed"`` the space is (r, alpha, kappa),
kappa the curvature field of :mod:`rawehelix.forms.mixed` with kappa = 0 at
both ends (Eq. 37) as Dirichlet conditions (``curvature_bcs``, also in ``bcs``).
With ``[torsion_hysteresis]`` it is (r, alpha, z), z the Bouc-Wen internal
twist on DG_(p-1) (:mod:`rawehelix.forms.hysteresis`), which needs no end condition.
"""

from __future__ import annotations

import numpy as np
import ufl
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.fem

from rawehelix import compat
from rawehelix.solvers import fields
from rawehelix.solvers.fields import set_constant
from rawehelix.solvers.state import RodState
from rawehelix.forms import rod
from rawehelix.parameters import Parameters
from rawehelix.meshes import interval


class RodDiscretisation:
    """Everything a solver needs to assemble Eqs. (30)-(31) on one mesh."""

    def __init__(self, params: Parameters, comm=MPI.COMM_WORLD, pin_twist: bool = True):
        disc = params.discretisation
        if disc.scheme != "fe":
            raise ValueError(f"discretisation.scheme = {disc.scheme!r}: this solver is the FE scheme")
        self.params = params
        self.q = params.normalised()
        self.comm = comm
        self.degree = disc.degree
        self.penalty = disc.penalty
        self.mixed = disc.bending == "mixed"  # the curvature field kappa, forms/mixed.py
        self.mesh = interval.mesh_from_parameters(comm, params)
        self.hysteretic = params.model.torsion_hysteresis.active  # z, forms/hysteresis.py
        self.W = compat.function_space(self.mesh, compat.rod_element(
            self.mesh.ufl_cell(), self.degree, curvature=self.mixed, internal=self.hysteretic))
        self.w = dolfinx.fem.Function(self.W, name="state")
        self.test = ufl.TestFunction(self.W)
        self.trial = ufl.TrialFunction(self.W)
        self.c = rod.Coefficients.from_normalised(
            self.q, params.model, make=lambda v: dolfinx.fem.Constant(self.mesh, PETSc.ScalarType(v)))
        self.measures = rod.measures(self.mesh, disc.degree, disc.quadrature_degree)
        self._set_up_end_conditions(pin_twist)

    # -- end conditions, Eqs. (35), (36), (66), (70) ------------------------------
    def _set_up_end_conditions(self, pin_twist: bool):
        mesh = self.mesh
        bottom = compat.locate_boundary_vertices(mesh, lambda x: np.isclose(x[0], 0.0))
        top = compat.locate_boundary_vertices(mesh, lambda x: np.isclose(x[0], 1.0))
        self.V_r, _ = compat.collapse(self.W.sub(0))
        self.r_bottom = dolfinx.fem.Function(self.V_r)  # r(0) = 0, Eq. (35)
        self.r_top = dolfinx.fem.Function(self.V_r)  # r(1) = r_N(t), Eq. (36)
        self.set_top_position(self.q.top_position(0.0))
        dofs_b = dolfinx.fem.locate_dofs_topological((self.W.sub(0), self.V_r), 0, bottom)
        dofs_t = dolfinx.fem.locate_dofs_topological((self.W.sub(0), self.V_r), 0, top)
        self.end_dofs = {"bottom": dofs_b, "top": dofs_t}  # centre-line dofs (W, V_r)
        self.bcs = [dolfinx.fem.dirichletbc(self.r_bottom, dofs_b, self.W.sub(0)),
                    dolfinx.fem.dirichletbc(self.r_top, dofs_t, self.W.sub(0))]
        self.V_a, _ = compat.collapse(self.W.sub(1))
        self.alpha_zero = dolfinx.fem.Function(self.V_a)
        # model.twist = false: no twist field, alpha = 0 on every dof (the scene
        # is torque-free, which Parameters checks); the solvers add these bcs
        self.twist_bcs = [] if self.params.model.twist else [dolfinx.fem.dirichletbc(
            self.alpha_zero, self.all_dofs(self.W.sub(1), self.V_a), self.W.sub(1))]
        if pin_twist:
            # alpha(0) = 0 removes the free rigid rotation (torque-free ends)
            dofs_a = dolfinx.fem.locate_dofs_topological((self.W.sub(1), self.V_a), 0, bottom)
            self.bcs.append(dolfinx.fem.dirichletbc(self.alpha_zero, dofs_a, self.W.sub(1)))
        self.bcs += self.twist_bcs
        self.curvature_bcs = []
        if self.mixed:  # kappa(0) = kappa(1) = 0, Eq. (37), essential
            self.V_k, self._kappa_dofs = compat.collapse(self.W.sub(2))
            self.kappa_zero = dolfinx.fem.Function(self.V_k)
            ends = np.concatenate([bottom, top]).astype(np.int32)
            dofs_k = dolfinx.fem.locate_dofs_topological((self.W.sub(2), self.V_k), 0, ends)
            self.curvature_bcs = [dolfinx.fem.dirichletbc(self.kappa_zero, dofs_k, self.W.sub(2))]
            self._curvature_problem = None
        self.bcs += self.curvature_bcs

    def end_twist_conditions(self):
        """alpha(0) = 0 and alpha(1) = ``self.alpha_top`` (a Function, set by the
        caller): the prescribed end twist of a torsion test (Sec. 4)."""
        mesh = self.mesh
        self.alpha_top = dolfinx.fem.Function(self.V_a)
        bcs = []
        for x_end, g in ((0.0, self.alpha_zero), (1.0, self.alpha_top)):
            vertices = compat.locate_boundary_vertices(mesh, lambda x: np.isclose(x[0], x_end))
            dofs = dolfinx.fem.locate_dofs_topological((self.W.sub(1), self.V_a), 0, vertices)
            bcs.append(dolfinx.fem.dirichletbc(g, dofs, self.W.sub(1)))
        return bcs

    def all_dofs(self, W_sub, V_collapsed):
        """Every dof of a sub-space (for a field held at zero)."""
        return compat.locate_all_dofs(self.mesh, (W_sub, V_collapsed))

    def set_top_position(self, position):
        position = np.asarray(position, dtype=float)
        set_constant(self.r_top, position)

    # -- states ------------------------------------------------------------------
    def get_state(self, w=None, w_t=None, t: float = 0.0) -> RodState:
        """The state held in ``w`` (default ``self.w``) and ``w_t`` (a copy)."""
        w = w or self.w
        return RodState(w.x.array.copy(), None if w_t is None else w_t.x.array.copy(), t,
                        self.dof_count())

    def set_state(self, state: RodState, w=None, w_t=None):
        """``w`` (default ``self.w``) and ``w_t`` (if given) <- the state."""
        w = w or self.w
        state.check(self.dof_count(), w.x.array.size)
        w.x.array[:] = state.w
        if w_t is not None:
            w_t.x.array[:] = 0.0 if state.w_t is None else state.w_t

    def set_chord(self, w=None):
        """w <- the straight chord r = s r_N, alpha = 0: the default first guess."""
        w = w or self.w
        top = self.q.top_position(0.0)
        w.sub(0).interpolate(lambda x: np.outer(top, x[0]))
        w.sub(1).interpolate(lambda x: np.zeros(x.shape[1]))
        w.x.scatter_forward()
        self.update_curvature(w)

    def set_centre_line(self, centre_line, w=None):
        """w <- (r(s) from a callable s -> (n, 3), alpha = 0)."""
        w = w or self.w
        w.sub(0).interpolate(lambda x: np.asarray(centre_line(x[0])).T)
        w.sub(1).interpolate(lambda x: np.zeros(x.shape[1]))
        w.x.scatter_forward()
        self.update_curvature(w)

    def update_curvature(self, w=None):
        """Mixed bending form: kappa of ``w`` (default ``self.w``) <- kappa(r),
        the kappa equation with kappa = 0 at the ends (:mod:`.curvature`), so
        that a state set from a centre line is consistent.  Nothing for IP."""
        if not self.mixed:
            return
        if self._curvature_problem is None:
            from rawehelix.solvers.curvature import CurvatureProjection
            self._curvature_problem = CurvatureProjection(self)
        self._curvature_problem.apply(w or self.w)

    def centre_line(self):
        """r as UFL (the first field of the state)."""
        return ufl.split(self.w)[0]

    def curvature(self):
        """kappa as UFL (mixed bending form), or None: r'' is then cellwise."""
        return ufl.split(self.w)[2] if self.mixed else None

    def internal_twist(self, w=None):
        """z as UFL (hysteretic torsion, forms/hysteresis.py), or None."""
        return ufl.split(w or self.w)[2] if self.hysteretic else None

    def gather_centre_line(self):
        """(s, r (n, 3)) at the Lagrange nodes on rank 0 ((None, None) elsewhere)."""
        return fields.gather(self.w.sub(0).collapse())

    def stationary_residual(self, w=None):
        w = w or self.w
        return rod.residual(w, None, None, self.test, self.c, self.degree, self.penalty,
                            self.measures)

    def dof_count(self) -> int:
        im = self.W.dofmap.index_map
        return im.size_global * self.W.dofmap.index_map_bs
