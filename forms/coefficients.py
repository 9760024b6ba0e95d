"""The normalised groups of Eqs. (26)-(27) as the forms read them (:class:`Coefficients`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from rawehelix.forms import wind as wind_profile
from rawehelix.forms.components import (BendingLaw, Damping, Hysteresis, Kinematics, SectionLaw,
                                        SpinDragLaw, WindProfile)
from rawehelix.forms.damping import KelvinVoigt, NoneDamping
from rawehelix.forms.eilaw import ConstantBending, TensionDependentBending
from rawehelix.forms.extensible import ExtensibleKinematics
from rawehelix.forms.hysteresis import BoucWen, NoneHysteresis
from rawehelix.forms.paper import PaperKinematics
from rawehelix.forms.shearable import ShearableKinematics
from rawehelix.forms.spin_drag import NoSpinDrag, SpinDrag
from rawehelix.forms import section_law

#: the kinematics components by the name a scene gives (model.kinematics, parameters/sections.py):
#: the UFL half of the kinematics registry models/kinematics.py (forms lie below models)
KINEMATICS = {"paper": PaperKinematics, "extensible": ExtensibleKinematics,
              "shearable": ShearableKinematics}

#: the components that add a stored energy per length W(r) and nothing else
#: (forms/energy_component.py): the residual gets their variation (forms/rod.py), the
#: energy W (forms/energy.py).  Each is a class with from_normalised(q, make) (its
#: null object when off); a new one is appended here.
ENERGY_COMPONENTS = ()

#: the components built from the normalised groups, by their field of Coefficients:
#: ``build(q, make)`` gives the component, or its null object when the scene has it off
COMPONENTS = {"damping": KelvinVoigt.from_normalised,
              "bending_law": TensionDependentBending.from_normalised,
              "hysteresis": BoucWen.from_normalised,
              "section": section_law.from_normalised,
              "spin_drag": SpinDrag.from_normalised,
              "wind": wind_profile.from_normalised}


@dataclass
class Coefficients:
    """The normalised groups of Eqs. (26)-(27) as UFL-ready values.

    Each field is a number or a constant (for instance ``dolfinx.fem.Constant``)
    so that a solver can change it (torques in time) without recompiling.
    """

    sigma: Any
    mu: Any
    beta: Any
    nu: Any
    delta: Any
    v_w0: Any
    m0: Any = 0.0  # torque at s = 0, Eq. (38)
    mN: Any = 0.0  # torque at s = 1, Eq. (39)
    gravity: Any = 1.0  # 1 switches gravity on, 0 off
    drag: Any = 1.0
    bending: Any = 1.0
    gamma_eps: Any = 1.0e-3
    gamma_coupling: Any = 1.0  # 0 drops gamma (the paper's own code)
    shear: Any = 0.0  # GA / (M g), the shearable rod's (parameters/shear.py)
    rotary: Any = 0.0  # its sections' rotary inertia EI / (EA L0^2), 0: none
    # the kinematics, a component chosen by model.kinematics (:data:`KINEMATICS`)
    kinematics: Kinematics = field(default_factory=PaperKinematics)
    # structural damping, a component (forms/damping.py): KelvinVoigt, or the null
    # object NoneDamping that leaves the viscous terms out of the forms altogether
    damping: Damping = field(default_factory=NoneDamping)
    # the EI law, a component (forms/eilaw.py): TensionDependentBending, or the
    # null object ConstantBending (mu)
    bending_law: BendingLaw = field(default_factory=ConstantBending)
    # hysteretic torsion, a component (forms/hysteresis.py): BoucWen, or the null
    # object NoneHysteresis (no z field, the elastic moment)
    hysteresis: Hysteresis = field(default_factory=NoneHysteresis)
    # the section law, a component (forms/section_law.py, chosen by the registry
    # section_laws.py): NonlinearSection of its law, or the null object SolidSection
    section: SectionLaw = field(default_factory=section_law.SolidSection)
    # the spinning tethers' torque loss, a component (forms/spin_drag.py): SpinDrag, or
    # the null object NoSpinDrag
    spin_drag: SpinDragLaw = field(default_factory=NoSpinDrag)
    # the wind's profile in the drag, a component (forms/wind.py): ProfileWind, or the
    # null object UniformWind (the paper's v_w0 at every height)
    wind: WindProfile = field(default_factory=wind_profile.UniformWind)
    # the ENERGY_COMPONENTS of the scene
    extra: tuple = ()

    @classmethod
    def from_normalised(cls, q, model, make=float):
        """From :class:`rawehelix.parameters.Normalised` and a scene's
        ``model``; ``make`` wraps each number (e.g. into a dolfinx Constant)."""
        return cls(
            sigma=make(q.sigma), mu=make(q.mu), beta=make(q.beta), nu=make(q.nu),
            delta=make(q.delta), v_w0=make(q.v_w0), m0=make(0.0), mN=make(0.0),
            gravity=make(q.gravity), drag=make(q.drag), bending=make(q.bending),
            gamma_eps=make(model.gamma_eps),
            gamma_coupling=make(1.0 if model.gamma == "regularised" else 0.0),
            shear=make(q.shear_stiffness), rotary=make(q.rotary_inertia),
            kinematics=KINEMATICS[model.kinematics](),  # kinematics by name: the UFL half
            **{name: build(q, make) for name, build in COMPONENTS.items()},
            extra=tuple(cls.from_normalised(q, make) for cls in ENERGY_COMPONENTS),
        )
