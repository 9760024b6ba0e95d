"""The interfaces of the components that :class:`~rawehelix.forms.coefficients.Coefficients`
holds (typing.Protocol): what the forms, models and solvers call on each, so that a
new component (or a null object) knows what it must give.  Each implementation is
checked against its protocol (tests/test_components.py)."""

from __future__ import annotations

from typing import Protocol, runtime_checkable


@runtime_checkable
class Kinematics(Protocol):
    """The rod's kinematics (forms/paper.py, extensible.py, shearable.py)."""

    name: str

    def bending_modulus(self, r, c):
        """mu at the centre line r (with the EI law)."""


@runtime_checkable
class Damping(Protocol):
    """Structural damping (forms/damping.py): KelvinVoigt, or the null NoneDamping."""

    fields: tuple

    def dissipation(self, r, r_t, alpha_t, c, degree: int, penalty, measures):
        """The dissipation potential D."""

    def residual(self, r, r_t, alpha_t, v, psi, c, degree: int, penalty, measures):
        """The viscous residual dD/dw_t."""


@runtime_checkable
class BendingLaw(Protocol):
    """The EI law (forms/eilaw.py): TensionDependentBending, or the null ConstantBending."""

    field: bool  # mu depends on the state

    def modulus(self, r, c):
        """The bending switch times mu."""


@runtime_checkable
class Hysteresis(Protocol):
    """Hysteretic torsion (forms/hysteresis.py): BoucWen, or the null NoneHysteresis."""

    fields: tuple
    refuses: dict

    def moment(self, tau, z):
        """The twisting moment / GJ."""

    def residual(self, z, z_t, tau_t, zeta, dx, c):
        """z's equation."""


@runtime_checkable
class SectionLaw(Protocol):
    """The section law (forms/section_law.py): TensegritySection, SaturatingSection,
    or the null SolidSection."""

    name: str
    torsion: bool
    ring_turns: bool

    def energy(self, r, c, alpha_ip, dx, dS, tau=None, alpha=None):
        """The stored energy of the section's law."""

    def axial_force(self, r, c, tau=0, alpha=None):
        """N."""

    def twist_moment(self, r, tau, c, alpha=None):
        """The twisting moment / GJ of Eq. (31)."""

    def ring_phase(self, r, c, alpha):
        """The ring's phase psi against the bending plane."""

    def twist_energy(self, tau, c):
        """The twist's stored energy per length."""

    def shear_stiffness(self, eps, kappa, c):
        """GA~ at the strains."""


__all__ = ["BendingLaw", "Damping", "Hysteresis", "Kinematics", "SectionLaw"]
