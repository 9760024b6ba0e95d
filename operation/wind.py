"""The wind's speed with height (issue 43): V(z) along -i_E (Eq. 14's direction).

* ``"uniform"``: V(z) = V_ref, the paper's wind (Eq. 14, environment.wind_speed_m_s);
* ``"power"``: V(z) = V_ref (z / z_ref)^a, a the shear exponent;
* ``"log"``: V(z) = V_ref ln(z / z0) / ln(z_ref / z0), z0 the roughness length.

z [m] is the height above the helix's ground end.  Both laws are singular at the
ground (V' infinite at z = 0, ln(z/z0) -> -inf): below :data:`FLOOR_M` (power) or z0
(log) they take the speed there, so V(z) >= 0 everywhere and its derivative is finite
(forms/wind.py writes the same law in UFL).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

FLOOR_M = 1.0e-2  # [m] the power law's lowest height: V(z < 1 cm) = V(1 cm)


def _uniform(z, w):
    return np.ones_like(z)


def _power(z, w):
    """(z / z_ref)^a, z at least :data:`FLOOR_M`."""
    return (np.maximum(z, FLOOR_M) / w.reference_height_m) ** w.shear_exponent


def _log(z, w):
    """ln(z / z0) / ln(z_ref / z0), z at least z0."""
    z0 = w.roughness_m
    return np.log(np.maximum(z, z0) / z0) / math.log(w.reference_height_m / z0)


UNIFORM = "uniform"  # the paper's profile: V_ref at every height
#: the profiles' factors V(z) / V_ref by name (forms/wind.py has the same in UFL)
FACTORS = {UNIFORM: _uniform, "power": _power, "log": _log}
PROFILES = tuple(FACTORS)


@dataclass(frozen=True)
class WindProfile:
    """V(z) of one of :data:`PROFILES` (module docstring); SI units."""

    speed_m_s: float  # V_ref, at the reference height [m/s]
    reference_height_m: float = 10.0  # z_ref [m]
    profile: str = "uniform"
    shear_exponent: float = 1.0 / 7.0  # a, "power" [-]
    roughness_m: float = 0.03  # z0, "log" [m]
    hub_height_m: float = 0.0  # the rotor hub's height z [m] (the top end's)

    def __post_init__(self):
        if self.profile not in PROFILES:
            raise ValueError(f"wind profile {self.profile!r} must be one of {PROFILES}")

    def factor(self, z_m):
        """V(z) / V_ref [-]."""
        return FACTORS[self.profile](np.asarray(z_m, float), self)

    def speed_at(self, z_m):
        """V(z) [m/s]."""
        return self.speed_m_s * self.factor(z_m)

    @property
    def hub_speed(self) -> float:
        """V at the rotor's hub (:attr:`hub_height_m`) [m/s]."""
        return float(self.speed_at(self.hub_height_m))

    def at_reference(self, speed_m_s: float) -> "WindProfile":
        """The same profile at another reference speed (a wind sweep)."""
        return WindProfile(speed_m_s, self.reference_height_m, self.profile,
                           self.shear_exponent, self.roughness_m, self.hub_height_m)


def top_height_m(params) -> float:
    """The top end's height above the ground end [m]: the chord (1 + eps0) L0 at the
    elevation Gamma0 (Eq. 66; eps0 = 0 until a tension_N scene's is found)."""
    eps0 = params.ends.elongation or 0.0
    return (1 + eps0) * params.helix.length_m * math.sin(math.radians(params.ends.elevation_deg))


def from_params(params) -> WindProfile:
    """The scene's wind: its ``[wind]`` section, else environment.wind_speed_m_s
    uniform (the paper's); the hub at the top end's height."""
    w = params.wind
    if not w.active:
        return WindProfile(params.environment.wind_speed_m_s, hub_height_m=top_height_m(params))
    return WindProfile(w.speed_m_s, w.reference_height_m, w.profile, w.shear_exponent,
                       w.roughness_m, hub_height_m=top_height_m(params))


def reference_speed(params) -> float:
    """V_ref [m/s]: wind.speed_m_s if the scene gives it, else environment.wind_speed_m_s."""
    given = params.wind.speed_m_s
    return params.environment.wind_speed_m_s if given is None else given


def air_density(params) -> float:
    """rho [kg/m^3]: wind.air_density_kg_m3 if the scene gives it, else the environment's."""
    w = params.wind
    given = w.air_density_kg_m3
    return params.environment.air_density_kg_m3 if given is None else given
