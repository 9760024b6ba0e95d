"""The twist equation (31) with its end torques (38)-(39), in pure UFL: the one weak
form of the spin that the unshearable rod (forms/rod.py) and the shearable rod
(forms/shearable.py) share.

    delta int M psi' ds - delta [M psi]_0^1,   M(0) = m0, M(1) = mN,

the twisting moment M / GJ (tau, the members' Q / GJ or the hysteresis's moment)
times delta, so that with the inertia int alpha_tt psi it is Eq. (31) scaled by
delta / beta (forms/energy.py)."""

from __future__ import annotations

import ufl

from rawehelix.forms.kinematics import d


def twist_equation(moment, psi, c, dx, ds):
    """delta int moment psi' - delta (mN psi(1) - m0 psi(0)): x = 0 or 1 on the ends."""
    x = ufl.SpatialCoordinate(ds.ufl_domain())
    return (c.delta * moment * d(psi) * dx  # (31)
            - c.delta * (c.mN * x[0] - c.m0 * (1 - x[0])) * psi * ds)  # (38)-(39)
