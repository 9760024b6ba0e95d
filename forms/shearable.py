"""The shearable rod (``model.kinematics = "shearable"``): a geometrically exact
(Simo-Reissner) Cosserat rod of an isotropic section, in pure UFL.

**Fields.**  The centre line r (vector P_p), the spin alpha (scalar P_p) and a
director field n (vector P_(p-1)) whose direction is the section's normal,
d3 = n / |n|.  The section's frame is d3 with d1, d2 turned by alpha about it
from a twist-free (parallel-transported) frame, so the twist is K3 = alpha', as
in the paper's model with gamma = "off" (forms/kinematics.py::twist).

**Why this parametrisation.**  The rotation R = [d1 d2 d3] of a section is
split into the direction of its normal, a point of the sphere, and the spin about
it, an angle on the real line.  Neither has a singularity:

* d3 = n / |n| is smooth wherever n != 0; |n| is a gauge (nothing depends on it
  but the gauge energy kappa_g/2 (|n| - 1)^2, which holds |n| = 1 at every
  equilibrium and leaves the direction free), so a director may turn by any
  angle, also past pi (the roll-up under an end moment), with no chart to
  change: unlike a total rotation vector (singular at |theta| = 2 pi) or Euler
  angles (gimbal lock), and without a quaternion's unit constraint;
* alpha is the paper's spin (Eq. 31): unbounded, additive, so the controller
  (40) and the end torques (38)-(39) act on it as they do on the paper's rod.

The unknowns live in a vector space, so Newton, the generalised-alpha
integrator and the linearisation update them additively and the rotation built
from them is always a rotation: the scheme is consistent on SO(3) by
construction (the parametrised form, not a Lie-group update).  An isotropic
section (EI, GA the same about both diameters) needs d1, d2 only through the
twist, so the energy reads d3 alone.

**Strains** (per unstretched length s), Gamma = R^T r' - e3:

    Gamma_3 = r'.d3 - 1                       the stretch, (N = EA Gamma_3)
    Gamma_s = r' - (r'.d3) d3                 the two shear strains (|Gamma_s|)
    K_b = d3'                                 the two curvatures (|K_b| = |d3'|)
    K_3 = alpha'                              the twist

**Stored energy** (normalised as forms/energy.py: energies in M g L0)

    U = int sigma/2 Gamma_3^2 + GA~/2 |Gamma_s|^2 + mu/2 |d3'|^2 + beta/2 alpha'^2
        - k_E . r + kappa_g/2 (|n| - 1)^2 ds,

C_N = diag(GA, GA, EA), C_M = diag(EI, EI, GJ).  As GA -> infinity Gamma_s -> 0,
d3 -> t = r'/|r'|, Gamma_3 -> |r'| - 1 and |d3'| -> |t'|: the extensible
unshearable rod of forms/extensible.py, term by term.

**Kinetic energy**: K = int 1/2 |r_t|^2 + beta/(2 delta) alpha_t^2 + j~/2 |n_t|^2,
the paper's two terms and the sections' rotary inertia about a diameter,
j~ = EI / (EA L0^2) (parameters/shear.py: half the polar inertia of Eq. 27).
|n_t|^2 = |n|^2 |d3_t|^2 + (|n|_t)^2 is the sections' j~/2 |d3_t|^2 where |n| = 1, and
gives the gauge |n| a mass: a constant mass matrix, so that the integrator sees
the nonlinearity in the stiffness only, as in the unshearable rods.  (The exact
j~/2 |d3_t|^2 leaves |n| massless, an algebraic variable whose error alpha2 with
rho_inf = 1 never damps; its 1/|n|^2 then pumps energy into the motion: measured,
a drift growing to 6.5e-3 of a free vibration's energy over 50 periods.)  The
price is one spurious mode per director node, |n| oscillating at
sqrt(kappa_g / j~) (290 Hz for Table 2's helix), which the modal classification
names ``gauge`` and the studies leave out.

**Twist coupling.**  The paper's rod carries the twisting moment's shear force
beta tau (r' x r'') in the centre-line equation (Eq. 32, forms/extensible.py),
from the moment balance m' + r' x n = 0 with m = GJ tau d3 + EI d3 x d3'.
Here the moment balance is the director's equation, and the twisting moment's
part of it is int beta tau (d3 x d3') . delta d3, delta d3 = (I - d3 d3) eta / |n|
(:func:`twist_coupling`): like the paper's, not the variation of an energy.

**Shear locking** is avoided by the interpolation: r of degree p and n of degree
p - 1, so that r' and d3 are polynomials of the same degree in a cell and the
constraint Gamma_s = 0 of a stiff GA can be met without freezing the bending
(the consistent-interpolation cure of Timoshenko elements); no reduced
integration, no interior penalty (d3 is continuous, so |d3'|^2 is integrable).

**Ends.**  r(0) = 0 (35) and r(1) = r_N (36, 70) as in the paper; alpha(0) = 0 or
the controller's torque (38), (40); the torque at the top (39); the zero-moment
ends (37) are natural: d3' = 0 there, no condition on n.
"""

