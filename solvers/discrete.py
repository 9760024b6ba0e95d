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

import dataclasses

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
from rawehelix.models import rod_model
from rawehelix.parameters import Parameters, schemes
from rawehelix.meshes import interval


def _same(a, b) -> bool:
    """Equal values, NaN equal to NaN (a group not yet known, such as eps0)."""
    try:
        return bool(a == b) or (a != a and b != b)
    except (TypeError, ValueError):
        return a is b


def unit_tangent_of(centre_line, s, h: float = 1e-6):
    """t(s) (n, 3) of a callable s -> r(s) (n, 3), by central differences (one-sided
    at the ends): the shearable rod's director of a centre line without shear."""
    lo, hi = np.clip(s - h, 0.0, 1.0), np.clip(s + h, 0.0, 1.0)
    dr = np.asarray(centre_line(hi)) - np.asarray(centre_line(lo))
    return dr / np.linalg.norm(dr, axis=1)[:, None]


class RodDiscretisation:
    """Everything a solver needs to assemble Eqs. (30)-(31) on one mesh."""

    #: the full rod (solvers/planar.py's PlanarRod is the reduced (x, z) one)
    planar = False

    def __init__(self, params: Parameters, comm=MPI.COMM_WORLD, pin_twist: bool = True,
                 free_top: bool = False):
        disc = params.discretisation
        if not schemes.of(params).fe_assembled:
            raise ValueError(f"discretisation.scheme = {disc.scheme!r}: this solver is the FE scheme")
        self.params = params
        self.q = params.normalised()
        self.comm = comm
        self.degree = disc.degree
        self.penalty = disc.penalty
        self.model = model = rod_model(params)  # its fields and forms, models/
        self.mixed = model.has("curvature")  # the curvature field kappa, forms/mixed.py
        self.hysteretic = model.has("internal_twist")  # z, forms/hysteresis.py
        self.mesh = interval.mesh_from_parameters(comm, params)
        self.W = compat.function_space(self.mesh, model.element(self.mesh.ufl_cell(), self.degree))
        self.w = dolfinx.fem.Function(self.W, name="state")
        self.test = ufl.TestFunction(self.W)
        self.trial = ufl.TrialFunction(self.W)
        self.c = rod.Coefficients.from_normalised(
            self.q, params.model, make=lambda v: dolfinx.fem.Constant(self.mesh, PETSc.ScalarType(v)))
        self.measures = rod.measures(self.mesh, disc.degree, disc.quadrature_degree)
        self._set_up_end_conditions(pin_twist, free_top)

    # -- end conditions, Eqs. (35), (36), (66), (70) ------------------------------
    def sub(self, role: str):
        """The sub-space of the field ``role`` (models/base.py::ROLES) in W."""
        return self.W.sub(self.model.index(role))

    def dofs(self, role: str) -> np.ndarray:
        """The dofs of W (this rank's local indices) of the field ``role``; none if the
        model has no such field (the internal twist without hysteresis)."""
        if not self.model.has(role):
            return np.zeros(0, dtype=int)
        return np.asarray(compat.collapse(self.sub(role))[1], dtype=int)

    def _set_up_end_conditions(self, pin_twist: bool, free_top: bool = False):
        """The model's end conditions (models/unshearable.py) as dolfinx bcs:
        ``bcs`` all of them, ``twist_bcs`` alpha = 0 everywhere (model.twist =
        false), ``curvature_bcs`` kappa = 0 at the ends (mixed form).  ``free_top``:
        without the top's position (36), whose force is then a natural term
        (the lifted top, solvers/lifted.py)."""
        self.free_top = free_top
        mesh = self.mesh
        vertices = {"bottom": compat.locate_boundary_vertices(mesh, lambda x: np.isclose(x[0], 0.0)),
                    "top": compat.locate_boundary_vertices(mesh, lambda x: np.isclose(x[0], 1.0))}
        vertices["ends"] = np.concatenate([vertices["bottom"], vertices["top"]]).astype(np.int32)
        self.V_r, _ = compat.collapse(self.sub("centre_line"))
        self.r_bottom = dolfinx.fem.Function(self.V_r)  # r(0) = 0, Eq. (35)
        self.r_top = dolfinx.fem.Function(self.V_r)  # r(1) = r_N(t), Eq. (36)
        self.set_top_position(self.q.top_position(0.0))
        self.V_a, _ = compat.collapse(self.sub("twist"))
        self.alpha_zero = dolfinx.fem.Function(self.V_a)
        spaces = {"centre_line": self.V_r, "twist": self.V_a}
        zeros = {"centre_line": self.r_bottom, "twist": self.alpha_zero}
        if self.mixed:
            self.V_k, self._kappa_dofs = compat.collapse(self.sub("curvature"))
            self.kappa_zero = dolfinx.fem.Function(self.V_k)
            spaces["curvature"], zeros["curvature"] = self.V_k, self.kappa_zero
            self._curvature_problem = None
        self.bcs, self.twist_bcs, self.curvature_bcs, self.end_dofs = [], [], [], {}
        for end in self.model.end_conditions(pin_twist):
            if free_top and end.value == "top_position":
                continue
            W_sub, V = self.sub(end.role), spaces[end.role]
            dofs = (self.all_dofs(W_sub, V) if end.where == "all" else
                    dolfinx.fem.locate_dofs_topological((W_sub, V), 0, vertices[end.where]))
            bc = dolfinx.fem.dirichletbc(self.r_top if end.value == "top_position"
                                         else zeros[end.role], dofs, W_sub)
            if end.role == "centre_line":
                self.end_dofs[end.where] = dofs  # centre-line dofs (W, V_r)
            (self.twist_bcs if end.where == "all" else
             self.curvature_bcs if end.role == "curvature" else self.bcs).append(bc)
        self.bcs += self.twist_bcs + self.curvature_bcs

    def end_twist_conditions(self):
        """alpha(0) = 0 and alpha(1) = ``self.alpha_top`` (a Function, set by the
        caller): the prescribed end twist of a torsion test (Sec. 4)."""
        mesh = self.mesh
        self.alpha_top = dolfinx.fem.Function(self.V_a)
        bcs = []
        for x_end, g in ((0.0, self.alpha_zero), (1.0, self.alpha_top)):
            vertices = compat.locate_boundary_vertices(mesh, lambda x: np.isclose(x[0], x_end))
            dofs = dolfinx.fem.locate_dofs_topological((self.sub("twist"), self.V_a), 0, vertices)
            bcs.append(dolfinx.fem.dirichletbc(g, dofs, self.sub("twist")))
        return bcs

    def all_dofs(self, W_sub, V_collapsed):
        """Every dof of a sub-space (for a field held at zero)."""
        return compat.locate_all_dofs(self.mesh, (W_sub, V_collapsed))

    def set_top_position(self, position):
        position = np.asarray(position, dtype=float)
        set_constant(self.r_top, position)

    def set_wind(self, params: Parameters):
        """The rod of ``params``, the same scene at another wind speed: only the helix's
        drag (Eq. 14) changes, through v_w0 (Eq. 27), a constant of the forms.  Raises
        ValueError if ``params`` changes another normalised group (it needs its own rod)."""
        q = params.normalised()
        changed = sorted(f.name for f in dataclasses.fields(q) if f.name != "v_w0"
                         and not _same(getattr(q, f.name), getattr(self.q, f.name)))
        if changed:
            raise ValueError(f"set_wind: the scene also changes {changed}: build its own rod")
        self.c.v_w0.value = q.v_w0
        self.params, self.q = params, q

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
        w.sub(self.model.index("centre_line")).interpolate(lambda x: np.outer(top, x[0]))
        w.sub(self.model.index("twist")).interpolate(lambda x: np.zeros(x.shape[1]))
        if self.model.has("director"):  # d3 = the chord's direction (forms/shearable.py)
            w.sub(self.model.index("director")).interpolate(
                lambda x: np.outer(top / np.linalg.norm(top), np.ones(x.shape[1])))
        w.x.scatter_forward()
        self.update_curvature(w)

    def set_centre_line(self, centre_line, w=None, director=None):
        """w <- (r(s) from a callable s -> (n, 3), alpha = 0); the shearable rod's
        director from ``director`` (s -> (n, 3)), or the unit tangent."""
        w = w or self.w
        w.sub(self.model.index("centre_line")).interpolate(lambda x: np.asarray(centre_line(x[0])).T)
        w.sub(self.model.index("twist")).interpolate(lambda x: np.zeros(x.shape[1]))
        if self.model.has("director"):  # d3 = the unit tangent (forms/shearable.py)
            w.sub(self.model.index("director")).interpolate(
                lambda x: (unit_tangent_of(centre_line, x[0]) if director is None
                           else np.asarray(director(x[0]))).T)
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
        """r as UFL (the model's centre line)."""
        return self.model.split(self.w)["centre_line"]

    def curvature(self):
        """kappa as UFL (mixed bending form), or None: r'' is then cellwise."""
        return self.model.split(self.w)["curvature"]

    def internal_twist(self, w=None):
        """z as UFL (hysteretic torsion, forms/hysteresis.py), or None."""
        return self.model.split(w or self.w)["internal_twist"]

    def gather_centre_line(self):
        """(s, r (n, 3)) at the Lagrange nodes on rank 0 ((None, None) elsewhere)."""
        return fields.gather(self.w.sub(self.model.index("centre_line")).collapse())

    def stationary_residual(self, w=None):
        w = w or self.w
        return self.model.residual(w, None, None, self.test, self.c, self.degree, self.penalty,
                                   self.measures)

    def dof_count(self) -> int:
        im = self.W.dofmap.index_map
        return im.size_global * self.W.dofmap.index_map_bs
