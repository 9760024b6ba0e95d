"""K, C, M of the linearised Eqs. (30)-(31) about a stationary state.

About a state w0, a small motion w = w0 + x e^{lambda t} obeys

    (lambda^2 M + lambda C + K) x = 0,                                 (*)

with the three Jacobians of the full residual F(w, w_t, w_tt; v) of
Eqs. (30)-(31) (:meth:`rawehelix.models.unshearable.UnshearableRod.residual`):

    K = dF/dw     at (w0, 0, 0)   elastic + geometric stiffness (32)-(34),
    C = dF/dw_t   at (w0, 0, 0)   the linearised drag of Eq. (28) and the
                                  structural damping (forms/damping.py),
    M = dF/dw_tt                  the mass, int r_tt.v + alpha_tt psi.

Boundary conditions: the displacement vanishes at s = 0 and s = 1
(Eqs. 35-36); the twist is *not* pinned, so with torque-free ends (38)-(39)
the rigid rotation alpha = const is a true mode.  The bc rows are assembled
with 1 on the diagonal of K and 0 on those of C and M: a bc dof then satisfies
x_i = 0 exactly and contributes only *infinite* eigenvalues, which
shift-and-invert maps to 0 and never returns (no spurious finite eigenvalue).

The kinetic-energy matrices classify the modes (:mod:`.classify`): the
displacement u along the local tangent t of the stationary centre line
(``longitudinal``), along n = j_E x t (in the x-z plane, ``lateral_in_plane``)
and along j_E (``lateral_out_of_plane``); the twist with the rotational
inertia beta/delta = 2 rho I / (rho A L0^2) of Eq. (27) (``torsional``); and
per component x, y, z, alpha.  The spline reference uses the same frame.

Mixed bending form (:mod:`rawehelix.forms.mixed`): the curvature kappa has
no inertia and no damping, so M and C are zero on its rows and columns;
its interior dofs then add only infinite eigenvalues (the kappa equation is
a constraint, K's kappa block -mu M_kappa is regular), which shift-and-invert
never returns, and the finite count is 2 (n_r + n_alpha - n_bc).  Its end
conditions kappa = 0 (37) are in the bcs like the displacement's.
"""

from __future__ import annotations


import ufl
from mpi4py import MPI

import dolfinx.fem
import dolfinx.fem.petsc

from rawehelix.forms.kinematics import d
from rawehelix.solvers.state import RodState

COMPONENTS = ("x", "y", "z", "alpha")


def _assemble(a, bcs, diagonal):
    A = dolfinx.fem.petsc.assemble_matrix(a, bcs=bcs, diagonal=diagonal)
    A.assemble()
    return A


