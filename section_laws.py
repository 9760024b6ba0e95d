"""The section laws (``[section] law``), chosen by name: the one registry that every
module asks instead of testing the name (issue 42, as studies/schemes.py registers
the schemes).

* ``solid`` (the null object): the paper's section, EA, EI and GJ of ``[helix]``;
  its members only measure what a tensegrity would feel (members.py::
  Members.linear_forces);
* ``tensegrity``: the members' own law (section_math.py::TetherRing);
* ``saturating``: the solid's EA and EI inside the cone |M| <= c R N (members.py::
  ConeSection; section_math.py::Cone, the fallback of issue 29).

A :class:`SectionLaw` gives everything decided by the law: whether the FE rod's
stored energy is its own W(eps, kappa) (:attr:`~SectionLaw.nonlinear`) or the
solid's quadratic, whether it is smooth (:attr:`~SectionLaw.smooth`: harmonic
balance's tool), its numbers in the normalised FE rod (:meth:`~SectionLaw.normalised`,
written once with the math namespace of members.py, numpy or UFL), and the numpy law
the ``limits`` block measures the members with.  The names are :data:`NAMES`, which
the scene's check reads (parameters/section.py); :func:`get` refuses any other name
with :func:`refusal`'s one message.
"""

from __future__ import annotations

from rawehelix.members import ConeSection, Members
from rawehelix.registry import Registry
from rawehelix.section_math import NUMPY, Cone, TetherRing


class SectionLaw:
    """The solid, the null object: no law of its own (the FE rod's stored energy is
    forms/extensible.py's quadratic, its limits the solid's resultants)."""

    name = "solid"
    #: the section's stored energy is the law's own W(eps, kappa) (not the solid's quadratic)
    nonlinear = False
    #: the law is C-infinity at any strain (no slack kink, however regularised)
    smooth = True
    #: its resultants are the members' own: they have a phase (section.ring), may carry
    #: the twist (section.torsion) and give the shearable rod's GA
    members = False

    def normalised(self, q, make=float, m=NUMPY):
        """The law in the FE rod's units (``q`` the scene's Normalised; ``make`` wraps the
        numbers a solver may change, ``m`` the math: section_math.NUMPY or forms' UFL_MATH);
        None: the solid's quadratic."""
        return None

    def limits_law(self, section, helix, members: Members):
        """The numpy law of its own the ``limits`` block reads the resultants of (SI),
        beside the members; None: none (the solid's, and the members' own)."""
        return None

    def resultants(self, members: Members, law, N, M, eps, kappa, tau, psi=0.0):
        """(N, |M|) of the section at the strains (SI) for the limits, ``law`` the
        :meth:`limits_law`: the solid's N and M as given."""
        return N, M

    def member_forces(self, members: Members, N, M, Q, eps, kappa, tau, psi=0.0):
        """The members' forces (..., n) [N] and their slack mask: a tensegrity carrying
        the resultants N, M, Q (Members.linear_forces, what a tensegrity would feel)."""
        f = members.linear_forces(N, M, Q)
        return f, f <= 0


class Tensegrity(SectionLaw):
    """The members' own law (members.py)."""

    name, nonlinear, smooth, members = "tensegrity", True, False, True

    def normalised(self, q, make=float, m=NUMPY):
        # the lay angle and the member count shape the form and stay numbers
        return TetherRing(q.section_tethers, make(q.section_radius), q.section_lay_angle,
                          make(q.section_stiffness), make(q.section_prestrain),
                          make(q.section_bar_stiffness), make(q.section_bar_prestrain),
                          make(q.section_width), torsion=q.section_torsion,
                          ring_turns=q.section_ring_turns, m=m)

    def resultants(self, members, law, N, M, eps, kappa, tau, psi=0.0):
        """The members' own resultants at the strains (the ring's phase psi)."""
        r = members.resultants(eps, kappa, tau, psi)
        return r["N"], abs(r["M"])

    def member_forces(self, members, N, M, Q, eps, kappa, tau, psi=0.0):
        """The members' own forces at the rod's strains, slack where their strain <= 0."""
        return members.forces(eps, kappa, tau, psi), members.strains(eps, kappa, tau, psi) <= 0


class Saturating(SectionLaw):
    """The cone (section_math.py::Cone): its resultants, the solid's members' forces."""

    name, nonlinear, smooth = "saturating", True, False

    def normalised(self, q, make=float, m=NUMPY):
        return Cone(make(q.sigma), make(q.mu), make(q.section_saturation * q.section_radius),
                    make(q.section_width), m=m)

    def limits_law(self, section, helix, members):
        return ConeSection(EA=helix.EA_N, EI=helix.EI_Nm2, R=members.R, c=members.saturation,
                           width=section.slack_width)

    def resultants(self, members, law, N, M, eps, kappa, tau, psi=0.0):
        """The cone's resultants at the strains."""
        r = law.resultants(eps, kappa)
        return r["N"], abs(r["M"])


#: every section law by name (the first is the default, the null object)
SECTION_LAWS: Registry[SectionLaw] = Registry("section.law", (SectionLaw(), Tensegrity(),
                                                               Saturating()), listed=list)
#: the names, in the registry's order (the scene's section.law is one of them)
NAMES = SECTION_LAWS.names()
#: why a name is no section law (the list of names), None: it is one
refusal = SECTION_LAWS.refusal
#: the section law of a name; any other name is refused (ValueError) with the list
get = SECTION_LAWS.get


__all__ = ["NAMES", "SECTION_LAWS", "Saturating", "SectionLaw", "Tensegrity", "get", "refusal"]
