"""Extensible kinematics (``model.kinematics = "extensible"``): elastic forces from a stored energy.

The paper's Eq. (23) applies -EI r'''' to the whole vector r, and its tension
force T r' uses the non-unit r'.  Along the chord an axial motion u then feels
the bending stiffness mu u'''' and the axial stiffness sigma (1 + 2 eps0)
(forms/rod.py, solvers/analytic.py).  Here the centre-line forces are instead
the variation of the stored energy of an extensible, unshearable rod
(Antman, *Nonlinear Problems of Elasticity*, 2005, Ch. 8), normalised as in
:mod:`rawehelix.forms.energy` (energies in units of M g L0):

    U = int sigma/2 eps^2 + mu/2 |t'|^2 ds,   eps = |r'| - 1,  t = r'/|r'|,

per *unstretched* (material) length s, with kappa = |t'| = |dt/ds| the
material curvature.  Why material: it is the strain measure of the
reference configuration (the one conjugate to the bending moment in the
Reissner-Antman rod, so m = EI kappa with the EI of the lab tests, which
measure moment against curvature per unstretched length at strains of 1e-3);
the per-stretched-length curvature |t'|/|r'| integrated over the stretched
length would put EI/|r'| in place of EI, a change of O(eps) = 5e-3 that no
measurement of Table 1 resolves.  The energy is quadratic in t', so at eps = 0
it is the paper's mu/2 |r''|^2 restricted to lateral motions: with it

- the axial force is d/dr' (sigma eps^2/2) = T t, T = sigma (|r'| - 1) (29),
  so an axial motion has stiffness sigma: the fixed-fixed bar's n pi sqrt(sigma);
- the bending acts on t only: a motion along t changes no curvature.

The twist terms are the paper's: (31) (the variation of beta/2 int tau^2 with
respect to alpha, scaled by delta/beta as in forms/energy.py) and the coupling
beta tau (r' x r'') of F_NL, Eq. (32), in the centre-line equation: the shear
force of the twisting moment (Kirchhoff's n = T t + GJ tau t x t' + ...),
which with ``model.gamma = "off"`` (tau = alpha') has no energy partner; it is
kept so that the two kinematics differ in the stretch and the bending only.
The paper's -mu kappa^2 r' (the inextensibility's part of F_NL) has no place
here: the variation of U takes its role.

Discretisation: C0 Lagrange r, so t = r'/|r'| jumps at the nodes.  The
interior-penalty energy of the dolfinx biharmonic demo (forms/interior_penalty.py::bending,
whose symmetric form is the variation of 1/2 B(r, r) with [[r']] and {{r''}})
is written on the unit tangent instead:

    U_b = mu [ int 1/2 |t'|^2 dx - sum_nodes {{t'}}.[[t]] + alpha_ip/2 sum_nodes |[[t]]|^2 ].

The exact solution has [[t]] = 0, so the energy and its variation are
consistent (the -{{t'}}.[[dt]] term cancels the node terms of integrating
int t'.dt' by parts), symmetric, and coercive on the jumps for the same
penalty alpha_ip = eta p^2 / h as the paper's form (they agree for |r'| = 1
and lateral jumps).  The jump is taken of t, not of r': a stretch jump
[[|r'|]] carries no bending energy, as it must.  No boundary terms: the ends'
t' = 0 (zero moment, the extensible form of r'' = 0, Eq. 37) is natural, as
in the paper's form.  The mixed form (forms/mixed.py) would need a Lagrange
multiplier for kappa = r'' under a nonlinear energy; it is not offered
(parameters/sections.py::check_kinematics refuses ``discretisation.bending = "mixed"``).

Tension-dependent bending (``helix.EI_law``, EI = a T + b at the local
tension T = EA eps, Eq. 64 and Fig. 4).  Normalised (parameters.Normalised:
mu_a = a / L0^2, mu_b = b / (M g L0^2)) the bending modulus is a field of
the strain,

    mu(eps) = mu_a sigma eps + mu_b,    U = int sigma/2 eps^2 + mu(eps)/2 |t'|^2 ds,

and the variation of U (no other change) gives the moment m = mu(eps) t'
and the axial force

    N.t = dW/d eps = sigma eps + 1/2 mu'(eps) |t'|^2 = T + 1/2 mu_a sigma kappa^2,

the consistent term 1/2 EI'(eps) kappa^2 (in SI: 1/2 a EA kappa^2).  The
"tension" reported everywhere stays T = sigma eps (Eq. 29), the quantity the
law is written in.  The interior-penalty terms carry the modulus at the
nodes, where eps jumps: -{{mu t'}}.[[t]] (the average of the moment, so the
form stays consistent: the exact solution has [[t]] = 0 and a continuous
moment mu t') and alpha_ip/2 {{mu}} |[[t]]|^2 (coercive while mu > 0, i.e.
T > -b/a).  The energy is convex in (eps, kappa) while mu(eps) > mu_a^2
sigma kappa^2 (the determinant of its Hessian); for Eq. (64) on Table 2 the
right side is 2e-3 of the left.  The law is refused with the paper's
kinematics (parameters/eilaw.py::check): its forces are not the variation of an energy
(the -mu kappa^2 r' of Eq. 32) and its bending acts on axial motion, so
"the consistent axial term" has no meaning there.

The section law (``[section] law``, ``c.section``, forms/section_law.py) owns the
cell and node energies: the solid (the default) is U above with the EI law; the
tensegrity's members and the saturating cone replace sigma/2 eps^2 + mu/2 |t'|^2 by
their W(eps, |t'|) and the node terms by -{{dW/dt'}}.[[t]] + alpha_ip/2 {{EI_t}} |[[t]]|^2.

The residual is the Gateaux derivative d/de U(r + e v) at e = 0, taken by UFL
(:func:`variation`), so it is the exact variation of U on the discrete space
and its Jacobian (ufl.derivative of the residual, as everywhere) the exact
second variation: residual, Jacobian and energy agree by construction.
"""

