"""Structural damping (the scene's ``[damping]``): Kelvin-Voigt on the strain rates.

Each viscous stress is the elastic modulus x the retardation time x the
strain rate: N_v = EA tau_a eps_t, m_v = EI tau_b kappa_t, M_v = GJ tau_t tau_t.
They come from a Rayleigh dissipation potential, normalised as
:mod:`rawehelix.forms.energy` (power in units of M g L0 / t_scale, the
retardation times divided by t_scale, Eq. 25):

    D = 1/2 int sigma tau_a eps_t^2 + beta tau_t tau_t^2 ds + tau_b mu D_b,

and the viscous part of the residual is its derivative with respect to the
velocity (r_t, alpha_t) in the direction (v, delta/beta psi) (the twist row
scaled by delta/beta like the elastic one, forms/energy.py): residual and
Jacobian agree, C = d^2 D / d w_t^2 is symmetric, and since D is quadratic in
the rates the dissipated power is R_v(w_t) = 2 D.

The rates (t = r'/|r'|, t_t = (I - t t) r_t'/|r'| its rate):

* eps_t = d|r'|/dt = t . r_t' (the rate of eps = |r'| - 1, Eq. 29);
* tau_t = d tau/dt of Eq. (34) (alpha_t' with gamma off);
* bending: the co-rotational rate of the curvature measure q (r'' with the
  paper's kinematics, t' with the extensible ones, forms/extensible.py) in the
  frame that turns with the tangent, w = t x t_t:

      b = q_t - w x q.

Which motions are not damped.  A rigid translation (r_t = c) and the steady
spin of Sec. 5.2 (r_t = 0, alpha_t uniform) have eps_t = tau_t = b = 0.  A
rigid rotation r_t = Omega x r has eps_t = tau_t = 0 (|r'| and tau are
invariants) and b = (Omega . t) t x q: zero on a straight rod (to first order
about one: the modes of Table 3), and for a planar state turning about the
normal of its plane (Omega . t = 0), but not for a curved rod turning about an
axis along its tangent.  Making that zero needs the sections' axial spin in
the rate; in this model that is alpha_t, and with it the steady spin of a
sagging rod would be damped (the rotating damping of a bent shaft), which the
switch is specified not to do (tests/test_damping.py measures both).

With the EI law (helix.EI_law, forms/extensible.py) the bending modulus in D
is the local mu(eps) of the state (EI(T) tau_b: "the elastic modulus x the
retardation time"), at the nodes as {{mu b}} and {{mu}}.

Discretisation (C0 Lagrange, interior penalty): D_b is the IP energy of the
rate, as the elastic bending form is that of r (forms/interior_penalty.py::bending) or of t
(forms/extensible.py),

    D_b = 1/2 int |b|^2 dx - sum_nodes {{b}}.[[j]]_t + alpha_ip/2 sum_nodes |[[j]]_t|^2,

with [[j]] the node jump of r' (paper) or t (extensible) and [[j]]_t =
[[j_t]] - {{w}} x [[j]] its co-rotational rate.  About a straight state it is
1/2 B(r_t, r_t) (paper) or U_b(t_t) (extensible): symmetric and coercive on
the jumps like the elastic form.  The mixed bending form and the spline
scheme are refused (parameters/damping.py::check).
"""

from __future__ import annotations

import ufl

from rawehelix.forms.interior_penalty import ip_penalty
from rawehelix.forms.kinematics import d, frenet_torsion_rate, tangent_rate, unit_tangent


def strain_rates(r, r_t, alpha_t, c, n):
    """(eps_t, tau_t, b, [[j]]_t) of the module docstring at the state r, each linear
    in (r_t, alpha_t); ``alpha_t`` None (the planar model): tau_t None."""
    t, t_t = unit_tangent(r), tangent_rate(r, r_t)
    w = ufl.cross(t, t_t)  # the tangent's spin

    # the kinematics component's curvature measure: q = r'', [[j]] = [[r']] (paper)
    # or q = t', [[j]] = [[t]] (extensible)
    q, q_t, j, j_t = c.kinematics.bending_measure(r, r_t, t, t_t, n)
    b = q_t - ufl.cross(w, q)
    jb = j_t - ufl.cross(0.5 * (w("+") + w("-")), j)
    eps_t = ufl.dot(t, d(r_t))  # d|r'|/dt
    tau_t = None if alpha_t is None else (
        c.gamma_coupling * frenet_torsion_rate(r, r_t, c.gamma_eps) + d(alpha_t))  # (34)
    return eps_t, tau_t, b, jb


