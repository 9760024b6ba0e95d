"""The spinning helix's own aerodynamic torque loss (``[spin_drag]``,
parameters/spin_drag.py), a component: a distributed torque q = -c Omega |Omega| per
length in the twist equation (31), Omega = alpha_t the sections' spin.

It comes from the dissipation potential per length

    D(alpha_t) = c~ |alpha_t|^3 / 3,   dD/d alpha_t = c~ alpha_t |alpha_t|,

(normalised: c~ = c g L0 / GJ, parameters/spin_drag.py), whose derivative in the
direction psi, scaled by delta like the elastic twist row (forms/twist.py), is the
residual term delta int c~ alpha_t |alpha_t| psi ds: Eq. (31) gains the torque
-c Omega |Omega| per length.  Its power alpha_t dD/d alpha_t = 3 D.  In a relative
equilibrium (the operating point, alpha_t = Omega uniform) the solver passes Omega
as a constant: the torque falls linearly along s.  |alpha_t| is smoothed by 1e-14
under the root, as the drag of Eq. (14) (forms/rod.py), so that its derivative exists.
:class:`NoSpinDrag` is the null object.
"""

from __future__ import annotations

import ufl

from rawehelix.forms.extensible import variation


def _magnitude(a):
    return ufl.sqrt(a * a + 1e-14)


class SpinDrag:
    """The torque loss -c~ alpha_t |alpha_t| per length (module docstring)."""

    fields = ()
    refuses = {}

    def __init__(self, c):
        self.c = c  # c~, normalised (a number or a constant)

    @classmethod
    def from_normalised(cls, q, make=float):
        """From :class:`rawehelix.parameters.Normalised`; the null object when c~ = 0."""
        return cls(make(q.spin_drag)) if q.spin_drag > 0 else NoSpinDrag()

    def dissipation(self, alpha_t, dx):
        """D = int c~ |alpha_t|^3 / 3 ds [M g L0 / t_scale]."""
        return self.c * _magnitude(alpha_t) ** 3 / 3 * dx

    def residual(self, alpha_t, psi, c, dx):
        """delta dD/d alpha_t [psi] = delta int c~ alpha_t |alpha_t| psi (Eq. 31), the
        variation of :meth:`dissipation` (UFL's derivative)."""
        return c.delta * variation(lambda a: self.dissipation(a, dx), alpha_t, psi,
                                   dx.ufl_domain())


class NoSpinDrag:
    """The spin drag switched off: no torque."""

    fields = ()
    refuses = {}

    def dissipation(self, alpha_t, dx):
        return None

    def residual(self, alpha_t, psi, c, dx):
        return 0
