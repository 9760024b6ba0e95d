"""The paper's kinematics (``model.kinematics = "paper"``), a component: the forces of Eqs. (30)-(33).

F_NL = (T - mu kappa^2) r' + beta tau (r' x r'') (Eq. 32) and -F_L' = -mu r''''
(Eq. 33) as the C0 interior-penalty form B (forms/interior_penalty.py) or, with
``discretisation.bending = "mixed"``, the mixed form of forms/mixed.py.  Its
stored energy (forms/energy.py) is sigma (|r'|^3/3 - |r'|^2/2) + mu/2 B(r, r);
the rest of F_NL, -mu kappa^2 r' + beta tau (r' x r''), is not the variation
of an energy: its power is :meth:`PaperKinematics.non_variational_force`.
The other kinematics: forms/extensible.py::ExtensibleKinematics.
"""

from __future__ import annotations

import ufl

from rawehelix.forms import mixed
from rawehelix.forms.interior_penalty import bending, jump_d
from rawehelix.forms.kinematics import curvature, d, internal_force, normal_part, stretch, tension


class PaperKinematics:
    """The centre-line forces, stored energy and bending measure of Eqs. (30)-(34)."""

    name = "paper"

    def centre_line_residual(self, r, v, tau, c, degree: int, penalty, dx, dS, kappa=None, eta=None,
                             twist=None, ring=None):
        """int F_NL.v' + mu B(r, v) (32)-(33); with the curvature field ``kappa`` (test
        ``eta``) the mixed form and its equation kappa = r'' (37).  ``tau``: the moment /
        GJ; ``twist``, ``ring``: the twist and alpha, unread (the paper's section is the solid)."""
        if kappa is None:
            return (ufl.inner(internal_force(r, tau, c.sigma, c.mu, c.beta), d(v)) * dx  # (32)
                    + c.bending * c.mu * bending(r, v, degree, penalty, dx, dS))  # (33)
        return (ufl.inner(internal_force(r, tau, c.sigma, c.mu, c.beta, k=kappa), d(v)) * dx
                + c.bending * c.mu * mixed.bending_force(kappa, v, dx)
                - c.mu * mixed.curvature_equation(r, kappa, eta, dx))

    def stored_energy(self, r, c, degree: int, penalty, dx, dS, kappa=None, twist=None, ring=None):
        """int sigma (|r'|^3/3 - |r'|^2/2) + mu/2 B(r, r) (B(r, r) = int |kappa|^2, mixed)."""
        lam = stretch(r)
        bend = (0.5 * bending(r, r, degree, penalty, dx, dS) if kappa is None
                else mixed.energy(kappa, dx))
        return c.sigma * (lam**3 / 3 - lam**2 / 2) * dx + c.bending * c.mu * bend

    def non_variational_force(self, r, tau, c, kappa=None):
        """T r' - F_NL = mu kappa^2 r' - beta tau (r' x r''), Eqs. (29) and (32)."""
        return (tension(r, c.sigma) * d(r)
                - internal_force(r, tau, c.sigma, c.mu, c.beta, k=kappa))

    def bending_measure(self, r, r_t, t, t_t, n):
        """(q, q_t, [[j]], [[j]]_t) of forms/damping.py: q = r'', [[j]] = [[r']]."""
        return d(r, 2), d(r_t, 2), jump_d(r, n), jump_d(r_t, n)

    def bending_curvature(self, r, kappa=None):
        """The bending measure's curvature vector: r'' (Eq. 34), or the mixed form's field."""
        return curvature(r, kappa)

    def bending_modulus(self, r, c):
        """mu times the bending switch (the EI law needs the extensible kinematics)."""
        return c.bending * c.mu

    def clamp(self, r, axis):
        """([[r']] n, r'') at a clamped wall (forms/cantilever.py)."""
        return normal_part(d(r), axis), d(r, 2)
