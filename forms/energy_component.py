"""Energy components: physics that adds a stored energy W(r) per length and nothing else.

Their residual is the variation delta W(r; v) (taken by UFL,
forms/extensible.py::variation), so residual, Jacobian and energy agree by
construction; forms/rod.py adds :meth:`EnergyComponent.residual` and
forms/energy.py :meth:`EnergyComponent.energy` of each of ``c.extra``
(forms/coefficients.py::ENERGY_COMPONENTS).  :class:`NoEnergy` is the null
object of a component switched off.
"""

from __future__ import annotations

from rawehelix.forms.extensible import variation


class EnergyComponent:
    """A stored energy W(r) per length (:meth:`energy`, a form) and its variation."""

    def energy(self, r, c, dx):
        raise NotImplementedError

    def residual(self, r, v, c, dx):
        """delta W(r; v)."""
        return variation(lambda x: self.energy(x, c, dx), r, v, dx.ufl_domain())


class NoEnergy:
    """A component switched off: no energy, no force."""

    def energy(self, r, c, dx):
        return 0

    def residual(self, r, v, c, dx):
        return 0
