"""The interfaces of the components that :class:`~rawehelix.forms.coefficients.Coefficients`
holds (typing.Protocol): what the forms, models and solvers call on each, so that a
new component (or a null object) knows what it must give.  Each implementation is
checked against its protocol (tests/test_components.py)."""

from __future__ import annotations

from typing import Protocol, runtime_checkable

from rawehelix.forms.section_law import SectionComponent


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
class SpinDragLaw(Protocol):
    """The spinning tethers' torque loss (forms/spin_drag.py): SpinDrag, or the null
    NoSpinDrag."""

    fields: tuple

    def dissipation(self, alpha_t, c, dx):
        """The dissipation potential D(alpha_t)."""

    def power(self, alpha_t, c, dx):
        """The power it takes, alpha_t dD/d alpha_t."""

    def residual(self, alpha_t, psi, c, dx):
        """Its torque in the twist equation, delta dD/d alpha_t [psi]."""


@runtime_checkable
class WindProfile(Protocol):
    """The wind's profile in the drag (forms/wind.py): ProfileWind, or the null UniformWind."""

    def speed(self, r, c):
        """The wind's speed (normalised) at the centre line r."""

    def air(self, r, c):
        """-v_w at the centre line r, the vector Eq. (14)'s v_A adds to r_t."""


#: the section law's protocol is written beside the laws it describes
#: (forms/section_law.py::SectionComponent, the registry's UFL half)
SectionLaw = SectionComponent


__all__ = ["BendingLaw", "Damping", "Hysteresis", "Kinematics", "SectionLaw", "SpinDragLaw",
           "WindProfile"]
