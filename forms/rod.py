"""Weak forms of the rod equations (30)-(31) in pure UFL.

Unknowns on a mixed Lagrange space of degree p >= 2 over s in [0, 1]:
centre line r (3 components) and twist angle alpha.  With test functions
(v, psi), v = 0 at both ends (Dirichlet, Eqs. 35-36):

    int r_tt.v + int F_NL.v' + mu B(r, v) - int (k_E + F_A).v = 0        (30)
    int alpha_tt psi + delta int tau psi' - delta [tau psi]_0^1 = 0       (31)

with F_NL of Eq. (32), tau = gamma + alpha' (34), tau(0) = m0 and
tau(1) = mN (38)-(39) as natural boundary terms, and B the C0
interior-penalty form of int r''.v'' (the -F_L' = -mu r'''' term, Eq. 33).
The zero-curvature ends r'' = 0 (37) are natural: B has no boundary terms.

With ``discretisation.bending = "mixed"`` the state has a third field, the
curvature kappa, and B is replaced by the mixed form of
:mod:`rawehelix.forms.mixed` (second order, kappa = 0 at the ends
essential); the functions below see it as ``kappa`` (and its test ``eta``).

With ``model.kinematics = "extensible"`` the centre-line forces (F_NL and
B) are instead the variation of the extensible rod's stored energy,
:mod:`rawehelix.forms.extensible`; :func:`elastic_residual` is the one place
that chooses.

With ``[torsion_hysteresis]`` (``c.hysteresis``) the state has a third
field, the Bouc-Wen internal twist z (a DG field), every GJ tau is the moment
of :mod:`rawehelix.forms.hysteresis` and the residual has z's equation; the
functions below see it as ``z`` (and its test ``zeta``).

No solver code here: functions take UFL objects and numbers (or constants)
and return UFL.
"""

from __future__ import annotations

import ufl

from rawehelix.forms.coefficients import Coefficients
from rawehelix.forms.extensible import variation
from rawehelix.forms.twist import twist_equation
from rawehelix.forms.kinematics import I_E, K_E, d, frenet_torsion_rate, tension, twist  # noqa: F401


def quadrature_degree(degree: int, chosen: int = 0) -> int | None:
    """The quadrature degree of every cell integral (residual and Jacobian alike).

    ``chosen`` = 0: the rule 3p.  The polynomial parts of the integrands of
    (30)-(31) at degree p are of degree 2p (inertia r_tt.v), 2p - 4 (bending
    r''.v''), 4p - 6 (mu kappa^2 r'.v') and 3p (drag |r_t| r_t.v, if |r_t|
    were a polynomial); the tension (|r'| - 1) r'.v' is a polynomial of degree
    2p - 2 times 1/|r'| = 1 + O(strain), so the part that no rule integrates
    exactly is of the order of the strain (2e-3) times a smooth function.
    3p integrates every polynomial part exactly for p <= 6 and the rest to
    well below the discretisation error (docs/explanation/speed.md).  UFL's own estimate
    (``chosen`` = -1) adds the degrees of every factor, 14 for the residual
    and 20 for the Jacobian at p = 3, so the Jacobian is not even the exact
    derivative of the residual; ``chosen`` > 0: that degree."""
    if chosen == -1:
        return None
    return chosen if chosen > 0 else 3 * degree


def measures(mesh, degree: int, chosen: int = 0):
    """(dx, dS, ds) with the quadrature of :func:`quadrature_degree` on the cells
    (the facet measures are point evaluations in 1D)."""
    q = quadrature_degree(degree, chosen)
    metadata = {} if q is None else {"quadrature_degree": q}
    return (ufl.dx(domain=mesh, metadata=metadata), ufl.dS(domain=mesh), ufl.ds(domain=mesh))


def aerodynamic_force(r_t, c: Coefficients, r=None):
    """F~_A = -nu |v_A| v_A with v_A = r_t + v_w(z) i_E, Eqs. (14) and (28): v_w(z) the
    wind component's speed at the height of r (forms/wind.py; v_w0, the paper's, for
    the uniform wind, which reads no r).

    |v_A| is smoothed by 1e-14 under the root so that its derivative exists at
    v_A = 0 (it is then zero, as the exact one-sided limits agree)."""
    v_a = r_t + c.wind.air(r, c)
    return -c.nu * ufl.sqrt(ufl.dot(v_a, v_a) + 1e-14) * v_a


def body_force(r_t, c: Coefficients, r=None):
    """Gravity k_E plus drag F_A per unit length at the centre line r, the right side of
    Eq. (30)."""
    return c.gravity * K_E + c.drag * aerodynamic_force(r_t, c, r)


