"""The stationary shearable rod's independent reference: the planar Simo-Reissner
elastica shot as an ODE (model.kinematics = "shearable", forms/shearable.py).

It shares no code with the FE forms: the strains and the equilibrium are written
out here from the section's law.  With the section's normal d3 = (cos theta,
sin theta), d1 = (-sin theta, cos theta) in the (x, z) plane (z down, as
references/shooting.py) and the resultant N = N(0) - q s of the load q
(shooting.load_vector),

    N.d3 = sigma Gamma_3,   N.d1 = GA~ gamma,          (C_N = diag(GA, EA), Gamma = R^T r' - e3)
    r' = (1 + Gamma_3) d3 + gamma d1,
    (mu theta')' + r' x N = 0,   r' x N = (1 + Gamma_3) N.d1 - gamma N.d3,

with the zero moments theta' = 0 at both ends (37).  As GA~ -> infinity gamma -> 0
and the system is references/shooting.py::extensible_rhs without the EI law.
"""

from __future__ import annotations

import numpy as np

from rawehelix.references.shooting import (ExtensibleSolution, _bending_modulus, load_vector,
                                           resultant_in_frame, shoot_planar_rod)


def shearable_rhs(normalised, resultant0):
    """f(s, y), y = (x, z, theta, kappa = theta')."""
    q = normalised
    sigma, shear, mu = q.sigma, q.shear_stiffness, _bending_modulus(q)
    load = load_vector(q)
    N0 = np.asarray(resultant0, dtype=float)

    def f(s, y):
        c, sn, Nt, Nn = resultant_in_frame(N0, load, s, y[2])
        kappa = y[3]
        stretch, gamma = 1.0 + Nt / sigma, Nn / shear
        return np.array([stretch * c - gamma * sn, stretch * sn + gamma * c, kappa,
                         -(stretch * Nn - gamma * Nt) / mu])

    return f


class ShearableSolution(ExtensibleSolution):
    """The stationary planar shearable rod, normalised: the extensible solution's
    accessors on y = (x, z, theta, theta') with theta the director's angle, so that its
    tension N.t is N.d3 (references/shooting.py, no EI law here) and :meth:`director`."""

    def director(self, s) -> np.ndarray:
        """d3 = [cos theta, 0, sin theta], shape (n, 3)."""
        theta = self._dense(np.atleast_1d(np.asarray(s, dtype=float)))[2]
        return np.column_stack([np.cos(theta), 0 * theta, np.sin(theta)])


def not_applicable(params) -> str | None:
    """Why this reference does not apply to a shearable scene (the reference its
    kinematics names, models/kinematics.py), or None: it takes a constant GA
    (helix.GA_N), not the members' (section.law = "tensegrity")."""
    if params.helix.GA_N is None:
        return ("the members' GA follows their force (section.law = 'tensegrity'); the "
                "shearable shooting reference takes a constant GA (helix.GA_N)")
    return None


def solve_shearable(normalised, rtol: float = 1e-11, atol: float = 1e-13,
                    tol: float = 1e-10) -> ShearableSolution:
    """Shoot from s = 0 (r = 0, theta' = 0) for (N(0), theta(0)) to r(1) = the top of
    Eq. (66) and theta'(1) = 0.  Raises RuntimeError past ``tol``."""
    if not normalised.shear_stiffness > 0:
        raise ValueError("the shearable reference needs GA > 0 (helix.GA_N)")
    resultant0, mismatch, dense = shoot_planar_rod(normalised, shearable_rhs, "shearable",
                                                   rtol, atol, tol)
    return ShearableSolution(normalised=normalised, resultant0=resultant0,
                             boundary_residual=mismatch, _dense=dense)