from __future__ import annotations

import ufl
from ufl.algorithms.apply_algebra_lowering import apply_algebra_lowering
from ufl.algorithms.apply_derivatives import apply_derivatives
from ufl.algorithms.map_integrands import map_integrands
from ufl.corealg.map_dag import map_expr_dag
from ufl.corealg.multifunction import MultiFunction

from rawehelix.forms.interior_penalty import ip_penalty, jump
from rawehelix.forms.kinematics import d, stretch, unit_tangent


def strain(r):
    """eps = |r'| - 1, the axial strain (T = sigma eps, Eq. 29)."""
    return stretch(r) - 1


def bending_modulus(r, c):
    """The bending modulus of the stored energy, times the bending switch: mu,
    or with the EI law (``c.bending_law``, forms/eilaw.py) mu(eps) = mu_a sigma eps + mu_b (see above)."""
    return c.bending_law.modulus(r, c)  # the EI-law component (forms/eilaw.py)


def stored_energy(r, sigma, mu, alpha_ip, dx, dS, field=False):
    """U = int sigma/2 eps^2 + mu U_b(t), U_b the interior-penalty energy of
    1/2 int |t'|^2 on the unit tangent (see above); ``alpha_ip`` the penalty
    eta p^2 / h_avg (forms/interior_penalty.py::ip_penalty), ``mu`` includes the bending switch.
    ``field``: mu is a field (the EI law), taken at the nodes as {{mu t'}} and {{mu}}."""
    n = ufl.FacetNormal(dS.ufl_domain())
    t = unit_tangent(r)
    jump_t = jump(t, n)  # [[t]] at a node
    cells = (0.5 * sigma * strain(r)**2 + 0.5 * mu * ufl.dot(d(t), d(t))) * dx
    if field:
        avg_m = 0.5 * (mu("+") * d(t)("+") + mu("-") * d(t)("-"))  # {{mu t'}}
        avg_mu = 0.5 * (mu("+") + mu("-"))  # {{mu}}
        return cells + (-ufl.dot(avg_m, jump_t)
                        + 0.5 * alpha_ip * avg_mu * ufl.dot(jump_t, jump_t)) * dS
    avg_dt = 0.5 * (d(t)("+") + d(t)("-"))  # {{t'}}
    return cells + mu * (-ufl.dot(avg_dt, jump_t) + 0.5 * alpha_ip * ufl.dot(jump_t, jump_t)) * dS


