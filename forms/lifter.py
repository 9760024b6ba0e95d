"""The lifted top end (``[lifter] top = "lifted"``): the top's position r(1) is an
unknown, held by forces instead of by Eq. (36).

The top is a point mass (rotor plus hub) under its weight, the rotor's thrust and
the lifter's force; their sum F (normalised by M g, Eq. 29) is constant in the
stationary state, so it has the potential

    V_top(r) = -F . r(1),

and its variation -F . v(1) is the natural end term of Eq. (30) that replaces the
position of Eq. (36): with v free at s = 1 the weak form gives the end balance
n(1) = F (n the internal force of Eq. 32 with the bending's shear).

The rotor's thrust along its axis "tangent" turns with the end: a follower force
F_t t(1), t = r'/|r'|, which has no potential; its end term -F_t t(1) . v(1) is
written directly (:func:`follower_residual`), and Newton's Jacobian takes its
derivative with the rest.  No solver code.
"""

from __future__ import annotations

import ufl

from rawehelix.forms.extensible import variation
from rawehelix.forms.kinematics import d, stretch


def end_potential(F, r, ds):
    """-F . r(1) [M g L0]: ``ds`` the end measure; x = 1 picks the top end."""
    x = ufl.SpatialCoordinate(ds.ufl_domain())
    return -ufl.dot(F, r) * x[0] * ds


def end_residual(F, r, v, ds):
    """delta V_top(r; v) = -F . v(1), the natural term of the lifted top."""
    return variation(lambda y: end_potential(F, y, ds), r, v, ds.ufl_domain())


def follower_residual(F_t, r, v, ds):
    """-F_t t(1) . v(1), t = r'/|r'| at the top: a force of size ``F_t`` [M g] along
    the end tangent (not a variation: a follower load)."""
    x = ufl.SpatialCoordinate(ds.ufl_domain())
    return -F_t * ufl.dot(d(r) / stretch(r), v) * x[0] * ds


def top_kinetic(m, r_t, ds):
    """1/2 m |r_t(1)|^2 [M g L0]: the top mass's kinetic energy (``m`` by M, the rod's
    mass, as the rod's 1/2 int |r_t|^2 of forms/energy.py)."""
    x = ufl.SpatialCoordinate(ds.ufl_domain())
    return 0.5 * m * ufl.dot(r_t, r_t) * x[0] * ds


def top_inertia_residual(m, r_tt, v, ds):
    """m r_tt(1) . v(1): d/dt of the kinetic energy's derivative by r_t(1) (Lagrange),
    its variation at the rate r_tt: the top's lumped mass in the residual."""
    return variation(lambda y: top_kinetic(m, y, ds), r_tt, v, ds.ufl_domain())


def thrust_power(F_t, r, r_t, ds):
    """F_t t(1) . r_t(1) [M g L0 / t_scale]: the follower thrust's power on the top."""
    x = ufl.SpatialCoordinate(ds.ufl_domain())
    return F_t * ufl.dot(d(r) / stretch(r), r_t) * x[0] * ds
