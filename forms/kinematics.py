"""Kinematics of the centre line, Eqs. (2), (3), (29) and (34), in pure UFL.

Every function takes UFL expressions of the normalised centre line ``r`` (a
3-vector field over the normalised arc length s in [0, 1]) and returns UFL.
Derivatives along s are cellwise (broken): with C0 Lagrange elements r'' and
r''' are discontinuous across element boundaries, and the bending form in
:mod:`rawehelix.forms.rod` makes up for it with interior-penalty terms.
"""

from __future__ import annotations

import ufl


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


def curvature_squared(r):
    """kappa^2 = r''.r'', Eq. (34)."""
    return ufl.dot(d(r, 2), d(r, 2))


def frenet_torsion(r, eps):
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
    degree 2 elements r''' vanishes cellwise and so does gamma.
    """
    r1, r2, r3 = d(r), d(r, 2), d(r, 3)
    return ufl.dot(r1, ufl.cross(r2, r3)) / (ufl.dot(r2, r2) + eps**2)


def twist(r, alpha, eps, coupling=1.0):
    """Total twist tau = gamma + alpha', Eqs. (8) and (34); ``coupling`` = 0 drops gamma."""
    return coupling * frenet_torsion(r, eps) + d(alpha)


def internal_force(r, tau, sigma, mu, beta):
    """F_NL = (T - mu kappa^2) r' + beta tau (r' x r''), Eq. (32)."""
    return (tension(r, sigma) - mu * curvature_squared(r)) * d(r) \
        + beta * tau * ufl.cross(d(r), d(r, 2))
