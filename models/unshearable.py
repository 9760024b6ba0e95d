"""The paper's unshearable rod (r, alpha), Eqs. (30)-(39), as a :class:`~rawehelix.models.base.RodModel`.

Fields, in the order of the mixed space (compat.rod_element):

* ``centre_line`` r (vector P_p) and ``twist`` alpha (scalar P_p), always;
* ``curvature`` kappa (vector P_p), with ``discretisation.bending = "mixed"``
  (forms/mixed.py, kappa = 0 at both ends, Eq. 37);
* ``internal_twist`` z (scalar DG_(p-1)), with ``[torsion_hysteresis]``
  (forms/hysteresis.py; no end condition).

Its forms are those of forms/rod.py and forms/energy.py: the elastic part is
the variation of the stored energy where the code takes it so (the extensible
kinematics, forms/extensible.py: ufl derivative of U; Kelvin-Voigt damping,
forms/damping.py: the derivative of D); the paper's kinematics keep their
hand-written F_NL (Eq. 32), whose -mu kappa^2 r' and twist coupling
beta tau (r' x r'') are the model's non-variational terms, with drag (Eq. 28)
and the end torques (Eqs. 38-39).
"""

from __future__ import annotations

import ufl

from rawehelix import compat
from rawehelix.forms import energy, kinematics, rod
from rawehelix.forms.damping import KelvinVoigt
from rawehelix.forms.hysteresis import BoucWen
from rawehelix.models.base import EndCondition, Refusal, RodModel
from rawehelix.parameters import Parameters

#: the first-order TS types are set up for (r, alpha) and its rates only
MIXED_FIRST_ORDER = Refusal(
    "discretisation.bending",
    "'mixed' runs with the second-order integrator "
    "only (-rawehelix_ts_type alpha2, the default): the first-order TS types "
    "are not set up for its algebraic curvature field")


