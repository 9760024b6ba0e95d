"""The normalised groups of Eqs. (26)-(27) as the forms read them (:class:`Coefficients`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from rawehelix.forms.damping import KelvinVoigt, NoneDamping
from rawehelix.forms.hysteresis import BoucWen, NoneHysteresis


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
    kinematics: str = "paper"  # model.kinematics: "extensible" is forms/extensible.py
    # structural damping, a component (forms/damping.py): KelvinVoigt, or the null
    # object NoneDamping that leaves the viscous terms out of the forms altogether
    damping: Any = field(default_factory=NoneDamping)
    # the EI law (helix.EI_law, forms/extensible.py::bending_modulus): mu(eps) =
    # mu_a sigma eps + mu_b; ``bending_law`` False: mu
    mu_a: Any = 0.0
    mu_b: Any = 0.0
    bending_law: bool = False
    # hysteretic torsion, a component (forms/hysteresis.py): BoucWen, or the null
    # object NoneHysteresis (no z field, the elastic moment)
    hysteresis: Any = field(default_factory=NoneHysteresis)

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
            kinematics=model.kinematics,
            damping=KelvinVoigt.from_normalised(q, make),
            mu_a=make(q.mu_per_tension), mu_b=make(q.mu_at_zero_tension),
            bending_law=q.bending_law,
            hysteresis=BoucWen.from_normalised(q, make),
        )