from __future__ import annotations

import ufl

from rawehelix.forms.extensible import variation
from rawehelix.forms.kinematics import K_E, d
from rawehelix.forms.section_law import NonlinearSection
from rawehelix.forms.twist import twist_equation

#: the gauge's stiffness kappa_g, in units of sigma: any positive value gives the same
#: solution (|n| = 1); sigma keeps the Jacobian's scale
GAUGE = 1.0


def director(n):
    """d3 = n / |n|, the section's normal."""
    return n / ufl.sqrt(ufl.dot(n, n))


def director_rate(n, n_t):
    """d3_t = (I - d3 d3) n_t / |n|, the rate of :func:`director`."""
    d3 = director(n)
    return (n_t - ufl.dot(d3, n_t) * d3) / ufl.sqrt(ufl.dot(n, n))


def stretch_strain(r, n):
    """Gamma_3 = r'.d3 - 1: the axial strain (N = sigma Gamma_3)."""
    return ufl.dot(d(r), director(n)) - 1


def shear_strain(r, n):
    """Gamma_s = r' - (r'.d3) d3: the shear strains as a vector normal to d3."""
    d3 = director(n)
    return d(r) - ufl.dot(d(r), d3) * d3


def bending_strain(n):
    """K_b = d3': the curvature vector (|K_b| the curvature, 1/L0 units)."""
    return d(director(n))


def section_strains(r, n, c):
    """(Gamma_3, kappa): the stretch and the regularised curvature |bending switch x d3'|
    that a member section law reads (forms/section_law.py::NonlinearSection.curvature)."""
    return stretch_strain(r, n), NonlinearSection.curvature(c.bending * bending_strain(n))


def elastic_density(r, n, c):
    """sigma/2 Gamma_3^2 + GA~/2 |Gamma_s|^2 + mu/2 |d3'|^2 + the gauge's energy
    (without the twist, whose energy alpha alone carries); with a member section law
    W(Gamma_3, |d3'|) + GA~(Gamma_3, |d3'|)/2 |Gamma_s|^2, GA~ the section's
    (forms/section_law.py: the members' GA at their mean force, or helix.GA_N)."""
    g, k = shear_strain(r, n), bending_strain(n)
    gauge = 0.5 * GAUGE * c.sigma * (ufl.sqrt(ufl.dot(n, n)) - 1) ** 2
    return c.section.sheared_density(stretch_strain(r, n), g, k, r, c) + gauge


def stored_energy(r, alpha, n, c, dx):
    """U: the elastic energy, beta/2 alpha'^2 and gravity's -k_E . r."""
    return (elastic_density(r, n, c) + c.section.twist_energy(d(alpha), c)
            - c.gravity * ufl.dot(K_E, r)) * dx


def kinetic_density(r_t, alpha_t, n_t, c):
    """1/2 |r_t|^2 + beta/(2 delta) alpha_t^2 + j~/2 |n_t|^2."""
    return (0.5 * ufl.dot(r_t, r_t) + 0.5 * c.beta / c.delta * alpha_t ** 2
            + 0.5 * c.rotary * ufl.dot(n_t, n_t))


def rotary_inertia(n_tt, eta, c, dx):
    """int j~ n_tt . eta: the director's inertia, of K_r = j~/2 |n_t|^2 (see above)."""
    return c.rotary * ufl.dot(n_tt, eta) * dx


def twist_coupling(n, tau, eta, c):
    """beta tau (d3 x d3') . delta d3, delta d3 = (I - d3 d3) eta / |n|: the twisting
    moment's part of the moment balance (see above)."""
    return c.beta * tau * ufl.dot(ufl.cross(director(n), bending_strain(n)),
                                  director_rate(n, eta))


def elastic_residual(r, alpha, n, tests, c, dx, ds):
    """delta U on (r, n), the scaled twist equation (31) and the end torques (38)-(39)
    (forms/twist.py): the shearable rod's internal forces, as forms/rod.py::elastic_residual
    gives the paper's (the twist equation times delta / beta, so it reads alpha_tt + ...)."""
    v, psi, eta = tests
    tau = d(alpha)  # K_3 = alpha', the moment / GJ
    F = variation(lambda a, b: elastic_density(a, b, c) * dx, (r, n), (v, eta), dx.ufl_domain())
    return F + twist_coupling(n, tau, eta, c) * dx + twist_equation(tau, psi, c, dx, ds)


def non_variational_power(alpha, n, n_t, c, dx):
    """The twist coupling's power: int beta tau (d3 x d3') . d3_t."""
    return twist_coupling(n, d(alpha), n_t, c) * dx


class ShearableKinematics:
    """The kinematics component ``model.kinematics = "shearable"`` (forms/coefficients.py):
    its forms are the model's (models/shearable.py); it answers what the section law
    and the observables ask of a kinematics."""

    name = "shearable"

    def bending_modulus(self, r, c):
        return c.bending_law.modulus(r, c)
