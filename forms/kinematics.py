"""Kinematics of the centre line, Eqs. (2), (3), (29) and (34), in pure UFL.

Every function takes UFL expressions of the normalised centre line ``r`` (a
3-vector field over the normalised arc length s in [0, 1]) and returns UFL.
Derivatives along s are cellwise (broken): with C0 Lagrange elements r'' and
r''' are discontinuous across element boundaries, and the bending form in
:mod:`rawehelix.forms.rod` makes up for it with interior-penalty terms.

The functions that use r'' take an optional curvature field ``k``: the mixed
bending form (:mod:`rawehelix.forms.mixed`) passes its own continuous field
kappa (= r'' weakly), and r''' is then kappa'.  ``k = None`` means r''.
"""

from __future__ import annotations

import ufl

K_E = ufl.as_vector((0.0, 0.0, 1.0))  # k_E: z points down, Sec. 2.1
I_E = ufl.as_vector((1.0, 0.0, 0.0))  # i_E: the wind blows along -i_E


def d(f, k: int = 1):
    """The k-th derivative along the normalised arc length s."""
    for _ in range(k):
        f = f.dx(0)
    return f


def stretch(r):
    """|r'|, the local stretch of the centre line."""
    return ufl.sqrt(ufl.dot(d(r), d(r)))


def tension(r, sigma):
    """Normalised tension T~ = sigma (|r'| - 1), Eqs. (22) and (29)."""
    return sigma * (stretch(r) - 1)


def curvature(r, k=None):
    """r'' (cellwise), or the curvature field ``k`` when given."""
    return d(r, 2) if k is None else k


def curvature_squared(r, k=None):
    """kappa^2 = r''.r'', Eq. (34)."""
    kappa = curvature(r, k)
    return ufl.dot(kappa, kappa)


def frenet_torsion(r, eps, k=None):
    """Frenet torsion gamma = r'.(r'' x r''') / |r''|^2, Eq. (34), regularised.

    gamma is singular where the curvature vanishes: on a straight centre line,
    and at the ends where the condition r'' = 0 (Eq. 37) holds.  There the
    Frenet frame turns by pi over a vanishing length, and alpha makes up for it
    so that the total twist tau = gamma + alpha' stays smooth.  We replace
    |r''|^2 by |r''|^2 + eps^2:

    - where kappa >> eps it is the paper's gamma;
    - where kappa << eps it vanishes like kappa^2 / eps^2, as in the paper's
      own code, which drops the gamma' term altogether;
    - it is smooth, so Newton and the linearisation for the spectra see a
      bounded Jacobian.

    ``eps`` is a normalised curvature (1/L0 units): ``model.gamma_eps`` in a
    scene; ``model.gamma = "off"`` drops gamma like the paper's code.  With
    degree 2 elements r''' vanishes cellwise and so does gamma; with the
    curvature field ``k`` (any degree) r'' = k and r''' = k'.
    """
    r1 = d(r)
    r2 = curvature(r, k)
    r3 = d(r, 3) if k is None else d(k)
    return ufl.dot(r1, ufl.cross(r2, r3)) / (ufl.dot(r2, r2) + eps**2)


def twist(r, alpha, eps, coupling=1.0, k=None):
    """Total twist tau = gamma + alpha', Eqs. (8) and (34); ``coupling`` = 0 drops gamma."""
    return coupling * frenet_torsion(r, eps, k) + d(alpha)


def internal_force(r, tau, sigma, mu, beta, k=None):
    """F_NL = (T - mu kappa^2) r' + beta tau (r' x r''), Eq. (32)."""
    return (tension(r, sigma) - mu * curvature_squared(r, k)) * d(r) \
        + beta * tau * ufl.cross(d(r), curvature(r, k))


def unit_tangent(r):
    """t = r'/|r'|."""
    return d(r) / stretch(r)


def tangent_rate(r, r_t):
    """t_t = (I - t t) r_t' / |r'|, the rate of t = r'/|r'|."""
    t = unit_tangent(r)
    return (d(r_t) - ufl.dot(t, d(r_t)) * t) / stretch(r)


def frenet_torsion_rate(r, r_t, eps):
    """d gamma/dt along r_t of the regularised Frenet torsion of Eq. (34),
    gamma = r'.(r'' x r''')/(|r''|^2 + eps^2) (forms/kinematics.py::frenet_torsion)."""
    r1, r2, r3 = d(r), d(r, 2), d(r, 3)
    u1, u2, u3 = d(r_t), d(r_t, 2), d(r_t, 3)
    num = ufl.dot(r1, ufl.cross(r2, r3))
    num_t = (ufl.dot(u1, ufl.cross(r2, r3)) + ufl.dot(r1, ufl.cross(u2, r3))
             + ufl.dot(r1, ufl.cross(r2, u3)))
    den = ufl.dot(r2, r2) + eps**2
    return num_t / den - num * 2 * ufl.dot(r2, u2) / den**2


def normal_part(f, axis):
    """P f = f - (f.e) e: the part of f normal to the unit axis e."""
    return f - ufl.dot(f, axis) * axis
