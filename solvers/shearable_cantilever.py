"""The shearable rod as a cantilever: a tip force and the roll-up under a tip moment.

The clamp holds r(0) = 0 and d3(0) = e_x (the director's dofs at s = 0); alpha = 0
everywhere (model.twist = false: a planar problem); gravity and drag as the scene
says (off for the benchmarks).  The loads are potentials at s = 1:

* a dead force F (normalised by M g): -F . r(1);
* a moment M about e_y (normalised by M g L0), turning d3 in the x-z plane:
  -M phi(1), phi the director's angle from e_x, continued from the previous load
  step as phi_prev + atan2((d_prev x d3).e_y, d_prev . d3) so that it passes pi
  (the roll-up turns the tip by 2 pi) without a branch cut: each step's increment
  stays far below pi.

Closed forms (tests/test_shearable.py): the tip deflection F L^3/(3 EI) + F L/(GA)
of a small force, and the circle of radius EI/M (per unstretched length: a pure
moment stretches and shears nothing) with the tip at the root when M = 2 pi EI/L
(the large-rotation benchmark of comet-fenicsx's finite-rotation beam).
"""

from __future__ import annotations

import numpy as np
import ufl
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.fem

from rawehelix import compat
from rawehelix.forms import shearable
from rawehelix.parameters import Parameters
from rawehelix.solvers.discrete import RodDiscretisation
from rawehelix.solvers.fields import set_constant
from rawehelix.solvers.snes import NewtonSolver

E_X = np.array([1.0, 0.0, 0.0])


class ShearableCantilever:
    """The clamped rod of a shearable scene (``model.kinematics = "shearable"``)."""

    def __init__(self, params: Parameters, comm=MPI.COMM_WORLD):
        params = params.replace(model={"twist": False})
        self.rod = rod = RodDiscretisation(params, comm, pin_twist=False)
        mesh, model = rod.mesh, rod.model
        make = lambda v: dolfinx.fem.Constant(mesh, PETSc.ScalarType(v))  # noqa: E731
        self.force, self.moment = make((0.0, 0.0, 0.0)), make(0.0)
        self.d_prev, self.phi_prev = make(tuple(E_X)), make(0.0)
        f = model.split(rod.w)
        r, n = f["centre_line"], f["director"]
        x = ufl.SpatialCoordinate(mesh)[0]
        dx, _, ds = rod.measures
        d3 = shearable.director(n)
        e_y = ufl.as_vector((0.0, 1.0, 0.0))
        phi = self.phi_prev + compat.atan2(ufl.dot(ufl.cross(self.d_prev, d3), e_y),
                                           ufl.dot(self.d_prev, d3))
        U = (shearable.stored_energy(r, f["twist"], n, rod.c, dx)
             - x * (ufl.dot(self.force, r) + self.moment * phi) * ds)  # the loads at s = 1
        F = ufl.derivative(U, rod.w, rod.test)
        self.newton = NewtonSolver(F, rod.w, self._clamp() + rod.twist_bcs,
                                   prefix="rawehelix_cantilever_")
        self._tip_forms = [dolfinx.fem.form(x * r[i] * ds) for i in range(3)] + \
            [dolfinx.fem.form(x * d3[i] * ds) for i in range(3)]

    def _clamp(self):
        """r(0) = 0 and n(0) = e_x."""
        rod = self.rod
        bottom = compat.locate_boundary_vertices(rod.mesh, lambda x: np.isclose(x[0], 0.0))
        bcs = []
        for role, value in (("centre_line", np.zeros(3)), ("director", E_X)):
            V, _ = compat.collapse(rod.sub(role))
            g = dolfinx.fem.Function(V)
            set_constant(g, value)
            dofs = dolfinx.fem.locate_dofs_topological((rod.sub(role), V), 0, bottom)
            bcs.append(dolfinx.fem.dirichletbc(g, dofs, rod.sub(role)))
        return bcs

    def straight(self):
        """The unloaded state: r = s e_x, n = e_x."""
        rod = self.rod
        rod.w.sub(rod.model.index("centre_line")).interpolate(lambda x: np.outer(E_X, x[0]))
        rod.w.sub(rod.model.index("director")).interpolate(lambda x: np.outer(E_X, 1 + 0 * x[0]))
        rod.w.x.scatter_forward()

    def tip(self) -> tuple[np.ndarray, np.ndarray]:
        """(r(1), d3(1)), on every rank."""
        comm = self.rod.comm
        values = [comm.allreduce(dolfinx.fem.assemble_scalar(f), op=MPI.SUM)
                  for f in self._tip_forms]
        return np.array(values[:3]), np.array(values[3:])

    def tip_force(self, force) -> np.ndarray:
        """r(1) under the dead force ``force`` (normalised), from the straight rod."""
        self.straight()
        self.force.value[:] = np.asarray(force, dtype=float)
        self.moment.value = 0.0
        self.newton.solve("cantilever under a tip force")
        return self.tip()[0]

    def roll_up(self, moment: float, steps: int) -> list[tuple[float, np.ndarray, float]]:
        """Load the tip moment to ``moment`` (normalised) in ``steps`` equal steps from the
        straight rod; per step (M, r(1), phi(1))."""
        self.straight()
        self.force.value[:] = 0.0
        self.d_prev.value[:] = E_X
        self.phi_prev.value = 0.0
        out = []
        for k in range(1, steps + 1):
            self.moment.value = moment * k / steps
            self.newton.solve(f"cantilever roll-up, step {k} of {steps}")
            r1, d1 = self.tip()
            d_prev = np.array(self.d_prev.value)
            phi = float(self.phi_prev.value) + np.arctan2(np.cross(d_prev, d1)[1], d_prev @ d1)
            self.d_prev.value[:] = d1 / np.linalg.norm(d1)
            self.phi_prev.value = phi
            out.append((float(self.moment.value), r1, phi))
        return out
