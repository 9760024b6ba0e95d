"""The lifted top end (``[lifter] top = "lifted"``): the top's position r(1) is an
unknown, held by forces instead of by Eq. (36).

The top is a point mass (rotor plus hub) under its weight, the rotor's thrust and
the lifter's force; their sum F (normalised by M g, Eq. 29) is constant in the
stationary state, so it has the potential

    V_top(r) = -F . r(1),

and its variation -F . v(1) is the natural end term of Eq. (30) that replaces the
position of Eq. (36): with v free at s = 1 the weak form gives the end balance
n(1) = F (n the internal force of Eq. 32 with the bending's shear).  No solver code.
"""

from __future__ import annotations

import ufl

from rawehelix.forms.extensible import variation


def end_potential(F, r, ds):
    """-F . r(1) [M g L0]: ``ds`` the end measure; x = 1 picks the top end."""
    x = ufl.SpatialCoordinate(ds.ufl_domain())
    return -ufl.dot(F, r) * x[0] * ds


def end_residual(F, r, v, ds):
    """delta V_top(r; v) = -F . v(1), the natural term of the lifted top."""
    return variation(lambda y: end_potential(F, y, ds), r, v, ds.ufl_domain())
