"""A PETSc LU of a scipy sparse matrix (harmonic balance's Newton and its bordered
continuation): MUMPS by default, which pivots (the bordered matrix has a zero
diagonal entry), options under the prefix ``rawehelix_hb_``
(``-rawehelix_hb_pc_factor_mat_solver_type petsc``, ``-rawehelix_hb_ksp_view``)."""

from __future__ import annotations

import numpy as np
import scipy.sparse
from mpi4py import MPI
from petsc4py import PETSc

from rawehelix.solvers.snes import SolverError

PREFIX = "rawehelix_hb_"


class LU:
    """A PETSc LU of a scipy sparse (or dense) matrix, with solve(r, transpose)."""

    def __init__(self, K, comm=MPI.COMM_SELF):
        K = scipy.sparse.csr_matrix(K)
        self.A = PETSc.Mat().createAIJ(K.shape, csr=(K.indptr.astype(PETSc.IntType),
                                                     K.indices.astype(PETSc.IntType), K.data),
                                       comm=comm)
        self.A.assemble()
        self.ksp = PETSc.KSP().create(comm)
        self.ksp.setOperators(self.A)
        self.ksp.setType("preonly")
        pc = self.ksp.getPC()
        pc.setType("lu")
        pc.setFactorSolverType("mumps")
        self.ksp.setOptionsPrefix(PREFIX)
        self.ksp.setFromOptions()
        self.x, self.b = self.A.createVecs()

    def solve(self, r, transpose: bool = False) -> np.ndarray:
        self.b.array[:] = r
        (self.ksp.solveTranspose if transpose else self.ksp.solve)(self.b, self.x)
        reason = self.ksp.getConvergedReason()
        x = self.x.array.copy()
        if reason <= 0 or not np.all(np.isfinite(x)):
            raise SolverError(f"harmonic balance: the LU solve failed (KSP reason {reason}): "
                              f"the Jacobian is singular (a fold or an undamped mode at a "
                              f"harmonic of f1)")
        return x

    def destroy(self):
        self.ksp.destroy()
        self.A.destroy()

    def __del__(self):
        # petsc4py 3.18 leaves a dropped object to PETSc's garbage, freed only by
        # PETSc.garbage_cleanup: the continuation's dropped LUs (MUMPS factors) grew
        # harmonic balance's Fig. 8 by ~7 MB a point at N = 4 (issue 41)
        if not PETSc.Sys.isFinalized():
            self.destroy()
