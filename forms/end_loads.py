"""The end components' lumped terms in the linearised twist equation (31), pure UFL.

About a relative equilibrium (uniform spin Omega, end torques Q at the top and
tau_gen at the ground, Eqs. 38-39), the ends add to (lambda^2 M + lambda C + K) x = 0
only on the twist alpha at s = 0 and s = 1.  With the twist row of the residual
int alpha_tt psi + delta int M psi' - delta (mN psi(1) - m0 psi(0)) (forms/twist.py),
mN = Q / (GJ/L0), m0 = tau_gen / (GJ/L0) and d/dt~ = t_scale d/dt:

    M += J_top / J_rod             alpha(1) psi(1)   the rotor's spin inertia
    C += -delta Q' / (GJ/L0 t_s)   alpha(1) psi(1)   its aerodynamic damping -dQ/dOmega
    C += delta tau' / (GJ/L0 t_s)  alpha(0) psi(0)   the generator's dtau/dOmega
    K += delta k1,  C += delta k2  alpha(0) psi(0)   the paper's law, Eq. (40)

J_rod = rho I_p L0 = (beta/delta) M L0^2 [kg m^2] is the rod's own polar inertia
(Eq. 27: 2 rho I = 2 M EI / (EA L0)).  The coefficients are constants, set per
operating point (:meth:`EndLoadForms.set`); all zero, the forms add nothing.
"""

from __future__ import annotations

import ufl

#: the coefficients, by matrix and end: (matrix, end) with end 1 = top, 0 = ground
TERMS = {"top_inertia": ("M", 1), "top_damping": ("C", 1), "ground_damping": ("C", 0),
         "ground_stiffness": ("K", 0)}


class EndLoadForms:
    """The lumped end terms as bilinear forms on a rod's twist, with one constant per
    term (``make``: value -> a dolfinx Constant on the rod's mesh)."""

    def __init__(self, model, mesh, make):
        self.model = model
        self.mesh = mesh
        self.coefficients = {name: make(0.0) for name in TERMS}

    def set(self, values: dict):
        """The normalised coefficients of :data:`TERMS` (missing ones: 0)."""
        unknown = set(values) - set(TERMS)
        if unknown:
            raise ValueError(f"end loads: unknown terms {sorted(unknown)}; known {tuple(TERMS)}")
        for name, constant in self.coefficients.items():
            constant.value = float(values.get(name, 0.0))

    def forms(self, trial, test) -> dict:
        """{"K" | "C" | "M": the sum of its end terms} on the twist of ``trial`` and ``test``."""
        a = self.model.split(trial)["twist"]
        b = self.model.split(test)["twist"]
        x = ufl.SpatialCoordinate(self.mesh)[0]
        weight = {1: x, 0: 1 - x}  # the point of the end: s = 1 or s = 0 (as forms/twist.py)
        ds = ufl.ds(domain=self.mesh)
        out = {}
        for name, (matrix, end) in TERMS.items():
            term = self.coefficients[name] * a * b * weight[end] * ds
            out[matrix] = out[matrix] + term if matrix in out else term
        return out
