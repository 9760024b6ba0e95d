"""The family of a mode of (*) from its eigenvector x, in two steps.

1. centre line or twist: the block (r or alpha) whose own dynamics resonates
   at lambda, i.e. the smaller relative residual of the diagonal block of
   P(lambda) (:meth:`Classifier.block_residuals`).  Energy alone cannot
   decide this when the gamma coupling of Eq. (34) is on: a slaved twist then
   dominates the kinetic energy of the out-of-plane lateral modes.
0. the shearable rod's ``rotation``: most of the kinetic energy in the sections'
   rotary inertia (its shear modes and the director's gauge, forms/shearable.py);
2. for the centre line, the largest kinetic-energy fraction of the
   displacement along the local tangent t of the stationary centre line
   (``longitudinal``), along n = j_E x t (``lateral_in_plane``) and along j_E
   (``lateral_out_of_plane``); the matrices are those of
   :class:`~rawehelix.solvers.linearise.Linearisation`.

|lambda| below a small fraction of the target is the ``rigid`` rotation
(decided by the caller, :class:`~rawehelix.solvers.modal.ModalSolver`).
"""

from __future__ import annotations

import math

import numpy as np
from mpi4py import MPI

from rawehelix.families import ROTATION
from rawehelix.solvers.linearise import COMPONENTS, Linearisation


class Classifier:
    """Energy fractions, block residuals and family of eigenvectors of one
    :class:`Linearisation` (assembled)."""

    def __init__(self, lin: Linearisation):
        self.lin = lin
        self.comm = lin.rod.comm
        self.mask = self._twist_mask()

    def _twist_mask(self) -> np.ndarray:
        """Boolean mask of the owned alpha dofs in a PETSc vector of W."""
        W = self.lin.rod.W
        n_owned = W.dofmap.index_map.size_local * W.dofmap.index_map_bs
        parent = self.lin.rod.dofs("twist")  # the model's twist field (models/base.py)
        mask = np.zeros(n_owned, dtype=bool)
        mask[parent[parent < n_owned]] = True
        return mask

    def _norm(self, z) -> float:
        return math.sqrt(self.comm.allreduce(float(np.sum(np.abs(z)**2)), op=MPI.SUM))

    def block_residuals(self, lam: complex, xr, xi) -> dict:
        """Relative residuals of the centre-line and twist blocks of (*).

        For x_b = x restricted to block b (r or alpha), and P_bb the diagonal
        block of P(lambda) = lambda^2 M + lambda C + K:

            rho_b = |P_bb x_b| / (|K_bb x_b| + |lambda|^2 |M_bb x_b|).

        A block whose own dynamics resonates at lambda has rho_b ~ 0; a block
        that is only driven by the other one has rho_b = O(1) (its residual is
        the coupling force).  This decides between centre line and twist when
        the coupling is one-sided: with the gamma coupling of Eq. (34) on, an
        out-of-plane motion y drives alpha through D gamma ~ y_sss / kappa
        (kappa ~ 0.02 for Table 2), while alpha drives the centre line only
        through the weak beta tau (r' x r'') of Eq. (32); the lateral mode then
        has most of its kinetic energy in alpha, but it is the centre line that
        resonates (and its damping is the lateral drag).  A block that does not
        move at all has rho_b = inf."""
        lin = self.lin
        out = {}
        for name, keep in (("centre_line", ~self.mask), ("twist", self.mask)):
            parts = []
            for x in (xr, xi):
                y = x.copy()
                y.array[~keep] = 0.0
                parts.append(y)
            prod = {}
            for key, A in (("K", lin.K), ("C", lin.C), ("M", lin.M)):
                pr, pi = A.createVecLeft(), A.createVecLeft()
                A.mult(parts[0], pr)
                A.mult(parts[1], pi)
                prod[key] = pr.array[keep] + 1j * pi.array[keep]
            residual = lam**2 * prod["M"] + lam * prod["C"] + prod["K"]
            scale = self._norm(prod["K"]) + abs(lam)**2 * self._norm(prod["M"])
            out[name] = self._norm(residual) / scale if scale > 0 else math.inf
        return out

    def energy_fractions(self, xr, xi):
        """(family fractions, component energies) of the eigenvector xr + i xi."""
        y = self.lin.K.createVecRight()

        def energy(A):
            A.mult(xr, y)
            e = y.dot(xr)
            A.mult(xi, y)
            return e + y.dot(xi)

        fam = {k: energy(A) for k, A in self.lin.energy["family"].items()}
        total = sum(fam.values()) or 1.0
        comps = {k: energy(A) for k, A in self.lin.energy["component"].items()}
        return {k: e / total for k, e in fam.items()}, comps

    def family(self, lam: complex, xr, xi, fractions: dict) -> str:
        """Torsional if the twist block resonates (:meth:`block_residuals`),
        else the centre-line family with the largest kinetic energy."""
        if fractions.get(ROTATION, 0.0) > 0.5:  # the shearable rod's sections turn
            return ROTATION
        rho = self.block_residuals(lam, xr, xi)
        if rho["twist"] < rho["centre_line"]:
            return "torsional"
        lateral = {k: v for k, v in fractions.items() if k not in ("torsional", ROTATION)}
        return max(lateral, key=lateral.get)

    @staticmethod
    def dominant(components: dict) -> list:
        """The components x, y, z, alpha with energy >= 0.5 of the largest."""
        top = max(components.values())
        return [c for c in COMPONENTS if components[c] >= 0.5 * top]
