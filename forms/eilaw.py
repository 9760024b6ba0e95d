"""The EI law (``helix.EI_law``), a component: tension-dependent bending, EI = a T + b (Eq. 64).

Normalised (parameters/eilaw.py: mu_a = a / L0^2, mu_b = b / (M g L0^2)) the
bending modulus of the extensible rod's stored energy is a field of the strain,
mu(eps) = mu_a sigma eps + mu_b (forms/extensible.py, where the consistent
axial term follows by the variation).  :class:`ConstantBending` is its null
object, the constant mu of Eq. (26).  Both answer :meth:`modulus` (times the
bending switch) and ``field`` (is the modulus a field, to be taken at the
nodes as {{mu t'}} and {{mu}}).
"""

from __future__ import annotations

from rawehelix.forms.kinematics import stretch


class TensionDependentBending:
    """mu(eps) = mu_a sigma eps + mu_b; ``mu_a``, ``mu_b`` numbers or constants."""

    field = True

    def __init__(self, mu_a, mu_b):
        self.mu_a, self.mu_b = mu_a, mu_b

    @classmethod
    def from_normalised(cls, q, make=float):
        """From :class:`rawehelix.parameters.Normalised`; the null object without a law."""
        if not q.bending_law:
            return ConstantBending()
        return cls(make(q.mu_per_tension), make(q.mu_at_zero_tension))

    def modulus(self, r, c):
        """The bending switch times mu(eps), eps = |r'| - 1 (Eq. 29)."""
        return c.bending * (self.mu_a * c.sigma * (stretch(r) - 1) + self.mu_b)

    def __bool__(self):  # the old truth test 'if c.bending_law' (studies/labtest.py)
        return True


class ConstantBending:
    """No EI law: the constant mu of Eq. (26)."""

    field = False

    def modulus(self, r, c):
        return c.bending * c.mu

    def __bool__(self):
        return False
