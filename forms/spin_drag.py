"""The spinning helix's own aerodynamic torque loss (``[spin_drag]``,
parameters/spin_drag.py), a component: a distributed torque q = -c Omega |Omega| per
length in the twist equation (31), Omega = alpha_t the sections' spin.

It comes from the dissipation potential per length, in the energy units of
forms/energy.py (M g L0 per t_scale, the twist weighted by beta),

    D(alpha_t) = beta c~ |alpha_t|^3 / 3,   dD/d alpha_t = beta c~ alpha_t |alpha_t|,

(c~ = c g L0 / GJ, parameters/spin_drag.py).  The twist row of the residual is the
energy's scaled by delta / beta (forms/energy.py), so the term is
(delta / beta) int dD/d alpha_t psi ds = delta int c~ alpha_t |alpha_t| psi ds:
Eq. (31) gains the torque -c Omega |Omega| per length.  Its power
alpha_t dD/d alpha_t = 3 D (:meth:`SpinDrag.power`).  In a relative equilibrium (the
operating point, alpha_t = Omega uniform) the solver passes Omega as a constant: the
torque falls linearly along s.  |alpha_t| is smoothed by 1e-14 under the root, as
the drag of Eq. (14) (forms/rod.py), so that its derivative exists.
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

    def dissipation(self, alpha_t, c, dx):
        """D = int beta c~ |alpha_t|^3 / 3 ds [M g L0 / t_scale]."""
        return c.beta * self.c * _magnitude(alpha_t) ** 3 / 3 * dx

    def power(self, alpha_t, c, dx):
        """The power it takes, int alpha_t dD/d alpha_t (= 3 D) [M g L0 / t_scale]."""
        return c.beta * self.c * _magnitude(alpha_t) * alpha_t * alpha_t * dx

    def residual(self, alpha_t, psi, c, dx):
        """(delta / beta) dD/d alpha_t [psi] = delta int c~ alpha_t |alpha_t| psi
        (Eq. 31), the variation of :meth:`dissipation` (UFL's derivative)."""
        return c.delta / c.beta * variation(lambda a: self.dissipation(a, c, dx), alpha_t, psi,
                                            dx.ufl_domain())


class NoSpinDrag:
    """The spin drag switched off: no torque."""

    fields = ()
    refuses = {}

    def dissipation(self, alpha_t, c, dx):
        return None

    def power(self, alpha_t, c, dx):
        return None

    def residual(self, alpha_t, psi, c, dx):
        return 0