def elastic_residual(r, alpha, v, psi, c: Coefficients, degree: int, penalty, dx, dS, ds,
                     kappa=None, eta=None, z=None):
    """Internal forces and end torques of Eqs. (30)-(31): everything but inertia and loads.

    ``kappa``, ``eta``: the curvature field and its test (mixed bending form).
    ``z``: the Bouc-Wen internal twist; every GJ tau is then the moment
    GJ (rho tau + (1 - rho) z) of :mod:`rawehelix.forms.hysteresis`.
    ``c.kinematics = "extensible"``: the centre-line forces are the variation
    of the extensible rod's stored energy, :mod:`rawehelix.forms.extensible`
    (IP bending only; the twist terms are the same)."""
    tau = twist(r, alpha, c.gamma_eps, c.gamma_coupling, k=kappa)  # (34)
    # the moment / GJ: tau, the members' Q / GJ (forms/section_law.py), or the
    # hysteresis component's (Fig. 5; the two are refused together)
    moment = c.section.twist_moment(r, tau, c, alpha) if z is None else c.hysteresis.moment(tau, z)
    # the kinematics component: the paper's F_NL (32)-(33) (forms/paper.py) or the
    # variation of the extensible rod's stored energy (forms/extensible.py)
    F = c.kinematics.centre_line_residual(r, v, moment, c, degree, penalty, dx, dS,
                                          kappa=kappa, eta=eta, twist=tau, ring=alpha)
    for comp in c.extra:  # the energy components (forms/energy_component.py): delta W(r; v)
        F += comp.residual(r, v, c, dx)
    if psi is None:  # the planar model: no twist equation
        return F
    if c.section.ring_turns:  # the ring's phase is alpha: (delta / beta) dU/d alpha (forms/energy.py)
        def energy(a):
            return c.kinematics.stored_energy(r, c, degree, penalty, dx, dS, kappa=kappa, twist=tau,
                                              ring=a)
        F += c.delta / c.beta * variation(energy, alpha, psi, dx.ufl_domain())
    return F + twist_equation(moment, psi, c, dx, ds)  # (31), (38)-(39)


def test_fields(test):
    """(v, psi) of a mixed (r, alpha) test function; (v, psi, eta) on (r, alpha, kappa)."""
    return ufl.split(test)


def residual_of_fields(r, alpha, r_t, r_tt, alpha_tt, tests, c: Coefficients, degree: int,
                       penalty, measures, kappa=None, alpha_t=None, z=None, z_t=None):
    """The full residual of Eqs. (30)-(31), inertia + elastic - loads + the
    components' terms, on fields given one by one (the rod model,
    models/unshearable.py, splits its state; the first-order form of the
    dynamics has (r, alpha) and their rates in a larger space); ``r_t``/``r_tt``/``alpha_tt`` may be None (zero).  ``kappa``:
    the curvature field of the mixed bending form, with the test
    ``tests[2]``.  ``alpha_t``: the twist rate, read by the structural damping
    (``c.damping``, forms/damping.py) and the hysteresis only.  ``z``, ``z_t``:
    the Bouc-Wen twist and its rate, with the test ``tests[2]``
    (forms/hysteresis.py); ``z_t`` None (a stationary residual) holds z = 0."""
    dx, dS, ds = measures
    v, psi, *third = tests
    moving = r_t is not None
    if r_t is None:
        r_t = ufl.as_vector((0.0, 0.0, 0.0))
    F = (elastic_residual(r, alpha, v, psi, c, degree, penalty, dx, dS, ds,
                          kappa=kappa, eta=third[0] if third and kappa is not None else None,
                          z=z)
         - ufl.inner(body_force(r_t, c, r), v) * dx)
    if z is not None:  # z's equation, of the hysteresis component (forms/hysteresis.py)
        # tau_t of Eq. (34): alpha_t', and the Frenet torsion's rate (None at rest)
        tau_t = (c.gamma_coupling * frenet_torsion_rate(r, r_t, c.gamma_eps) + d(alpha_t)
                 if moving and z_t is not None else None)
        F += c.hysteresis.residual(z, z_t, tau_t, third[0], dx, c)
    if moving:  # the damping component: Kelvin-Voigt from its dissipation potential, or none
        F += c.damping.residual(r, r_t, alpha_t, v, psi, c, degree, penalty, measures)
        if alpha_t is not None and psi is not None:  # the spin drag (forms/spin_drag.py), or none
            F += c.spin_drag.residual(alpha_t, psi, c, dx)
    if r_tt is not None:
        F += (ufl.inner(r_tt, v) + alpha_tt * psi) * dx
    return F


def tension_of(w, c: Coefficients):
    """The normalised tension field of a mixed state, Eq. (29)."""
    return tension(ufl.split(w)[0], c.sigma)
