"""The generator at the ground end: its resisting torque tau(Omega) [N m] (issue 43).

* ``"mppt"``: tau = k Omega^2 (k = mppt_gain_Nms2 [N m s^2]): at k = 1/2 rho pi R^5
  Cp_max / tsr_opt^3 the rotor runs at its best tip-speed ratio at every wind;
* ``"torque"``: a constant torque, or a table tau(rpm) (piecewise linear between its
  rows, its last row's torque beyond them; its first row is at 0 rpm);
* ``"paper"``: Eq. (40), the [controller]'s ground torque m0 = k1 (alpha - alpha_dot* t)
  + k2 alpha_t (+ C): with k1 > 0 its integral action holds Omega at the target spin
  alpha_dot* at any relative equilibrium (:attr:`GeneratorLaw.holds_speed`), its torque
  whatever balances the rotor's; with k1 = 0 it is the damper tau = K2 Omega (C, the
  constant of its start, left out).
* ``rated_power_W`` (mppt, torque): above the rated power the generator holds it,
  tau = P_rated / Omega.

Omega [rad/s] >= 0 (the rotor's sense); K1 = k1 GJ/L0 [N m/rad] and K2 = k2 (GJ/L0)
sqrt(L0/g) [N m s/rad] are Eq. (40)'s gains in SI (parameters/normalised.py's scales).
Each law is a function of :data:`TORQUES`, chosen by its name once, in the constructor.
"""

from __future__ import annotations

import math

import numpy as np

RPM = 2.0 * math.pi / 60.0  # rad/s per rpm
#: a released generator's torque ramps in linearly over this time (a soft start: the
#: torque is continuous in time, so the steps and the energy account's trapezoids stay
#: second order through the release) [s]
RELEASE_RAMP_S = 0.5


def _mppt(g, omega):
    """k Omega |Omega| and its derivative."""
    return g.k * omega * np.abs(omega), 2 * g.k * np.abs(omega)


def _torque(g, omega):
    """The constant torque, or the table piecewise linear, flat past its last row."""
    if g.table_omega.size == 0:
        return np.full_like(omega, g.constant_Nm), np.zeros_like(omega)
    x, y = g.table_omega, g.table_torque
    tau = np.interp(omega, x, y)
    i = np.clip(np.searchsorted(x, omega, side="right") - 1, 0, len(x) - 2)
    slope = np.where(omega >= x[-1], 0.0, (y[i + 1] - y[i]) / (x[i + 1] - x[i]))
    return tau, slope


def _paper(g, omega):
    """Eq. (40) without its integral action (k1 = 0): the damper K2 Omega."""
    if g.holds_speed is not None:
        raise ValueError("the paper's generator law (Eq. 40, controller.k1 > 0) holds the "
                         "rotor at its target spin: its torque is whatever balances the "
                         "rotor's, not a function of the speed (holds_speed)")
    return g.K2 * omega, np.full_like(omega, g.K2)


#: tau(Omega) and dtau/dOmega before the rated cap, by the law's name (generator.law)
TORQUES = {"paper": _paper, "mppt": _mppt, "torque": _torque}
#: the laws' names
LAWS = tuple(TORQUES)
#: the laws whose integral action holds a speed (Eq. 40's k1 > 0)
HOLDS = {"paper": lambda g: g.target_rad_s if g.K1 > 0 else None}


