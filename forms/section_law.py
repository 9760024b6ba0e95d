"""The section law (``[section] law``), a component: the stored energy per unit length
W(eps, kappa) of the extensible rod's section (forms/extensible.py), and its
interior-penalty node terms.

Normalised as forms/energy.py (energies in M g L0, so W per length in M g; eps and
the members' strains dimensionless, kappa = |t'| per unstretched length in 1/L0;
parameters/section.py::normalise gives R~ = R / L0, k~ = k / (M g), EA_b~ = EA_b / (M g)).

The law is chosen by name once, in the registry section_laws.py, whose object gives
its numbers (``SectionLaw.normalised``: section_math.py::TetherRing or Cone, the same
definition the numpy limits use, written here with :data:`UFL_MATH`); this module
wraps them in the rod's strains:

* :class:`SolidSection` (``"solid"``, the null object): the paper's section,
  sigma/2 eps^2 + mu(eps)/2 |t'|^2 with the EI law if any; it returns
  forms/extensible.py::stored_energy unchanged, the same UFL, so every default number
  is the same bit for bit.
* :class:`NonlinearSection` of ``"tensegrity"``: the members of members.py, in UFL
  on the normalised quantities (the one definition is section_math.py::TetherRing):

      W = sum_m (k / cos beta) Phi_w(e_m) + EA_b / 2 (eps + e_b0)^2,
      e_m = cos(beta) sqrt((1 + eps - R kappa cos phi_m)^2 + tan(beta)^2) - 1 + e0,

  at tau = 0 with ``[section] torsion = "helix"`` (the default): the twist equation
  (31) keeps the scene's GJ, and the members' torsional part lives in members.py for
  the limits and the lab fits only.  With ``torsion = "members"`` the members carry
  the twist too: tau enters their tangential advance R tau + tan(beta), W gains the
  bars' Q_b0 tau, the twist equation's moment / GJ is Q / GJ with Q = dW/d tau
  (members.py::Members.resultants: the lay's elastic and the tension's geometric
  torque) and the twisting moment's shear force of F_NL is Q (r' x r'') (Eq. 32 with
  beta tau -> Q).  The centre line's variation holds tau fixed, as the solid's does
  (forms/energy.py: the gamma coupling is one way).
  With ``[section] ring = "turning"`` the members' phase follows the directors:
  d1, d2 are (e1, e2) = (j_E projected on the section's plane, t x e1) turned by
  alpha, member m bends by kappa_m = cos(phi_m) kappa_1 + sin(phi_m) kappa_2 with
  kappa_i = t'.d_i (the worst phase's kappa cos(phi_m) otherwise), the moment is
  M1 d1 + M2 d2, and W depends on alpha: the twist equation gains
  (delta / beta) dW/d alpha (forms/rod.py), zero while every member is taut.
* :class:`NonlinearSection` of ``"saturating"`` (the fallback, section_math.py::Cone): the conjugate of the
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

The tension observable (models/unshearable.py::tension, Eq. 29) is sigma eps for the
solid and :meth:`axial_force`, N = dW/d eps, for a member law (a slack tether pulls
nothing; sigma eps would).
"""

from __future__ import annotations

import math
from typing import Protocol, runtime_checkable

import ufl

from rawehelix import section_laws
from rawehelix.compat import atan2
from rawehelix.forms.extensible import bending_modulus, stored_energy, strain
from rawehelix.forms.interior_penalty import jump
from rawehelix.forms.kinematics import d, unit_tangent
from rawehelix.section_math import ramp_energy as _ramp_energy
from rawehelix.section_math import smooth_ramp

#: j_E, the turning ring's reference direction (normal to every chord, forms/rod.py's frame)
J_E = ufl.as_vector((0.0, 1.0, 0.0))

#: eta, the curvature's regularisation sqrt(t'.t' + eta^2) (normalised, 1/L0)
KAPPA_ETA = 1.0e-10


