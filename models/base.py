"""The rod-model interface: the fields of a rod, their layout, its forms and what it refuses.

A solver asks the model instead of naming r, alpha, kappa or z:

* the fields, by role (:data:`ROLES`), in the order of the mixed space:
  :meth:`RodModel.index`, :meth:`RodModel.has`, :meth:`RodModel.split`;
* the element of the mixed space, :meth:`RodModel.element`;
* the forms: the residual (inertia + elastic + dissipative - loads), the
  stored energy, the kinetic energy, the dissipation potential and the power
  of the non-variational terms;
* the observables: tension, twist, curvature and the moments;
* the first-order form (r, alpha and their rates as unknowns, :data:`PAIR_ROLES`):
  :meth:`RodModel.pair_element`, :meth:`RodModel.residual_of_fields`, which a model
  without one leaves to raise (its :meth:`RodModel.refusals` of "first_order" say why);
* the end conditions, :meth:`RodModel.end_conditions`;
* the capabilities: :meth:`RodModel.refuse` raises the one refusal of a
  component (or of the discretisation) for a solver that cannot run it.
"""

from __future__ import annotations

import abc
import dataclasses
from dataclasses import dataclass

import ufl

from rawehelix.errors import SceneError
from rawehelix.forms import kinematics
from rawehelix.forms.damping import NoneDamping

#: the roles of a rod's fields; the unshearable rod has the first two always,
#: "curvature" with the mixed bending form, "internal_twist" with hysteresis; the
#: shearable rod (models/shearable.py) the first two and "director"
ROLES = ("centre_line", "twist", "curvature", "internal_twist", "director")

#: the fields of the first-order form (with their rates, :meth:`RodModel.pair_element`):
#: no curvature, no z
PAIR_ROLES = ("centre_line", "twist")

#: the solvers a model is asked about (:meth:`RodModel.refuse`)
SOLVERS = ("stationary", "second_order", "first_order", "modal")


@dataclass(frozen=True)
class EndCondition:
    """A Dirichlet condition: ``role``'s field at ``where`` ("bottom", "top",
    "ends" or "all" dofs) is ``value`` ("zero" or "top_position", Eq. 36)."""

    role: str
    where: str
    value: str = "zero"


@dataclass(frozen=True)
class Refusal:
    """A solver a component cannot run with: the scene key to name and the message."""

    key: str
    message: str


