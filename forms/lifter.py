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
