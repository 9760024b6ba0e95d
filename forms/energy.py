"""Energy of the rod, Eqs. (30)-(31), in pure UFL.

With the twist equation (31) multiplied by beta/delta (= 2 mu/sigma), the
conservative part of the residual of :mod:`rawehelix.forms.rod` is the
variation of

    E = K + U,
    K = 1/2 int |r_t|^2 + beta/(2 delta) int alpha_t^2                   kinetic
    U = int sigma (|r'|^3/3 - |r'|^2/2) + mu/2 B(r, r)
        + beta/2 int tau^2 - int k_E . r                                   elastic + gravity

since d/dr' [sigma (|r'|^3/3 - |r'|^2/2)] = sigma (|r'| - 1) r' = T r' (Eq. 29:
the paper's tension force is exactly variational with this density), B is
the symmetric interior-penalty bending form (so d(B(r, r)/2) = B(r, v)), and
gravity +k_E has the potential -k_E . r.  What is *not* the variation of E:

- the -mu kappa^2 r' part of F_NL (Eq. 32), from the inextensibility
  assumption of Sec. 2;
- beta tau (r' x r'') in the centre-line equation, whose energy partner would
  be beta tau d(gamma)/dr; with gamma off (tau = alpha') it is a one-way coupling;
- drag (Eq. 28) and the end torques, which do work.

With the mixed bending form (:mod:`rawehelix.forms.mixed`) mu/2 B(r, r) is
mu/2 int |kappa|^2, and every r'' is the curvature field ``kappa``.

With ``model.kinematics = "extensible"`` the stretch and bending parts of U
are the stored energy of :mod:`rawehelix.forms.extensible`, whose variation is
that model's residual (with the EI law's mu(eps) when the helix has one); the one non-variational part of its F_NL is then the
twist coupling beta tau (r' x r'').

All normalised: energies in units of M g L0.
"""

from __future__ import annotations

import ufl

from rawehelix.forms.coefficients import Coefficients
from rawehelix.forms.kinematics import d, twist
from rawehelix.forms.rod import K_E


def kinetic(r_t, alpha_t, c: Coefficients, dx):
    """K = 1/2 int |r_t|^2 + beta/(2 delta) int alpha_t^2."""
    return (0.5 * ufl.inner(r_t, r_t) + 0.5 * c.beta / c.delta * alpha_t**2) * dx


def potential(r, alpha, c: Coefficients, degree: int, penalty, measures, kappa=None):
    """U = int sigma (l^3/3 - l^2/2) + mu/2 B(r, r) + beta/2 int tau^2 - int k_E.r, l = |r'|;
    B(r, r) = int |kappa|^2 with the curvature field ``kappa``."""
    dx, dS, _ = measures
    tau = twist(r, alpha, c.gamma_eps, c.gamma_coupling, k=kappa)  # (34)
    # stretch and bending: the kinematics component's (forms/paper.py, forms/extensible.py)
    # beta/2 tau^2, or 0 when the section's members carry the twist (forms/section_law.py)
    return ((c.section.twist_energy(tau, c) - c.gravity * ufl.dot(K_E, r)) * dx
            + c.kinematics.stored_energy(r, c, degree, penalty, dx, dS, kappa=kappa, twist=tau,
                                         ring=alpha)
            + sum(comp.energy(r, c, dx) for comp in c.extra))  # forms/coefficients.py


def non_variational_power(r, alpha, r_t, c: Coefficients, dx, kappa=None):
    """Power of the parts of F_NL that are not the variation of E (see above):
    P = int (T r' - F_NL) . r_t' = int [mu kappa^2 r' - beta tau (r' x r'')] . r_t',
    with F_NL of Eq. (32) and its variational part T r'."""
    tau = twist(r, alpha, c.gamma_eps, c.gamma_coupling, k=kappa)  # (34)
    moment = c.section.twist_moment(r, tau, c, alpha)  # tau, or the members' Q / GJ
    f = c.kinematics.non_variational_force(r, moment, c, kappa=kappa)  # (29), (32)
    return ufl.inner(f, d(r_t)) * dx