class RodModel(abc.ABC):
    """A rod model on a mixed space whose fields have the roles :attr:`fields`."""

    fields: tuple[str, ...] = ()

    def index(self, role: str) -> int:
        """The position of the field ``role`` in the mixed space."""
        return self.fields.index(role)

    def has(self, role: str) -> bool:
        return role in self.fields

    def split(self, w) -> dict:
        """role -> UFL view of a mixed function (or trial/test function) ``w``;
        the roles this model lacks are None."""
        parts = ufl.split(w)
        return {role: parts[self.index(role)] if self.has(role) else None for role in ROLES}

    def rates(self, w_t) -> dict:
        """:meth:`split` of a rate, or every role None when ``w_t`` is None."""
        return self.split(w_t) if w_t is not None else dict.fromkeys(ROLES)

    @abc.abstractmethod
    def element(self, cell, degree: int):
        """The mixed element of :attr:`fields`."""

    @abc.abstractmethod
    def residual(self, w, w_t, w_tt, test, c, degree: int, penalty, measures):
        """The full residual; ``w_tt`` None: no inertia, ``w_t`` None: at rest."""

    def conservative(self, c):
        """``c`` without the dissipative components: the residual of the stiffness."""
        return dataclasses.replace(c, damping=NoneDamping())

    # -- the first-order form: (r, alpha) and their rates as unknowns ------------------
    def pair_element(self, cell, degree: int):
        """The fields :data:`PAIR_ROLES` and their rates as one mixed element."""
        raise NotImplementedError(f"{type(self).__name__} has no first-order form "
                                  "(its refusals('first_order') say why)")

    def residual_of_fields(self, f: dict, f_t: dict, f_tt: dict, tests, c, degree: int, penalty,
                           measures):
        """:meth:`residual` on fields, rates and accelerations by role (the
        first-order form's live in its own space, :meth:`split_pair`); ``tests``
        the tuple of test functions in the order of the fields."""
        raise NotImplementedError(f"{type(self).__name__} has no first-order form "
                                  "(its refusals('first_order') say why)")

    def pair_index(self, role: str, rate: bool = False) -> int:
        """The position of ``role``'s field (or of its rate) in :meth:`pair_element`."""
        return PAIR_ROLES.index(role) + len(PAIR_ROLES) * rate

    def split_pair(self, x) -> tuple[dict, dict]:
        """(fields, rates) by role of a function (or test function) on :meth:`pair_element`."""
        parts = ufl.split(x)
        f, f_t = dict.fromkeys(ROLES), dict.fromkeys(ROLES)
        for role in PAIR_ROLES:
            f[role], f_t[role] = parts[self.pair_index(role)], parts[self.pair_index(role, True)]
        return f, f_t

    @abc.abstractmethod
    def stored_energy(self, fields: dict, c, degree: int, penalty, measures):
        """U of the fields (:meth:`split`)."""

    @abc.abstractmethod
    def kinetic_energy(self, rates: dict, c, dx):
        """K of the rates (:meth:`split` of w_t)."""

    @abc.abstractmethod
    def dissipation(self, fields: dict, rates: dict, c, degree: int, penalty, measures):
        """The dissipation potential D; None: the model dissipates nothing."""

    def dissipated_power(self, fields: dict, rates: dict, c, degree: int, penalty, measures):
        """The power the dissipative components take: 2 D of the structural damping
        (:meth:`dissipation`, quadratic in the rates) plus the spin drag's
        alpha_t dD/d alpha_t (forms/spin_drag.py, cubic); None: nothing dissipates."""
        D = self.dissipation(fields, rates, c, degree, penalty, measures)
        spin = (None if rates["twist"] is None
                else c.spin_drag.power(rates["twist"], c, measures[0]))
        parts = [P for P in (None if D is None else 2 * D, spin) if P is not None]
        return sum(parts[1:], parts[0]) if parts else None

    @abc.abstractmethod
    def non_variational_power(self, fields: dict, rates: dict, c, dx):
        """The power of the terms that are not the variation of an energy."""

    def strain(self, fields: dict, c):
        """The axial strain (an observable): eps = |r'| - 1 (Eq. 29)."""
        return kinematics.stretch(fields["centre_line"]) - 1

    @abc.abstractmethod
    def tension(self, fields: dict, c):
        """The tension field (an observable)."""

    @abc.abstractmethod
    def twist(self, fields: dict, c):
        """The total twist field (an observable)."""

    @abc.abstractmethod
    def curvature(self, fields: dict, c):
        """The bending curvature field |kappa| (an observable, 1/L0 units)."""

    @abc.abstractmethod
    def bending_moment(self, fields: dict, c):
        """The bending moment's magnitude (an observable, M g L0 units)."""

    @abc.abstractmethod
    def moment(self, fields: dict, c):
        """The torsional moment / GJ (an observable)."""

    def ring_phase(self, fields: dict, c):
        """The phase psi of the section's members against the bending plane (an
        observable, members.py): 0, a member on the plane, unless the model's section
        turns its ring."""
        return 0.0

    @abc.abstractmethod
    def end_conditions(self, pin_twist: bool) -> list[EndCondition]:
        """The Dirichlet conditions of the ends (and of fields held at zero)."""

    @abc.abstractmethod
    def refusals(self, solver: str) -> list[Refusal]:
        """Why ``solver`` (one of :data:`SOLVERS`) cannot run this model; [] if it can."""

    def refuse(self, solver: str, scene: str) -> None:
        """Raise the first refusal of ``solver`` as a :class:`SceneError` of ``scene``."""
        for refusal in self.refusals(solver):
            raise SceneError(scene, refusal.key, refusal.message)
