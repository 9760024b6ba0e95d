"""The planar rod: the reduced model of a planar, torque-free stationary scene.

With fixed ends in the x-z plane (no circle, Eq. 70), gravity along k_E,
wind along i_E and no end torques, the stationary solution of Eqs. (30)-(31)
is r = x i_E + z k_E, alpha = 0 (paper Sec. 5.1).  Solving only for (x, z)
halves the unknowns; the residual is the same UFL with y = 0 and alpha = 0.
The interface is that of :class:`~rawehelix.solvers.discrete.RodDiscretisation`
as far as :class:`~rawehelix.solvers.stationary.StationarySolver` uses it.
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
from rawehelix.forms import rod
from rawehelix.models import kinematics
from rawehelix.parameters import Parameters
from rawehelix.meshes import interval


def planar_allowed(params: Parameters) -> bool:
    """The stationary scene is planar: its upper end lies in the x-z plane (and
    the bending form is the IP one: the mixed form's kappa field is not reduced
    here; it runs on the full rod) and its kinematics reduces (models/kinematics.py)."""
    return (params.ends.circle_radius_m == 0 and params.discretisation.bending == "ip"
            and kinematics.of(params).planar_reduction)


def embed(u):
    """(x, z) -> r = x i_E + z k_E."""
    return ufl.as_vector((u[0], 0.0, u[1]))


class PlanarRod:
    #: the reduced (x, z) rod, not the full rod of solvers/discrete.py (SectionProbe.of_rod)
    planar = True

    def __init__(self, params: Parameters, comm=MPI.COMM_WORLD):
        if not planar_allowed(params):
            raise ValueError("the planar model needs the upper end in the x-z plane and "
                             "discretisation.bending = 'ip'")
        disc = params.discretisation
        self.params, self.q, self.comm = params, params.normalised(), comm
        self.degree, self.penalty = disc.degree, disc.penalty
        self.mesh = interval.mesh_from_parameters(comm, params)
        self.W = compat.vector_space(self.mesh, "Lagrange", self.degree, 2)
        self.V_r = self.W
        self.w = dolfinx.fem.Function(self.W, name="state")
        self.test = ufl.TestFunction(self.W)
        self.c = rod.Coefficients.from_normalised(
            self.q, params.model, make=lambda v: dolfinx.fem.Constant(self.mesh, PETSc.ScalarType(v)))
        self.measures = rod.measures(self.mesh, disc.degree, disc.quadrature_degree)
        top = self.q.top_position(0.0)
        self.top_xz = np.array([top[0], top[2]])
        bottom_v = compat.locate_boundary_vertices(self.mesh, lambda x: np.isclose(x[0], 0.0))
        top_v = compat.locate_boundary_vertices(self.mesh, lambda x: np.isclose(x[0], 1.0))
        self.r_bottom = dolfinx.fem.Function(self.W)
        self.r_top = dolfinx.fem.Function(self.W)
        set_constant(self.r_top, self.top_xz)
        self.bcs = [dolfinx.fem.dirichletbc(self.r_bottom, dolfinx.fem.locate_dofs_topological(
                        self.W, 0, bottom_v)),
                    dolfinx.fem.dirichletbc(self.r_top, dolfinx.fem.locate_dofs_topological(
                        self.W, 0, top_v))]

    def set_top_position(self, position):
        """r(1) <- ``position`` (its x and z), Eq. (36)."""
        self.top_xz = np.array([position[0], position[2]], dtype=float)
        set_constant(self.r_top, self.top_xz)

    def centre_line(self):
        return embed(self.w)

    def get_state(self):
        """None: the planar rod keeps no :class:`~rawehelix.solvers.state.RodState`
        (StationaryResult.state; the full rod's is its fields)."""
        return None

    def stationary_residual(self):
        alpha = dolfinx.fem.Constant(self.mesh, PETSc.ScalarType(0.0))
        return rod.residual_of_fields(embed(self.w), alpha, None, None, None,
                                      (embed(self.test), None), self.c, self.degree,
                                      self.penalty, self.measures)

    def set_chord(self, w=None):
        (w or self.w).interpolate(lambda x: np.outer(self.top_xz, x[0]))

    def set_centre_line(self, centre_line, w=None, director=None):  # no director here
        (w or self.w).interpolate(lambda x: np.asarray(centre_line(x[0]))[:, [0, 2]].T)

    def gather_centre_line(self):
        """(s, r (n, 3) with y = 0) at the Lagrange nodes on rank 0 ((None, None) elsewhere)."""
        s, xz = fields.gather(self.w)
        x = None if xz is None else np.column_stack([xz[:, 0], 0 * xz[:, 0], xz[:, 1]])
        return s, x

    def dof_count(self) -> int:
        im = self.W.dofmap.index_map
        return im.size_global * self.W.dofmap.index_map_bs