class UflMath:
    """section_math.py::NumpyMath's names in UFL: the laws of members.py written once."""

    sqrt = staticmethod(ufl.sqrt)
    ln = staticmethod(ufl.ln)
    cos = staticmethod(ufl.cos)

    @staticmethod
    def array(x):
        return x

    @staticmethod
    def select_nonneg(x, then, otherwise):
        return ufl.conditional(ufl.ge(x, 0), then, otherwise)

    @staticmethod
    def divisor(x):
        return x  # the conditional takes one branch

    @staticmethod
    def unregularised(w) -> bool:
        return False  # the FE rod's width is > 0 (section.slack_width)


UFL_MATH = UflMath()


def ramp(e, w):
    """<e>_w = (e + sqrt(e^2 + w^2)) / 2 (section_math.py::smooth_ramp) in UFL."""
    return smooth_ramp(e, w, UFL_MATH)


def ramp_energy(e, w):
    """Phi_w(e) (section_math.py::ramp_energy) in UFL, w > 0."""
    return _ramp_energy(e, w, UFL_MATH)


@runtime_checkable
class SectionComponent(Protocol):
    """What the rod's forms, models and solvers ask of a scene's section (``c.section``):
    the null object :class:`SolidSection` and every law's :class:`NonlinearSection`
    answer all of it (tests/test_section_laws.py)."""

    torsion: bool  # the members carry the twist
    ring_turns: bool  # the members' phase turns with alpha

    def energy(self, r, c, alpha_ip, dx, dS, tau=None, alpha=None): ...

    def axial_force(self, r, c, tau=0, alpha=None): ...

    def axial_force_at(self, eps, kappa, c): ...

    def bending_moment_at(self, eps, kappa, mu, curvature): ...

    def sheared_density(self, eps, g, k, r, c): ...

    def shear_stiffness(self, eps, kappa, c): ...

    def wall_moment(self, x, c, tau, alpha, mu): ...

    def twist_moment(self, r, tau, c, alpha=None): ...

    def twist_energy(self, tau, c): ...

    def ring_phase(self, r, c, alpha): ...


class HelixTorsion:
    """The scene's GJ carries the twist (every section unless its members do)."""

    torsion = False  # the members carry the twist ([section] torsion = "members")
    ring_turns = False  # the members' phase turns with alpha ([section] ring = "turning")

    def twist_moment(self, r, tau, c, alpha=None):
        """The twisting moment / GJ of Eq. (31): tau."""
        return tau

    def ring_phase(self, r, c, alpha):
        """The ring's phase psi against the bending plane (members.py): 0, a member on it."""
        return 0.0

    def twist_energy(self, tau, c):
        """The twist's stored energy per length, beta/2 tau^2 (forms/energy.py)."""
        return 0.5 * c.beta * tau**2


class SolidSection(HelixTorsion):
    """The paper's section (the null object): forms/extensible.py::stored_energy, and
    the solid's answer to every question a member law answers."""

    def energy(self, r, c, alpha_ip, dx, dS, tau=None, alpha=None):
        return stored_energy(r, c.sigma, bending_modulus(r, c), alpha_ip, dx, dS,
                             field=c.bending_law.field)

    def axial_force(self, r, c, tau=0, alpha=None):
        """N = sigma eps (Eq. 29), without the EI law's 1/2 mu'(eps) kappa^2."""
        return c.sigma * strain(r)

    def axial_force_at(self, eps, kappa, c):
        """N at the stretch eps (the shearable rod's Gamma_3): sigma eps."""
        return c.sigma * eps

    def bending_moment_at(self, eps, kappa, mu, curvature):
        """|M| at the strains: the kinematics' mu times the curvature |d3'| (unregularised)."""
        return mu * curvature

    def sheared_density(self, eps, g, k, r, c):
        """The shearable rod's elastic energy per length (forms/shearable.py) without the
        gauge: sigma/2 Gamma_3^2 + GA~/2 |Gamma_s|^2 + mu/2 |d3'|^2 (helix.GA_N)."""
        return (0.5 * c.sigma * eps ** 2 + 0.5 * c.shear * ufl.dot(g, g)
                + 0.5 * c.bending_law.modulus(r, c) * ufl.dot(k, k))

    def shear_stiffness(self, eps, kappa, c):
        """GA~ of the shearable rod: the scene's helix.GA_N."""
        return c.shear

    def wall_moment(self, x, c, tau, alpha, mu):
        """(the wall's bending modulus, its moment dW/dt' or None: mu t') of the clamped
        cantilever (forms/cantilever.py::clamp_energy): the kinematics' mu."""
        return mu, None


