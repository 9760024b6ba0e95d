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

from rawehelix.forms.kinematics import I_E


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

    def air(self, r, c):
        """-v_w, the air's velocity relative to the ground reversed (Eq. 14's v_A = r_t
        - v_w): v_w0 i_E."""
        return self.speed(r, c) * I_E

    def factor(self, r):
        """f(z~) = V(z) / V_ref: 1."""
        return 1.0


class ProfileWind:
    """v_w0 f(z~) (module docstring); the heights over L0 as Normalised has them."""

    def __init__(self, profile: str, exponent: float, reference: float, roughness: float,
                 floor: float):
        self.law = FACTORS[profile]
        self.exponent, self.reference, self.roughness, self.floor = (exponent, reference,
                                                                     roughness, floor)

    def speed(self, r, c):
        """The wind's speed (normalised) at the centre line r: v_w0 f(-r . k_E)."""
        return c.v_w0 * self.factor(r)

    def air(self, r, c):
        """-v_w = v_w0 f(z~) i_E (Eq. 14's v_A = r_t - v_w)."""
        return self.speed(r, c) * I_E

    def factor(self, r):
        """f(z~) at the centre line r (z~ = -r . k_E)."""
        if r is None:  # a caller of forms/rod.py's drag that gave no centre line
            raise ValueError("a wind profile's drag needs the centre line r (its height): "
                             "pass r to forms/rod.py's aerodynamic_force and body_force")
        return self.law(-r[2], self)


def piecewise_linear(x, xs, ys):
    """The UFL interpolant of the values ``ys`` (UFL scalars) at the increasing
    ``xs`` (numbers), linear between, held below the first and above the last
    (numpy's ``interp``)."""
    out = ys[-1]
    for i in reversed(range(len(xs) - 1)):
        slope = (ys[i + 1] - ys[i]) / (xs[i + 1] - xs[i])
        out = ufl.conditional(ufl.lt(x, xs[i + 1]), ys[i] + slope * (x - xs[i]), out)
    return ufl.conditional(ufl.lt(x, xs[0]), ys[0], out) if len(xs) > 1 else out


class MovingWind:
    """The wind in time (issue 44, operation/wind_series.py), normalised by sqrt(g L0):
    along -i_E u = V_ref(t) f(z~) + G(t) + u'(z~, t), lateral v'(z~, t) along +j_E,
    vertical w'(z~, t) along -k_E (up); f the scene's profile (``steady``: the
    UniformWind or ProfileWind of the scene), u', v', w' linear in height between the
    history's ``heights`` (over L0).  ``reference``, ``gust`` (scalars) and
    ``fluctuation`` (heights x 3) are Constants a solver sets each time (solvers/weather.py)."""

    def __init__(self, steady, heights, reference, gust, fluctuation):
        self.steady, self.heights = steady, tuple(float(h) for h in heights)
        self.reference, self.gust, self.fluctuation = reference, gust, fluctuation

    def _fluctuation(self, r, k):
        z = -r[2]
        return piecewise_linear(z, self.heights,
                                [self.fluctuation[i, k] for i in range(len(self.heights))])

    def speed(self, r, c):
        """u (normalised) at the centre line r."""
        return self.reference * self.steady.factor(r) + self.gust + self._fluctuation(r, 0)

    def air(self, r, c):
        """-v_w = u i_E - v' j_E + w' k_E (Eq. 14's v_A = r_t - v_w)."""
        return ufl.as_vector((self.speed(r, c), -self._fluctuation(r, 1), self._fluctuation(r, 2)))


def from_normalised(q, make=float):
    """The scene's wind: the null object for the uniform one (parameters/wind.py)."""
    if q.wind_profile not in FACTORS:
        return UniformWind()
    return ProfileWind(q.wind_profile, q.wind_exponent, q.wind_reference, q.wind_roughness,
                       q.wind_floor)
