"""The section law (``[section] law``), a component: the stored energy per unit length
W(eps, kappa) of the extensible rod's section (forms/extensible.py), and its
interior-penalty node terms.

Normalised as forms/energy.py (energies in M g L0, so W per length in M g; eps and
the members' strains dimensionless, kappa = |t'| per unstretched length in 1/L0;
parameters/section.py::normalise gives R~ = R / L0, k~ = k / (M g), EA_b~ = EA_b / (M g)).

* :class:`SolidSection` (``"solid"``, the null object): the paper's section,
  sigma/2 eps^2 + mu(eps)/2 |t'|^2 with the EI law if any; it returns
  forms/extensible.py::stored_energy unchanged, the same UFL, so every default number
  is the same bit for bit.
* :class:`TensegritySection` (``"tensegrity"``): the members of members.py, written
  in UFL on the normalised quantities (the one definition is members.py's docstring):

      W = sum_m (k / cos beta) Phi_w(e_m) + EA_b / 2 (eps + e_b0)^2,
      e_m = cos(beta) sqrt((1 + eps - R kappa cos phi_m)^2 + tan(beta)^2) - 1 + e0,

  at tau = 0.  **Torsion is not the members'**: the twist equation (31) keeps the
  scene's GJ; the members' torsional part (the lay's elastic GJ, the tension's
  geometric GJ, the bars' torque Q_b0 tau) lives in members.py for the limits and the
  lab fits only.
* :class:`SaturatingSection` (``"saturating"``, the fallback): the conjugate of the
  complementary energy N^2/(2 EA) + M^2/(2 EI) on the cone |M| <= c R N.  With
  rho = c R, A = EA, B = EI, D = 1/A + rho^2/B, g = eps + rho kappa (the cone's ray)
  and h = eps - B kappa / (rho A) (the taut region is h >= 0) the three pieces of
  the conjugate (A eps^2/2 + B kappa^2/2 where h >= 0; g^2 / (2 D) where h < 0 < g;
  0 where g <= 0) are one formula,

      W = Phi_0(g) / D + (rho A)^2 / (B + rho^2 A) Phi_0(h),   Phi_0(x) = max(x, 0)^2 / 2,

  (the taut quadratic less the ray's is (rho A eps - B kappa)^2 / (2 (B + rho^2 A))).
  Its two kinks (g = 0, h = 0) are smoothed by Phi_0 -> Phi_w, the tethers' ramp
  energy with the section's slack width w (g and h are strains).  Then
  N = (A B <g>_w + rho^2 A^2 <h>_w) / (B + rho^2 A) (A eps all taut) and
  M = rho A B (<g>_w - <h>_w) / (B + rho^2 A) >= 0 (B kappa all taut; M / N -> rho
  as h -> -inf): convex in (eps, kappa) (Phi_w convex of affine maps) and in t'
  (M / kappa >= 0), C-infinity for w > 0.

kappa = sqrt(t'.t' + eta^2), eta = :data:`KAPPA_ETA`: |t'| has no derivative at
t' = 0 (the straight chord); eta shifts W by at most W_kappa eta ~ mu eta^2 (the
members' W is even in kappa at kappa = 0 when all taut), far below round-off of the
energy, and leaves the forces finite.  The bending switch (``model.bending``)
multiplies t' (off: no member feels curvature).

Node terms (the EI law's, forms/extensible.py, for a nonlinear W):
-{{dW/dt'}}.[[t]] + alpha_ip/2 {{EI_t}} |[[t]]|^2, dW/dt' = W_kappa t' / kappa and EI_t
the taut bending modulus (K R^2 / 2 of members.py's closed forms; mu for the
saturating law): consistent because the exact solution has [[t]] = 0.

The tension observable (models/unshearable.py::tension, Eq. 29) stays T = sigma eps,
the solid's; :meth:`axial_force` gives N = dW/d eps of a law (the members' N).
"""

from __future__ import annotations

import math

import ufl

from rawehelix.forms.extensible import bending_modulus, stored_energy, strain
from rawehelix.forms.interior_penalty import jump
from rawehelix.forms.kinematics import d, unit_tangent

#: eta, the curvature's regularisation sqrt(t'.t' + eta^2) (normalised, 1/L0)
KAPPA_ETA = 1.0e-10


def ramp(e, w):
    """<e>_w = (e + sqrt(e^2 + w^2)) / 2 (members.py::smooth_ramp) in UFL."""
    return 0.5 * (e + ufl.sqrt(e * e + w * w))


def ramp_energy(e, w):
    """Phi_w(e) (members.py::ramp_energy) in UFL, w > 0: (e^2 + e root + w^2 ln(plus / w)) / 4,
    plus = e + root, taken as w^2 / (root - e) for e < 0 where e + root loses digits."""
    root = ufl.sqrt(e * e + w * w)
    plus = ufl.conditional(ufl.ge(e, 0), e + root, w * w / (root - e))
    return 0.25 * (e * e + e * root + w * w * ufl.ln(plus / w))


class SolidSection:
    """The paper's section (the null object): forms/extensible.py::stored_energy."""

    name = "solid"

    def energy(self, r, c, alpha_ip, dx, dS):
        return stored_energy(r, c.sigma, bending_modulus(r, c), alpha_ip, dx, dS,
                             field=c.bending_law.field)

    def axial_force(self, r, c):
        """N = sigma eps (Eq. 29), without the EI law's 1/2 mu'(eps) kappa^2."""
        return c.sigma * strain(r)