class Linearisation:
    """The forms of (*) and of the kinetic energies on one rod; :meth:`assemble`
    evaluates them about a state."""

    def __init__(self, rod, ends=None):
        rod.model.refuse("modal", rod.params.name)  # hysteresis: z = A tau about z = 0
        self.rod = rod
        # separate fields for w, w_t, w_tt: the three Jacobians of F at (w0, 0, 0)
        self.w_t = dolfinx.fem.Function(rod.W, name="velocity")
        self.w_tt = dolfinx.fem.Function(rod.W, name="acceleration")
        F = rod.model.residual(rod.w, self.w_t, self.w_tt, rod.test, rod.c, rod.degree,
                               rod.penalty, rod.measures)  # (30)-(31)
        du = rod.trial
        # structural damping (forms/damping.py): its forces are linear in the rates, so
        # they add nothing to K at w_t = 0; K is taken of the residual without them
        # (the same K, for a fraction of the assembly)
        F_K = rod.model.residual(rod.w, self.w_t, self.w_tt, rod.test,
                                 rod.model.conservative(rod.c), rod.degree, rod.penalty,
                                 rod.measures)
        a = {"K": ufl.derivative(F_K, rod.w, du), "C": ufl.derivative(F, self.w_t, du),
             "M": ufl.derivative(F, self.w_tt, du)}
        # the end components' lumped terms (forms/end_loads.py: a rotor's spin inertia,
        # the aerodynamic and generator damping, Eq. 40's gains); none by default
        for key, form in (ends.forms(du, rod.test) if ends is not None else {}).items():
            a[key] = a[key] + form
        self.a_K, self.a_C, self.a_M = (dolfinx.fem.form(a[k]) for k in "KCM")
        self.twist_dofs = rod.dofs("twist")
        self.bcs = self._fixed_ends()
        self.a_energy = {kind: {k: dolfinx.fem.form(a) for k, a in forms.items()}
                         for kind, forms in self._energy_forms().items()}
        self.a_tension = dolfinx.fem.form(rod.model.tension(rod.model.split(rod.w), rod.c)
                                          * rod.measures[0])
        self.K = self.C = self.M = self.energy = None
        self.mean_tension = None

    def _fixed_ends(self):
        """Homogeneous Dirichlet conditions on the displacement at both ends
        (35)-(36); none on the twist (the rigid rotation stays free), unless
        model.twist = false holds alpha = 0."""
        rod = self.rod
        zero = dolfinx.fem.Function(rod.V_r)
        return [dolfinx.fem.dirichletbc(zero, dofs, rod.sub("centre_line"))
                for dofs in rod.end_dofs.values()] + rod.twist_bcs + rod.curvature_bcs

    def _energy_forms(self) -> dict:
        rod = self.rod
        dx = rod.measures[0]
        model = rod.model
        r0 = model.split(rod.w)["centre_line"]
        u, a = (model.split(rod.trial)[role] for role in ("centre_line", "twist"))
        v, b = (model.split(rod.test)[role] for role in ("centre_line", "twist"))
        t = d(r0) / ufl.sqrt(ufl.dot(d(r0), d(r0)))  # local tangent of the state
        j = ufl.as_vector((0.0, 1.0, 0.0))
        n = ufl.cross(j, t)
        n = n / ufl.sqrt(ufl.dot(n, n) + 1e-300)
        rot = rod.c.beta / rod.c.delta  # (27)
        family = {
            "longitudinal": ufl.dot(u, t) * ufl.dot(v, t) * dx,
            "lateral_in_plane": ufl.dot(u, n) * ufl.dot(v, n) * dx,
            "lateral_out_of_plane": u[1] * v[1] * dx,
            "torsional": rot * a * b * dx,
        }
        comps = {"x": u[0] * v[0] * dx, "y": u[1] * v[1] * dx, "z": u[2] * v[2] * dx,
                 "alpha": rot * a * b * dx}
        if model.has("director"):  # the sections' rotary inertia, forms/shearable.py
            n, m = model.split(rod.trial)["director"], model.split(rod.test)["director"]
            family["rotation"] = rod.c.rotary * ufl.dot(n, m) * dx
        return {"family": family, "component": comps}

    def assemble(self, state: RodState, spin: float = 0.0):
        """K, C, M and the energy matrices about ``state`` (its velocity is
        ignored: the linearisation is about (w0, (0, spin), 0), ``spin`` the uniform
        twist rate of a relative equilibrium, normalised).  Returns (K, C, M)."""
        self.rod.set_state(state)
        self.w_t.x.array[:] = 0.0
        self.w_t.x.array[self.twist_dofs] = spin
        self.w_tt.x.array[:] = 0.0
        self.K = _assemble(self.a_K, self.bcs, 1.0)
        self.C = _assemble(self.a_C, self.bcs, 0.0)
        self.M = _assemble(self.a_M, self.bcs, 0.0)
        self.energy = {kind: {k: _assemble(a, [], 0.0) for k, a in forms.items()}
                       for kind, forms in self.a_energy.items()}
        local = dolfinx.fem.assemble_scalar(self.a_tension)
        self.mean_tension = self.rod.comm.allreduce(local, op=MPI.SUM)  # int_0^1 T ds, (29)
        return self.K, self.C, self.M

    def finite_eigenvalue_count(self) -> int:
        """2 (n - n_bc): the number of finite eigenvalues of (*); the kappa dofs
        of the mixed form (all of them, massless) are not counted."""
        rod = self.rod
        bcs = [bc for bc in self.bcs if all(bc is not k for k in rod.curvature_bcs)]
        n_bc = rod.comm.allreduce(sum(bc.dof_indices()[1] for bc in bcs), op=MPI.SUM)
        n_kappa = 0
        if rod.model.has("curvature"):  # the massless kappa dofs, forms/mixed.py
            im = rod.V_k.dofmap.index_map
            n_kappa = im.size_global * rod.V_k.dofmap.index_map_bs
        return 2 * (rod.dof_count() - n_bc - n_kappa)
