"""The shearable (Simo-Reissner) rod (r, alpha, n), forms/shearable.py, as a
:class:`~rawehelix.models.base.RodModel`.

Fields, in the order of the mixed space (compat.shearable_element): ``centre_line``
r (vector P_p), ``twist`` alpha (scalar P_p) and ``director`` n (vector P_(p-1)),
the section's normal d3 = n / |n|.  Loads carry over from the paper's rod as they
act on the same fields: gravity and drag (Eq. 28) on r, the end torques (38)-(39)
and the controller (40) on alpha at the ends (the end section's spin), the moving
end (36), (70) on r(1); the zero-moment ends (37) are natural conditions on n.
"""

from __future__ import annotations

import ufl

from rawehelix import compat
from rawehelix.forms import rod, shearable
from rawehelix.forms.kinematics import d
from rawehelix.models.base import EndCondition, Refusal, RodModel
from rawehelix.parameters import Parameters

#: the first-order TS types are set up for (r, alpha) and its rates only
FIRST_ORDER = Refusal(
    "model.kinematics",
    "'shearable' runs with the second-order integrator only (-rawehelix_ts_type alpha2, "
    "the default): the first-order TS types are set up for (r, alpha)")


class ShearableRod(RodModel):
    """The (r, alpha, n) rod of a scene (``model.kinematics = "shearable"``)."""

    fields = ("centre_line", "twist", "director")

    def __init__(self, params: Parameters):
        self.params = params
        self.twist_field = params.model.twist  # false: alpha held at 0

    def element(self, cell, degree: int):
        return compat.shearable_element(cell, degree)

    # -- forms ---------------------------------------------------------------------
    def residual(self, w, w_t, w_tt, test, c, degree: int, penalty, measures):
        """delta U + inertia - gravity - drag (forms/shearable.py); ``w_tt`` None: no
        inertia, ``w_t`` None: at rest."""
        dx, _, ds = measures
        f, f_t, f_tt = self.split(w), self.rates(w_t), self.rates(w_tt)
        tests = tuple(ufl.split(test))
        r, alpha, n = f["centre_line"], f["twist"], f["director"]
        r_t = f_t["centre_line"] if w_t is not None else ufl.as_vector((0.0, 0.0, 0.0))
        F = (shearable.elastic_residual(r, alpha, n, tests, c, dx, ds)
             - ufl.inner(rod.body_force(r_t, c, r), tests[0]) * dx)
        if w_tt is not None:
            F += (ufl.inner(f_tt["centre_line"], tests[0]) + f_tt["twist"] * tests[1]) * dx
            F += shearable.rotary_inertia(f_tt["director"], tests[2], c, dx)
        return F

    def stored_energy(self, fields: dict, c, degree: int, penalty, measures):
        return shearable.stored_energy(fields["centre_line"], fields["twist"], fields["director"],
                                       c, measures[0])

    def kinetic_energy(self, rates: dict, c, dx):
        return shearable.kinetic_density(rates["centre_line"], rates["twist"], rates["director"],
                                         c) * dx

    def dissipation(self, fields: dict, rates: dict, c, degree: int, penalty, measures):
        return None

    def non_variational_power(self, fields: dict, rates: dict, c, dx):
        return shearable.non_variational_power(fields["twist"], fields["director"],
                                               rates["director"], c, dx)

    # -- observables ---------------------------------------------------------------
    def strain(self, fields: dict, c):
        """Gamma_3 = r'.d3 - 1."""
        return shearable.stretch_strain(fields["centre_line"], fields["director"])

    def tension(self, fields: dict, c):
        """N = sigma Gamma_3, the axial force along d3 (Eq. 29 with the stretch r'.d3 - 1);
        with a member section law N = dW/d Gamma_3 of the members (at zero shear)."""
        eps, kappa = shearable.section_strains(fields["centre_line"], fields["director"], c)
        return c.section.axial_force_at(eps, kappa, c)

    def twist(self, fields: dict, c):
        """K_3 = alpha'."""
        return d(fields["twist"])

    def curvature(self, fields: dict, c):
        """|d3'|, per unstretched length."""
        k = shearable.bending_strain(fields["director"])
        return ufl.sqrt(ufl.dot(k, k))

    def bending_moment(self, fields: dict, c):
        """mu |d3'|, or the members' M = dW/d kappa."""
        eps, kappa = shearable.section_strains(fields["centre_line"], fields["director"], c)
        return c.section.bending_moment_at(
            eps, kappa, c.kinematics.bending_modulus(fields["centre_line"], c),
            self.curvature(fields, c))

    def moment(self, fields: dict, c):
        """The torsional moment / GJ: K_3."""
        return self.twist(fields, c)

    def shear(self, fields: dict, c):
        """|Gamma_s|, the shear strain (the angle between d3 and r', to first order)."""
        g = shearable.shear_strain(fields["centre_line"], fields["director"])
        return ufl.sqrt(ufl.dot(g, g))

    # -- end conditions ---------------------------------------------------------------
    def end_conditions(self, pin_twist: bool) -> list[EndCondition]:
        """r(0) = 0 (35), r(1) = r_N (36); alpha(0) = 0 if ``pin_twist``; alpha = 0
        everywhere with model.twist = false; none on n (the zero-moment ends, 37)."""
        bcs = [EndCondition("centre_line", "bottom"), EndCondition("centre_line", "top", "top_position")]
        if pin_twist:
            bcs.append(EndCondition("twist", "bottom"))
        if not self.twist_field:
            bcs.append(EndCondition("twist", "all"))
        return bcs

    def refusals(self, solver: str) -> list[Refusal]:
        return [FIRST_ORDER] if solver == "first_order" else []