class NonlinearSection:
    """A section energy W(eps, kappa) with its IP node terms (module docstring);
    subclasses give :meth:`W`, :meth:`dW` (W_eps, W_kappa) and ``taut_bending``."""

    name = ""
    taut_bending = 0.0

    def W(self, eps, kappa):
        raise NotImplementedError

    def dW(self, eps, kappa):
        raise NotImplementedError

    @staticmethod
    def curvature(q):
        """kappa = sqrt(q.q + eta^2) (module docstring)."""
        return ufl.sqrt(ufl.dot(q, q) + KAPPA_ETA**2)

    def strains(self, r, c):
        """(eps, q = bending switch x t', kappa)."""
        q = c.bending * d(unit_tangent(r))
        return strain(r), q, self.curvature(q)

    def moment(self, r, c):
        """dW/dt' = W_kappa t' / kappa (with the bending switch)."""
        eps, q, kappa = self.strains(r, c)
        return c.bending * self.dW(eps, kappa)[1] / kappa * q

    def axial_force(self, r, c):
        """N = dW/d eps."""
        eps, _, kappa = self.strains(r, c)
        return self.dW(eps, kappa)[0]

    def energy(self, r, c, alpha_ip, dx, dS):
        """int W dx - sum {{dW/dt'}}.[[t]] + alpha_ip/2 {{EI_t}} |[[t]]|^2."""
        n = ufl.FacetNormal(dS.ufl_domain())
        eps, _, kappa = self.strains(r, c)
        jump_t = jump(unit_tangent(r), n)
        m = self.moment(r, c)
        avg_m = 0.5 * (m("+") + m("-"))  # {{dW/dt'}}
        EI_t = c.bending * self.taut_bending
        return (self.W(eps, kappa) * dx
                + (-ufl.dot(avg_m, jump_t) + 0.5 * alpha_ip * EI_t * ufl.dot(jump_t, jump_t)) * dS)


class TensegritySection(NonlinearSection):
    """The members (module docstring); numbers or constants, normalised."""

    name = "tensegrity"

    def __init__(self, n: int, R, beta: float, k, e0, EA_b, e_b0, width):
        self.n, self.R, self.beta, self.k, self.e0 = n, R, beta, k, e0
        self.EA_b, self.e_b0, self.width = EA_b, e_b0, width
        self.phi = [2 * math.pi * m / n for m in range(n)]
        cb, sb = math.cos(beta), math.sin(beta)
        # K R^2 / 2, K = n (k cos^3 beta + P0 cos beta sin^2 beta), P0 = k e0 (members.py)
        self.taut_bending = n * k * cb * (cb * cb + e0 * sb * sb) * R * R / 2

    def _members(self, eps, kappa):
        """[(a_m, l_m, e_m)] of members.py::Members._stretch and strains, tau = 0."""
        cb, tb = math.cos(self.beta), math.tan(self.beta)
        out = []
        for phi in self.phi:
            a = 1 + eps - self.R * kappa * math.cos(phi)
            l = ufl.sqrt(a * a + tb * tb) if tb != 0 else a  # a > 0: the stretch
            out.append((a, l, cb * l - 1 + self.e0))
        return out

    def member_strains(self, eps, kappa):
        return [e for _, _, e in self._members(eps, kappa)]

    def W(self, eps, kappa):
        tethers = sum(ramp_energy(e, self.width) for _, _, e in self._members(eps, kappa))
        return self.k / math.cos(self.beta) * tethers + 0.5 * self.EA_b * (eps + self.e_b0)**2

    def dW(self, eps, kappa):
        """(N, M) of members.py::Members.resultants at tau = 0."""
        N, M = self.EA_b * (eps + self.e_b0), 0
        for phi, (a, l, e) in zip(self.phi, self._members(eps, kappa)):
            f = self.k * ramp(e, self.width) * a / l
            N, M = N + f, M - f * self.R * math.cos(phi)
        return N, M


class SaturatingSection(NonlinearSection):
    """The cone law (module docstring): A = sigma, B = mu, rho = c R~."""

    name = "saturating"

    def __init__(self, A, B, rho, width):
        self.A, self.B, self.rho, self.width = A, B, rho, width
        self.taut_bending = B

    def _gh(self, eps, kappa):
        return eps + self.rho * kappa, eps - self.B * kappa / (self.rho * self.A)

    def W(self, eps, kappa):
        A, B, rho = self.A, self.B, self.rho
        g, h = self._gh(eps, kappa)
        return (A * B * ramp_energy(g, self.width)
                + (rho * A)**2 * ramp_energy(h, self.width)) / (B + rho * rho * A)

    def dW(self, eps, kappa):
        A, B, rho = self.A, self.B, self.rho
        g, h = self._gh(eps, kappa)
        G, H = ramp(g, self.width), ramp(h, self.width)
        return ((A * B * G + (rho * A)**2 * H) / (B + rho * rho * A),
                rho * A * B * (G - H) / (B + rho * rho * A))


def from_normalised(q, make=float):
    """The section law of :class:`rawehelix.parameters.Normalised`: the solid (null
    object) unless ``section_law`` names another; ``make`` wraps the numbers a solver
    may change (the lay angle and the member count shape the form and stay numbers)."""
    if q.section_law == "tensegrity":
        return TensegritySection(q.section_tethers, make(q.section_radius), q.section_lay_angle,
                                 make(q.section_stiffness), make(q.section_prestrain),
                                 make(q.section_bar_stiffness), make(q.section_bar_prestrain),
                                 make(q.section_width))
    if q.section_law == "saturating":
        return SaturatingSection(make(q.sigma), make(q.mu),
                                 make(q.section_saturation * q.section_radius), make(q.section_width))
    return SolidSection()
