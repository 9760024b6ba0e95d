"""The curvature field of a centre line: kappa = r'' weakly, for the mixed bending form.

Solves the kappa equation of :mod:`rawehelix.forms.mixed` for a given r,

    int kappa.eta = - int r'.eta'   for all eta with eta(0) = eta(1) = 0,
    kappa(0) = kappa(1) = 0                                         (37)

(a mass-matrix solve), so that a state set from a centre line alone (the
chord, a first guess, the shooting solution) is consistent.  Newton does
not need it; the residual of an outside solution and the index-1 DAE of
the dynamics (kappa is algebraic) do.
"""

from __future__ import annotations

import numpy as np
import ufl
from petsc4py import PETSc

import dolfinx.fem
import dolfinx.fem.petsc

from rawehelix import compat
from rawehelix.forms.kinematics import d
from rawehelix.solvers.snes import SolverError, direct_solver


class CurvatureProjection:
    """kappa of a mixed (r, alpha, kappa) Function <- kappa(r) of the equation above."""

    def __init__(self, rod):
        self.rod = rod
        self.source = dolfinx.fem.Function(rod.W)  # the state whose r is read
        self.V_k, self.parent = rod.V_k, rod.dofs("curvature")
        k, eta = ufl.TrialFunction(self.V_k), ufl.TestFunction(self.V_k)
        dx = rod.measures[0]
        r = rod.model.split(self.source)["centre_line"]
        ends = np.concatenate([compat.locate_boundary_vertices(rod.mesh, lambda x: np.isclose(x[0], v))
                               for v in (0.0, 1.0)]).astype(np.int32)
        self.bcs = [dolfinx.fem.dirichletbc(dolfinx.fem.Function(self.V_k),
                                            dolfinx.fem.locate_dofs_topological(self.V_k, 0, ends))]
        self.L = dolfinx.fem.form(-ufl.inner(d(r), d(eta)) * dx)
        self.A = dolfinx.fem.petsc.assemble_matrix(dolfinx.fem.form(ufl.inner(k, eta) * dx),
                                                   bcs=self.bcs)
        self.A.assemble()
        self.ksp = direct_solver(rod.comm, self.A)
        self.kappa = dolfinx.fem.Function(self.V_k)
        self.b = compat.create_vector(self.L)

    def apply(self, w):
        """Set the kappa part of ``w`` (a Function of rod.W) from its r."""
        self.source.x.array[:] = w.x.array
        with self.b.localForm() as b_local:
            b_local.set(0.0)
        dolfinx.fem.petsc.assemble_vector(self.b, self.L)
        self.b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        dolfinx.fem.petsc.set_bc(self.b, self.bcs)  # homogeneous: no lifting needed
        self.ksp.solve(self.b, compat.petsc_vec(self.kappa))
        if self.ksp.getConvergedReason() < 0:  # a zero pivot of the mass matrix, say
            raise SolverError(f"curvature projection: the LU solve failed (KSP reason "
                              f"{self.ksp.getConvergedReason()})")
        self.kappa.x.scatter_forward()
        w.x.array[self.parent] = self.kappa.x.array
        w.x.scatter_forward()