class GeneratorLaw:
    """tau(Omega) of one of :data:`LAWS` (module docstring); every attribute is set
    whatever the law (0 or empty where it does not read it)."""

    def __init__(self, law: str, mppt_gain_Nms2: float = 0.0, torque_Nm: float = 0.0,
                 table_rpm=(), table_torque_Nm=(), rated_power_W: float | None = None,
                 target_rad_s: float = 0.0, integral_Nm: float = 0.0, damping_Nms: float = 0.0,
                 release_rad_s: float | None = None):
        if law not in TORQUES:
            raise ValueError(f"generator law {law!r} must be one of {LAWS}")
        if rated_power_W is not None and not (rated_power_W > 0 and math.isfinite(rated_power_W)):
            raise ValueError(f"rated_power_W = {rated_power_W!r} must be a finite number > 0")
        self.law, self._law = law, TORQUES[law]
        self.k, self.constant_Nm = float(mppt_gain_Nms2), float(torque_Nm)
        self.table_omega = np.asarray(table_rpm, float) * RPM
        self.table_torque = np.asarray(table_torque_Nm, float)
        if self.table_omega.shape != self.table_torque.shape or self.table_omega.size == 1:
            raise ValueError("a torque table needs two columns of equal length, 2 rows at least")
        self.rated_power_W = rated_power_W
        self.target_rad_s, self.K1 = float(target_rad_s), float(integral_Nm)
        self.K2 = float(damping_Nms)
        # a start-up's release speed (the torque is zero until the ground first spins at
        # it, then ramps in over RELEASE_RAMP_S: solvers/release.py); None: on from the start
        self.release_rad_s = release_rad_s

    def __repr__(self):
        return f"GeneratorLaw({self.law!r}, rated {self.rated_power_W} W)"

    @property
    def holds_speed(self) -> float | None:
        """The speed [rad/s] the paper's law holds at a relative equilibrium (its
        integral action, k1 > 0), or None: the torque is a function of Omega."""
        return HOLDS.get(self.law, lambda g: None)(self)

    def _capped(self, omega) -> tuple[np.ndarray, np.ndarray]:
        omega = np.asarray(omega, float)
        tau, slope = self._law(self, omega)
        if self.rated_power_W is None:
            return tau, slope
        with np.errstate(divide="ignore"):
            cap = self.rated_power_W / omega
        over = (omega > 0) & (tau * omega > self.rated_power_W)
        return (np.where(over, cap, tau),
                np.where(over, -self.rated_power_W / np.where(omega > 0, omega, 1.0) ** 2, slope))

    def torque(self, omega):
        """tau(Omega) [N m]."""
        return self._capped(omega)[0]

    def dtorque_domega(self, omega):
        """dtau/dOmega [N m s] (one-sided, the upper, at a kink)."""
        return self._capped(omega)[1]

    def power(self, omega):
        """tau Omega [W]."""
        return self.torque(omega) * np.asarray(omega, float)


def _paper_of(g, params) -> GeneratorLaw | None:
    """Eq. (40) in SI from [controller]; None with the controller off."""
    c = params.controller
    if not c.active:
        return None
    L0, g_ = params.helix.length_m, params.environment.g_m_s2
    torque_scale, t_scale = params.helix.GJ_Nm2 / L0, math.sqrt(L0 / g_)  # Eqs. 25, 38
    return GeneratorLaw("paper", target_rad_s=c.target_rpm * RPM, integral_Nm=c.k1 * torque_scale,
                        damping_Nms=c.k2 * torque_scale * t_scale)


def _own_of(g, params) -> GeneratorLaw:
    return GeneratorLaw(g.law, mppt_gain_Nms2=g.mppt_gain_Nms2, torque_Nm=g.torque_Nm,
                        table_rpm=g.speeds_rpm or (), table_torque_Nm=g.torques_Nm or (),
                        rated_power_W=g.rated_power_W,
                        release_rad_s=None if g.release_rpm is None else g.release_rpm * RPM)


#: how a scene's [generator] (and [controller]) builds each law
FROM_SECTION = {"paper": _paper_of, "mppt": _own_of, "torque": _own_of}


def from_params(params) -> GeneratorLaw | None:
    """The generator of a scene (its ``[generator]``, and ``[controller]`` for the paper's
    law); None when the ground carries no generator torque (the paper's law with the
    controller off)."""
    return FROM_SECTION[params.generator.law](params.generator, params)