def rod_energy(r, c, alpha_ip, dx, dS, twist=None, ring=None):
    """The section law's stored energy, cells and nodes (``c.section``,
    forms/section_law.py): for the solid, :func:`stored_energy` with the coefficients
    ``c`` (forms/coefficients.py::Coefficients) and the bending modulus of
    :func:`bending_modulus`, built from ``r`` itself, so that its variation carries
    1/2 mu'(eps) kappa^2.  ``twist``: tau, held fixed, for a section whose members
    carry it (forms/section_law.py); ``ring``: alpha, held fixed, for a ring whose phase
    turns with it ([section] ring = "turning")."""
    return c.section.energy(r, c, alpha_ip, dx, dS, tau=twist, alpha=ring)


class _StripVariables(MultiFunction):
    """Each ufl.variable by its expression, once per node of the DAG (UFL's own
    strip_variables visits the tree: exponential in the shared subexpressions of a
    turning ring's members, forms/section_law.py)."""

    expr = MultiFunction.reuse_if_untouched

    def variable(self, o, expression, label):
        return expression


def _strip_variables(expression):
    return map_expr_dag(_StripVariables(), expression)


def variation(energy, r, v, domain):
    """d/de energy(r + e v) at e = 0: the first variation of ``energy`` (a
    callable r -> Form, or -> expression) in the direction v, for any UFL r and
    v (split fields of a mixed space, or the planar embedding); tuples r and v
    vary several arguments at once, ``energy(*(r + e v))``.  e is a placeholder
    constant, replaced by 0 once UFL has differentiated (which removes every e v)."""
    e0 = ufl.Constant(domain)
    e = ufl.variable(e0)
    if isinstance(r, tuple):
        varied = energy(*(x + e * y for x, y in zip(r, v)))
    else:
        varied = energy(r + e * v)
    dE = apply_derivatives(apply_algebra_lowering(ufl.diff(varied, e)))
    dE = map_integrands(_strip_variables, dE) if isinstance(dE, ufl.Form) else _strip_variables(dE)
    return ufl.replace(dE, {e0: ufl.as_ufl(0.0)})


def twist_coupling(r, tau, beta):
    """beta tau (r' x r''): the twisting moment's shear force in F_NL, Eq. (32) (see above)."""
    return beta * tau * ufl.cross(d(r), d(r, 2))


def centre_line_residual(r, v, tau, c, alpha_ip, dx, dS, twist=None, ring=None):
    """delta U(r; v) + int beta tau (r' x r'').v': the elastic forces of the
    centre-line equation (30) with extensible kinematics (``tau`` the moment / GJ,
    ``twist`` the twist that a member section's energy reads, held fixed)."""
    def energy(x):
        return rod_energy(x, c, alpha_ip, dx, dS, twist=twist, ring=ring)
    return variation(energy, r, v, dx.ufl_domain()) + ufl.inner(twist_coupling(r, tau, c.beta), d(v)) * dx


class ExtensibleKinematics:
    """The kinematics component ``model.kinematics = "extensible"``: the centre-line
    forces are the variation of :func:`rod_energy` (see above), bending acts on t."""

    name = "extensible"

    def centre_line_residual(self, r, v, tau, c, degree: int, penalty, dx, dS, kappa=None, eta=None,
                             twist=None, ring=None):
        """delta U(r; v) + the twist coupling (IP bending only: no ``kappa``)."""
        return centre_line_residual(r, v, tau, c, ip_penalty(degree, penalty, dS), dx, dS,
                                    twist=twist, ring=ring)

    def stored_energy(self, r, c, degree: int, penalty, dx, dS, kappa=None, twist=None, ring=None):
        return rod_energy(r, c, ip_penalty(degree, penalty, dS), dx, dS, twist=twist, ring=ring)

    def non_variational_force(self, r, tau, c, kappa=None):
        """-beta tau (r' x r''): the twist coupling, the one non-variational part of F_NL."""
        return -twist_coupling(r, tau, c.beta)

    def bending_measure(self, r, r_t, t, t_t, n):
        """(q, q_t, [[j]], [[j]]_t) of forms/damping.py: q = t', [[j]] = [[t]]."""
        return d(t), d(t_t), jump(t, n), jump(t_t, n)

    def bending_curvature(self, r, kappa=None):
        """The bending measure's curvature vector: t' per unstretched length (IP only)."""
        return d(unit_tangent(r))

    def bending_modulus(self, r, c):
        return bending_modulus(r, c)

    def clamp(self, r, axis):
        """([[t]] n, t') at a clamped wall (forms/cantilever.py)."""
        t = unit_tangent(r)
        return t - axis, d(t)
