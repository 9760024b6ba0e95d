"""The normalised groups of a scene, Eqs. (25)-(29), and the units back to SI."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from rawehelix.operation import wind
from rawehelix.parameters import components
from rawehelix.parameters.forcing import EndForcing

RPM = 2.0 * math.pi / 60.0  # rad/s per rpm


@dataclass(frozen=True)
@components.normalised_fields
class Normalised(EndForcing):
    """The dimensionless groups of Eqs. (25)-(29) and the scales to undo them."""

    # scales
    L0: float  # [m]
    t_scale: float  # sqrt(L0/g) [s], Eq. (25)
    force_scale: float  # M g [N], Eq. (29)
    torque_scale: float  # GJ / L0 [Nm], Eqs. (38)-(39)
    # groups
    sigma: float  # EA / (M g), Eq. (27)
    mu: float  # EI / (M g L0^2), Eq. (26)
    beta: float  # GJ / (M g L0^2), Eq. (26)
    nu: float  # rho0 l_a L0^2 C_D / (2 M), Eq. (26)
    delta: float  # beta sigma / (2 mu), Eq. (27)
    v_w0: float  # v_w0 / sqrt(g L0), Eq. (27)
    # ends
    eps0: float
    Gamma0: float  # [rad]
    r1: float  # R1 / L0, Eq. (70)
    omega1: float  # 2 pi f1 t_scale, Eq. (70)
    phase0: float  # phase of the circle at t~ = 0: omega1 t~ + phase0 in Eq. (70) [rad]
    # torque ramp (69) and controller (40)
    mN0: float
    t0: float
    k1: float
    k2: float
    spin_target: float  # alpha_dot* t_scale
    # switches
    gravity: float
    drag: float
    bending: float
    # then the components' groups, each module's NORMALISED (parameters/components.py):
    # tau_axial, tau_bending, tau_torsion (damping.py), bending_law, mu_per_tension,
    # mu_at_zero_tension (eilaw.py), bw_rho, bw_A, bw_beta, bw_gamma, bw_n (hysteresis.py)

    @property
    def damped(self) -> bool:
        return self.tau_axial > 0 or self.tau_bending > 0 or self.tau_torsion > 0

    @property
    def hysteretic(self) -> bool:
        return self.bw_rho < 1

    @classmethod
    def from_parameters(cls, p: "Parameters") -> "Normalised":
        """The groups of ``p``; a group past the float range is inf, 0 or nan here
        (numpy arithmetic, IEEE as Python's floats), never an exception:
        :meth:`Parameters.__post_init__` refuses such a scene with :data:`GROUP_KEYS`."""
        with np.errstate(all="ignore"):
            q = cls._groups(p)
        return dataclasses.replace(q, **{f.name: float(getattr(q, f.name))
                                         for f in dataclasses.fields(q)
                                         if isinstance(getattr(q, f.name), np.floating)})

    @classmethod
    def _groups(cls, p: "Parameters") -> "Normalised":
        h, e, env = p.helix, p.ends, p.environment
        L0, M, g = np.float64(h.length_m), np.float64(h.mass_kg), np.float64(env.g_m_s2)
        t_scale = np.sqrt(L0 / g)  # (25)
        mu = h.EI_Nm2 / (M * g * L0**2)  # (26)
        beta = h.GJ_Nm2 / (M * g * L0**2)  # (26)
        sigma = h.EA_N / (M * g)  # (27)
        return cls(
            L0=L0, t_scale=t_scale, force_scale=M * g, torque_scale=h.GJ_Nm2 / L0,
            sigma=sigma, mu=mu, beta=beta,
            # the air's density and the reference wind: [wind]'s when it gives them
            nu=wind.air_density(p) * h.drag_length_m * L0**2 * h.drag_coefficient / (2 * M),
            delta=_delta(p, beta, sigma, mu),  # (27), or the members' twist inertia
            v_w0=wind.reference_speed(p) / np.sqrt(g * L0),
            # eps0: nan until the elongation of ends.tension_N is found (Parameters.normalised)
            eps0=math.nan if e.elongation is None else e.elongation,
            Gamma0=math.radians(e.elevation_deg),
            r1=e.circle_radius_m / L0, omega1=2 * math.pi * e.circle_frequency_Hz * t_scale,
            phase0=0.0,
            mN0=p.torque.top_Nm / (h.GJ_Nm2 / L0), t0=p.torque.rise_time_s / t_scale,
            k1=p.controller.k1, k2=p.controller.k2,
            spin_target=p.controller.target_rpm * RPM * t_scale,
            gravity=float(p.model.gravity), drag=float(p.model.drag),
            bending=float(p.model.bending),
            # the components' groups (parameters/components.py)
            **components.normalise(p, {"L0": L0, "M": M, "g": g, "t_scale": t_scale}),
        )

    # -- units back to SI ---------------------------------------------------
    def tension_N(self, T):
        return np.asarray(T) * self.force_scale

    def torque_Nm(self, m):
        return np.asarray(m) * self.torque_scale

    def time_s(self, t):
        return np.asarray(t) * self.t_scale

    def length_m(self, x):
        return np.asarray(x) * self.L0

    def spin_rpm(self, alpha_t):
        return np.asarray(alpha_t) / self.t_scale / RPM


def _delta(p, beta, sigma, mu):
    """delta = GJ / (g L0 J'), J' the twist inertia per unit length: the solid's
    2 (M / L0) EI / EA (Eq. 27: beta sigma / (2 mu)), or the section's mass
    distribution (section.twist_inertia = "members", Section.inertia_per_length)."""
    J = p.model.section.inertia_per_length(p.helix)
    if J is None:
        return beta * sigma / (2 * mu)  # (27)
    h = p.helix
    return np.float64(h.GJ_Nm2) / (np.float64(p.environment.g_m_s2) * h.length_m * J[0])