class NonlinearSection(HelixTorsion):
    """A section energy W(eps, kappa) with its IP node terms (module docstring): ``law``
    the registry's numbers (section_laws.py: section_math.py::TetherRing or Cone in UFL)."""

    def __init__(self, law):
        self.law = law
        self.torsion, self.ring_turns = law.torsion, law.ring_turns
        self.taut_bending = law.taut_bending

    def W(self, eps, kappa, tau=0, bends=None):
        return self.law.W(eps, kappa, tau, bends)

    def dW(self, eps, kappa, tau=0, bends=None):
        """(N, M) = dW/d(eps, kappa) (M at the worst phase)."""
        return self.law.dW(eps, kappa, tau, bends)

    def member_strains(self, eps, kappa, tau=0, bends=None):
        return self.law.member_strains(eps, kappa, tau, bends)

    def torque(self, eps, kappa, tau, bends=None):
        """Q = dW/d tau (the members' torque)."""
        return self.law.torque(eps, kappa, tau, bends)

    def shear_stiffness(self, eps, kappa, c):
        """GA~ of the shearable rod (forms/shearable.py) at the strains: the members' at
        their mean force, or the scene's helix.GA_N."""
        return self.law.shear_stiffness(eps, kappa, c.shear)

    @staticmethod
    def curvature(q):
        """kappa = sqrt(q.q + eta^2) (module docstring)."""
        return ufl.sqrt(ufl.dot(q, q) + KAPPA_ETA**2)

    def strains(self, r, c):
        """(eps, q = bending switch x t', kappa)."""
        q = c.bending * d(unit_tangent(r))
        return strain(r), q, self.curvature(q)

    # -- the turning ring: the members' phase from the directors ----------------------
    @staticmethod
    def ring_frame(r):
        """(e1, e2): e1 the unit projection of j_E on the section's plane, e2 = t x e1.
        j_E is normal to every chord of Eq. (66) (in the (i_E, k_E) plane), so e1 exists
        while the tangent stays within 90 degrees of the chord."""
        t = unit_tangent(r)
        p = J_E - ufl.dot(J_E, t) * t
        e1 = p / ufl.sqrt(ufl.dot(p, p))
        return e1, ufl.cross(t, e1)

    def directors(self, r, alpha):
        """(d1, d2) = the ring frame (e1, e2) turned by the twist angle alpha (None: 0):
        member m lies along cos(phi_m) d1 + sin(phi_m) d2."""
        e1, e2 = self.ring_frame(r)
        if alpha is None:
            return e1, e2
        ca, sa = ufl.cos(alpha), ufl.sin(alpha)
        return ca * e1 + sa * e2, ca * e2 - sa * e1

    def ring_phase(self, r, c, alpha):
        """psi = alpha - theta, theta the angle of t' from e1: member m then bends by
        kappa cos(phi_m + psi) (members.py's phase); 0 for the worst-phase ring."""
        if not self.ring_turns:
            return 0.0
        e1, e2 = self.ring_frame(r)
        q = d(unit_tangent(r))
        theta = atan2(ufl.dot(q, e2), ufl.dot(q, e1) + KAPPA_ETA)
        return (0 if alpha is None else alpha) - theta

    def bends(self, r, c, alpha=None):
        """kappa_m, member m's curvature for a turning ring: cos(phi_m) kappa_1 +
        sin(phi_m) kappa_2 with kappa_i = q.d_i the curvatures in the directors' frame;
        None otherwise (the law's kappa cos(phi_m))."""
        if not self.ring_turns:
            return None
        _, q, _ = self.strains(r, c)
        d1, d2 = self.directors(r, alpha)
        k1, k2 = ufl.dot(q, d1), ufl.dot(q, d2)
        return [math.cos(phi) * k1 + math.sin(phi) * k2 for phi in self.law.phi]

    def member_state(self, r, c, alpha=None):
        """(eps, kappa, the members' curvatures of :meth:`bends`) at the rod's strains."""
        eps, _, kappa = self.strains(r, c)
        return eps, kappa, self.bends(r, c, alpha)

    # -- the law at the rod's strains -------------------------------------------------
    def moment(self, r, c, tau=0, alpha=None):
        """dW/dt' (with the bending switch): W_kappa t' / kappa, or for the turning ring
        M1 d1 + M2 d2, M_i = -R sum_m (dW/da_m) (cos, sin)(phi_m)."""
        if not self.ring_turns:
            eps, q, kappa = self.strains(r, c)
            return c.bending * self.dW(eps, kappa, tau)[1] / kappa * q
        eps, kappa, bends = self.member_state(r, c, alpha)
        _, M1, M2, _ = self.law.resultants(eps, kappa, tau, bends)
        d1, d2 = self.directors(r, alpha)
        return c.bending * (M1 * d1 + M2 * d2)

    def axial_force(self, r, c, tau=0, alpha=None):
        """N = dW/d eps."""
        eps, kappa, bends = self.member_state(r, c, alpha)
        return self.dW(eps, kappa, tau, bends)[0]

    def cell_energy(self, r, c, tau=0, alpha=None):
        """W per length at the rod's strains."""
        eps, kappa, bends = self.member_state(r, c, alpha)
        return self.W(eps, kappa, tau, bends)

    def twist_moment(self, r, tau, c, alpha=None):
        """The twisting moment / GJ of Eq. (31): Q / beta with the members' torque, or tau."""
        if not self.torsion:
            return super().twist_moment(r, tau, c)
        eps, kappa, bends = self.member_state(r, c, alpha)
        return self.law.torque(eps, kappa, tau, bends) / c.beta

    def twist_energy(self, tau, c):
        """beta/2 tau^2, or 0: the members' W holds the twist's energy."""
        return 0 if self.torsion else super().twist_energy(tau, c)

    def energy(self, r, c, alpha_ip, dx, dS, tau=None, alpha=None):
        """int W dx - sum {{dW/dt'}}.[[t]] + alpha_ip/2 {{EI_t}} |[[t]]|^2; ``tau`` the
        twist (held fixed in the centre line's variation), read if :attr:`torsion`;
        ``alpha`` the twist angle, read if :attr:`ring_turns` (None: 0)."""
        n = ufl.FacetNormal(dS.ufl_domain())
        tau = 0 if tau is None else tau  # read by the members' law only if it carries the twist
        jump_t = jump(unit_tangent(r), n)
        m = self.moment(r, c, tau, alpha)
        avg_m = 0.5 * (m("+") + m("-"))  # {{dW/dt'}}
        EI_t = c.bending * self.taut_bending
        return (self.cell_energy(r, c, tau, alpha) * dx
                + (-ufl.dot(avg_m, jump_t) + 0.5 * alpha_ip * EI_t * ufl.dot(jump_t, jump_t)) * dS)

    # -- the null object's questions ---------------------------------------------------
    def axial_force_at(self, eps, kappa, c):
        """N = dW/d eps at the strains."""
        return self.dW(eps, kappa)[0]

    def bending_moment_at(self, eps, kappa, mu, curvature):
        """M = dW/d kappa at the strains (not the kinematics' mu)."""
        return self.dW(eps, kappa)[1]

    def sheared_density(self, eps, g, k, r, c):
        """W(Gamma_3, |bending switch x d3'|) + GA~/2 |Gamma_s|^2, GA~ the section's."""
        kappa = self.curvature(c.bending * k)
        return self.W(eps, kappa) + 0.5 * self.shear_stiffness(eps, kappa, c) * ufl.dot(g, g)

    def wall_moment(self, x, c, tau, alpha, mu):
        """The wall's taut bending modulus and the law's moment dW/dt' (forms/cantilever.py)."""
        return c.bending * self.taut_bending, self.moment(x, c, tau, alpha)


def from_normalised(q, make=float):
    """The section law of :class:`rawehelix.parameters.Normalised` (the registry's,
    section_laws.py): the solid (null object) unless its law has an energy of its own;
    ``make`` wraps the numbers a solver may change."""
    law = section_laws.get(q.section_law)
    return NonlinearSection(law.normalised(q, make, UFL_MATH)) if law.nonlinear else SolidSection()