def _bilinear(x, y, r, c, degree: int, penalty, measures):
    """The symmetric form B(x, y) of D = 1/2 B(x, x), x = :func:`strain_rates` at the
    state r (which sets the bending modulus under the EI law)."""
    dx, dS, _ = measures
    kv = c.damping  # the retardation times of the KelvinVoigt component
    (ea, ta, ba, ja), (eb, tb, bb, jb) = x, y
    alpha_ip = ip_penalty(degree, penalty, dS)
    if c.bending_law.field:  # m_v = EI(T) tau_b b: the modulus at the nodes as in forms/extensible.py
        mu = c.bending_law.modulus(r, c)

        def avg(f):
            return 0.5 * (f("+") + f("-"))
        B_b = (mu * ufl.dot(ba, bb) * dx
               + (-ufl.dot(avg(mu * ba), jb) - ufl.dot(avg(mu * bb), ja)
                  + alpha_ip * avg(mu) * ufl.dot(ja, jb)) * dS)
        B = c.sigma * kv.tau_a * ea * eb * dx + kv.tau_b * B_b
    else:
        B_b = (ufl.dot(ba, bb) * dx
               + (-ufl.dot(0.5 * (ba("+") + ba("-")), jb) - ufl.dot(0.5 * (bb("+") + bb("-")), ja)
                  + alpha_ip * ufl.dot(ja, jb)) * dS)
        B = c.sigma * kv.tau_a * ea * eb * dx + c.bending * c.mu * kv.tau_b * B_b
    if ta is not None:
        B += c.beta * kv.tau_t * ta * tb * dx
    return B


def dissipation(r, r_t, alpha_t, c, degree: int, penalty, measures):
    """D of the module docstring at the state r and the rates (r_t, alpha_t);
    ``alpha_t`` None (the planar model) drops the torsion term."""
    x = strain_rates(r, r_t, alpha_t, c, ufl.FacetNormal(measures[0].ufl_domain()))
    return 0.5 * _bilinear(x, x, r, c, degree, penalty, measures)


def viscous_residual(r, r_t, alpha_t, v, psi, c, degree: int, penalty, measures):
    """dD/d(r_t, alpha_t) in the direction (v, delta/beta psi): the viscous forces.

    The rates are linear in (r_t, alpha_t), so this derivative is B(x(r_t, alpha_t),
    x(v, delta/beta psi)), x the rates.  Written so, its UFL is a fraction of that
    of the Gateaux derivative of :func:`dissipation` (extensible.variation), which
    tests/test_damping.py assembles against it."""
    n = ufl.FacetNormal(measures[0].ufl_domain())
    planar = psi is None
    x = strain_rates(r, r_t, None if planar else alpha_t, c, n)
    y = strain_rates(r, v, None if planar else c.delta / c.beta * psi, c, n)
    return _bilinear(x, y, r, c, degree, penalty, measures)


class KelvinVoigt:
    """The damping component (the scene's ``[damping]``, parameters/damping.py): its
    retardation times / t_scale (numbers or constants) and its contributions, the
    dissipation potential D and the viscous residual dD/dw_t.  It adds no field
    and every solver runs it (its scene refusals: parameters/damping.py)."""

    fields = ()
    refuses = {}

    def __init__(self, tau_a, tau_b, tau_t):
        self.tau_a, self.tau_b, self.tau_t = tau_a, tau_b, tau_t

    @classmethod
    def from_normalised(cls, q, make=float):
        """From :class:`rawehelix.parameters.Normalised`; the null object when all are 0."""
        if not q.damped:
            return NoneDamping()
        return cls(make(q.tau_axial), make(q.tau_bending), make(q.tau_torsion))

    def dissipation(self, r, r_t, alpha_t, c, degree: int, penalty, measures):
        return dissipation(r, r_t, alpha_t, c, degree, penalty, measures)

    def residual(self, r, r_t, alpha_t, v, psi, c, degree: int, penalty, measures):
        return viscous_residual(r, r_t, alpha_t, v, psi, c, degree, penalty, measures)


class NoneDamping:
    """No structural damping (the paper's model): no dissipation, no viscous force."""

    fields = ()
    refuses = {}

    def dissipation(self, r, r_t, alpha_t, c, degree: int, penalty, measures):
        return None

    def residual(self, r, r_t, alpha_t, v, psi, c, degree: int, penalty, measures):
        return 0
