"""The scene's ``[spin_drag]`` section: the spinning helix's own aerodynamic torque loss
(issue 43; forms/spin_drag.py).

Each of the section's n tethers (``section.tethers``) sits at the radius R
(``section.radius_m``, or ``helix.radius_m``) and moves through still air at Omega R
as the helix spins.  On a tether laid at the angle beta to the axis
(``section.lay_angle_deg``) the velocity normal to it is Omega R cos beta, and a
unit of axial length holds 1 / cos beta of tether; the drag per tether length is
1/2 rho C_d d |v_n| v_n (a cylinder in cross-flow, the law of KiteTurbineDynamics.jl's
tether drag), at the lever arm R.  So the distributed torque per axial length is

    q(Omega) = -c Omega |Omega|,   c = n (1/2) rho C_d d R^3 cos beta   [N m s^2 / m],

with rho the air's density (``wind.air_density_kg_m3``, or
``environment.air_density_kg_m3``).  The wind's own component across the
tethers is left out (it adds on one side of the ring what it takes on the other).
``tether_diameter_m = 0`` (the default) is off.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from rawehelix.parameters.checks import ParameterError, _non_negative


@dataclass(frozen=True)
class SpinDrag:
    """The spinning tethers' aerodynamic torque loss, a distributed torque
    -c Omega |Omega| per length (module docstring).  A scene's ``[spin_drag]``
    section; ``tether_diameter_m = 0`` (the default) is off."""

    tether_diameter_m: float = 0.0  # d, one tether's diameter; 0: off [m]
    drag_coefficient: float = 1.0  # C_d, a tether's drag coefficient in cross-flow [-]

    def __post_init__(self):
        _non_negative("spin_drag", self, "tether_diameter_m", "drag_coefficient")
        for name in ("tether_diameter_m", "drag_coefficient"):
            if not math.isfinite(getattr(self, name)):
                raise ParameterError(f"spin_drag.{name}", getattr(self, name), "must be finite")

    @property
    def active(self) -> bool:
        return self.tether_diameter_m > 0 and self.drag_coefficient > 0

    def describe(self) -> str:
        return (f"spin drag: tethers of d = {self.tether_diameter_m:g} m, "
                f"C_d = {self.drag_coefficient:g}: torque -c Omega|Omega| per length")


def coefficient(p) -> float:
    """c = n (1/2) rho C_d d R^3 cos beta [N m s^2 per m of helix] of a scene (0: off)."""
    drag, section = p.model.spin_drag, p.model.section
    if not drag.active:
        return 0.0
    R = section.radius_m or p.helix.radius_m
    rho = p.wind.air_density_kg_m3  # [wind]'s density where given (parameters/wind.py)
    rho = p.environment.air_density_kg_m3 if rho is None else rho
    return (section.tethers * 0.5 * rho * drag.drag_coefficient
            * drag.tether_diameter_m * R**3 * math.cos(math.radians(section.lay_angle_deg)))


@dataclass(frozen=True)
class Loss:
    """The spin drag's total torque on a helix spinning uniformly, the ``loss`` that
    operation/rigid_shaft.py's ``operating_points`` reads: c L0 Omega |Omega| [N m]."""

    c_total: float  # c L0 [N m s^2]

    def torque(self, omega):
        """int_0^L0 c Omega |Omega| ds = c L0 Omega |Omega| [N m] (``omega`` [rad/s])."""
        import numpy as np
        omega = np.asarray(omega, dtype=float)
        return self.c_total * omega * np.abs(omega)

    def dtorque_domega(self, omega):
        """2 c L0 |Omega| [N m s]."""
        import numpy as np
        return 2.0 * self.c_total * np.abs(np.asarray(omega, dtype=float))


def loss_of(params) -> Loss | None:
    """The spin drag's :class:`Loss` of a scene, or None when it has none."""
    c = coefficient(params)
    return Loss(c * params.helix.length_m) if c > 0 else None


def loss_torque(omega, params):
    """The spin drag's total torque at a uniform spin ``omega`` [rad/s] (scalar or array):
    c L0 Omega |Omega| [N m], the loss between the rotor's torque and the ground's at an
    operating point (0: off)."""
    return Loss(coefficient(params) * params.helix.length_m).torque(omega)


#: its normalised group (parameters/scene.py::GROUP_KEYS): q~ = q L0^2 / GJ and
#: Omega~ = Omega t_scale, so c~ = c L0^2 / (GJ t_scale^2) = c g L0 / GJ
GROUP_KEYS = {
    "spin_drag": ("c g L0/GJ", "Eq. 31",
                  ("spin_drag.tether_diameter_m", "spin_drag.drag_coefficient",
                   "environment.air_density_kg_m3"),
                  ("helix.GJ_Nm2", "helix.length_m", "environment.g_m_s2", "helix.radius_m")),
}

#: where the section lives in a scene: Parameters.model.spin_drag (the file's [spin_drag])
HOLDER, KEY, SECTION = "model", "spin_drag", SpinDrag

#: its field of Normalised, off: c~ of :data:`GROUP_KEYS` (forms/spin_drag.py)
NORMALISED = {"spin_drag": 0.0}


def normalise(p, scales: dict) -> dict:
    """c~ = c g L0 / GJ (the twist equation (31) in the units of forms/twist.py)."""
    return {"spin_drag": coefficient(p) * scales["g"] * scales["L0"] / p.helix.GJ_Nm2}


def check(params) -> None:
    """What the spin drag cannot run with: the spline scheme, model.twist = false (it is
    a torque in the twist equation, forms/spin_drag.py) and the shearable rod."""
    section = params.model.spin_drag
    if section.active and params.model.kinematics == "shearable":
        raise ParameterError("spin_drag.tether_diameter_m", section.tether_diameter_m,
                             "the spin drag is written on the unshearable rod's twist "
                             "equation: not with model.kinematics = 'shearable'")
    if section.active and (params.discretisation.scheme != "fe" or not params.model.twist):
        raise ParameterError("spin_drag.tether_diameter_m", section.tether_diameter_m,
                             "the spin drag is a torque in the twist equation (31): it needs "
                             "discretisation.scheme = 'fe' and model.twist = true")
