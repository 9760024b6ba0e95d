"""The wind's profile in the helix's drag (Eq. 14), a component: the wind along -i_E
at each point's height (operation/wind.py has the same law in numpy).

The paper's frame has k_E downwards (gravity is +k_E, Eq. 30), so the height above the
ground end (r(0) = 0) is z~ = -r . k_E (normalised by L0).  :class:`UniformWind` is the
null object, the paper's v_w0 everywhere (the same UFL expression as before the
component: the paper's scenes compile the same forms); :class:`ProfileWind` is
v_w0 f(z~), f of "power" or "log" (:data:`FACTORS`), with the numpy law's floor.
"""

from __future__ import annotations

import math

import ufl


def _power(z, w):
    """(z / z_ref)^a, z at least the floor (operation/wind.py::FLOOR_M)."""
    return (ufl.max_value(z, w.floor) / w.reference) ** w.exponent


def _log(z, w):
    """ln(z / z0) / ln(z_ref / z0), z at least z0 (0 below it)."""
    return ufl.ln(ufl.max_value(z, w.roughness) / w.roughness) / math.log(w.reference / w.roughness)


#: the profiles' factors V(z) / V_ref by Normalised.wind_profile (the uniform one is the null object)
FACTORS = {"power": _power, "log": _log}


class UniformWind:
    """The paper's wind: v_w0 at every height (the null object)."""

    def speed(self, r, c):
        """The wind's speed (normalised) at the centre line r: v_w0."""
        return c.v_w0


class ProfileWind:
    """v_w0 f(z~) (module docstring); the heights over L0 as Normalised has them."""

    def __init__(self, profile: str, exponent: float, reference: float, roughness: float,
                 floor: float):
        self.factor = FACTORS[profile]
        self.exponent, self.reference, self.roughness, self.floor = (exponent, reference,
                                                                     roughness, floor)

    def speed(self, r, c):
        """The wind's speed (normalised) at the centre line r: v_w0 f(-r . k_E)."""
        return c.v_w0 * self.factor(-r[2], self)


def from_normalised(q, make=float):
    """The scene's wind: the null object for the uniform one (parameters/wind.py)."""
    if q.wind_profile not in FACTORS:
        return UniformWind()
    return ProfileWind(q.wind_profile, q.wind_exponent, q.wind_reference, q.wind_roughness,
                       q.wind_floor)