class UnshearableRod(RodModel):
    """The (r, alpha) rod of a scene, with the fields its switches add."""

    def __init__(self, params: Parameters):
        self.params = params
        self.mixed = params.discretisation.bending == "mixed"  # kappa, forms/mixed.py
        self.twist_field = params.model.twist  # false: alpha held at 0
        q = params.normalised()
        # the components (a switched-off one is its null object): the fields they
        # add and what they refuse
        self.components = (KelvinVoigt.from_normalised(q), BoucWen.from_normalised(q))
        self.fields = (("centre_line", "twist") + ("curvature",) * self.mixed
                       + sum((comp.fields for comp in self.components), ()))
        self.hysteretic = self.has("internal_twist")  # z, forms/hysteresis.py

    def element(self, cell, degree: int):
        return compat.rod_element(cell, degree, curvature=self.mixed, internal=self.hysteretic)

    # -- forms ---------------------------------------------------------------------
    def residual(self, w, w_t, w_tt, test, c, degree: int, penalty, measures):
        """Eqs. (30)-(31) and the components' equations (forms/rod.py::residual_of_fields)
        on this model's fields; the curvature has no rate (its parts of w_t are unused)."""
        return self.residual_of_fields(self.split(w), self.rates(w_t), self.rates(w_tt),
                                       rod.test_fields(test), c, degree, penalty, measures)

    def residual_of_fields(self, f: dict, f_t: dict, f_tt: dict, tests, c, degree: int, penalty,
                           measures):
        return rod.residual_of_fields(
            f["centre_line"], f["twist"], f_t["centre_line"], f_tt["centre_line"], f_tt["twist"],
            tests, c, degree, penalty, measures, kappa=f["curvature"],
            alpha_t=f_t["twist"], z=f["internal_twist"], z_t=f_t["internal_twist"])

    # -- the first-order form: (r, alpha) and their rates as unknowns ------------------
    def pair_element(self, cell, degree: int):
        """The fields (r, alpha) and their rates as one mixed element (compat.rod_pair_element)."""
        return compat.rod_pair_element(cell, degree)

    def stored_energy(self, fields: dict, c, degree: int, penalty, measures):
        """U = elastic + gravity (forms/energy.py::potential)."""
        return energy.potential(fields["centre_line"], fields["twist"], c, degree, penalty,
                                measures, kappa=fields["curvature"])

    def kinetic_energy(self, rates: dict, c, dx):
        return energy.kinetic(rates["centre_line"], rates["twist"], c, dx)

    def dissipation(self, fields: dict, rates: dict, c, degree: int, penalty, measures):
        return c.damping.dissipation(fields["centre_line"], rates["centre_line"], rates["twist"],
                                     c, degree, penalty, measures)

    def non_variational_power(self, fields: dict, rates: dict, c, dx):
        return energy.non_variational_power(fields["centre_line"], fields["twist"],
                                            rates["centre_line"], c, dx,
                                            kappa=fields["curvature"])

    # -- observables ---------------------------------------------------------------
    def tension(self, fields: dict, c):
        """T = sigma (|r'| - 1), Eq. (29); with a member section law (forms/section_law.py)
        its axial force N = dW/d eps (a slack tether carries nothing; sigma eps would)."""
        return c.section.axial_force(fields["centre_line"], c, self.twist(fields, c), fields["twist"])

    def twist(self, fields: dict, c):
        """tau = gamma + alpha', Eq. (34)."""
        return kinematics.twist(fields["centre_line"], fields["twist"], c.gamma_eps,
                                c.gamma_coupling, k=fields["curvature"])

    def curvature(self, fields: dict, c):
        """The bending curvature |kappa| of the kinematics' bending measure: |r''| (the
        paper's, Eq. 34) or |t'| (the extensible kinematics, per unstretched length)."""
        k = c.kinematics.bending_curvature(fields["centre_line"], fields["curvature"])
        return ufl.sqrt(ufl.dot(k, k))

    def bending_moment(self, fields: dict, c):
        """|m| / (M g L0): the bending modulus (mu, or the EI law's) x :meth:`curvature`
        (Eq. 17: m = EI kappa b)."""
        return c.kinematics.bending_modulus(fields["centre_line"], c) * self.curvature(fields, c)

    def moment(self, fields: dict, c):
        """The torsional moment / GJ: tau, the members' Q / GJ (``[section] torsion =
        "members"``, forms/section_law.py) or the hysteresis component's
        rho tau + (1 - rho) z (forms/hysteresis.py)."""
        tau = self.twist(fields, c)
        z = fields["internal_twist"]
        if z is not None:
            return c.hysteresis.moment(tau, z)
        return c.section.twist_moment(fields["centre_line"], tau, c, fields["twist"])

    def ring_phase(self, fields: dict, c):
        """The section's ring phase psi against the bending plane (members.py; 0 unless
        ``[section] ring = "turning"``, forms/section_law.py)."""
        return c.section.ring_phase(fields["centre_line"], c, fields["twist"])

    # -- end conditions, Eqs. (35)-(37) ---------------------------------------------
    def end_conditions(self, pin_twist: bool) -> list[EndCondition]:
        """r(0) = 0 (35), r(1) = r_N (36); alpha(0) = 0 if ``pin_twist`` (the rigid
        rotation of torque-free ends); alpha = 0 everywhere with model.twist = false;
        kappa = 0 at both ends (37) with the mixed form."""
        bcs = [EndCondition("centre_line", "bottom"), EndCondition("centre_line", "top", "top_position")]
        if pin_twist:
            bcs.append(EndCondition("twist", "bottom"))
        if not self.twist_field:
            bcs.append(EndCondition("twist", "all"))
        if self.mixed:
            bcs.append(EndCondition("curvature", "ends"))
        return bcs

    # -- capabilities -----------------------------------------------------------------
    def refusals(self, solver: str) -> list[Refusal]:
        out = [Refusal(*comp.refuses[solver]) for comp in self.components
               if solver in comp.refuses]
        if solver == "first_order" and self.mixed:
            out.append(MIXED_FIRST_ORDER)
        return out
