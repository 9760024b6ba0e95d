"""The generator at the ground end: its resisting torque tau(Omega) [N m] (issue 43).

The laws, by the name a scene gives (``generator.law``, :data:`LAWS`):

* ``"mppt"`` (:class:`Mppt`): tau = k Omega^2 (k = mppt_gain_Nms2 [N m s^2]): at
  k = 1/2 rho pi R^5 Cp_max / tsr_opt^3 the rotor runs at its best tip-speed ratio at
  every wind;
* ``"torque"`` (:class:`TorqueTable`): a constant torque, or a table tau(rpm)
  (piecewise linear between its rows, its last row's torque beyond them; its first
  row is at 0 rpm);
* ``"paper"`` (:class:`PaperLaw`): Eq. (40), the [controller]'s ground torque
  m0 = k1 (alpha - alpha_dot* t) + k2 alpha_t (+ C): with k1 > 0 its integral action
  holds Omega at the target spin alpha_dot* at any relative equilibrium
  (:attr:`GeneratorLaw.holds_speed`), its torque whatever balances the rotor's; with
  k1 = 0 it is the damper tau = K2 Omega (C, the constant of its start, left out).

``rated_power_W`` (mppt, torque): above the rated power the generator holds it,
tau = P_rated / Omega.  Omega [rad/s] >= 0 (the rotor's sense); K1 = k1 GJ/L0
[N m/rad] and K2 = k2 (GJ/L0) sqrt(L0/g) [N m s/rad] are Eq. (40)'s gains in SI
(parameters/normalised.py's scales).
"""

from __future__ import annotations

import math

import numpy as np

RPM = 2.0 * math.pi / 60.0  # rad/s per rpm


class GeneratorLaw:
    """tau(Omega) [N m] and its derivative, with the rated power's cap; each law is a
    subclass (module docstring) giving :meth:`_law`."""

    name = ""
    holds_speed: float | None = None  # the speed [rad/s] it holds, or None (a function of Omega)

    def __init__(self, rated_power_W: float | None = None):
        if rated_power_W is not None and not (rated_power_W > 0 and math.isfinite(rated_power_W)):
            raise ValueError(f"rated_power_W = {rated_power_W!r} must be a finite number > 0")
        self.rated_power_W = rated_power_W

    def __repr__(self):
        return f"{type(self).__name__}(rated {self.rated_power_W} W)"

    def _law(self, omega: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(tau, dtau/dOmega) of the law before the rated cap."""
        raise NotImplementedError

    def _capped(self, omega) -> tuple[np.ndarray, np.ndarray]:
        omega = np.asarray(omega, float)
        tau, slope = self._law(omega)
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


class Mppt(GeneratorLaw):
    """tau = k Omega |Omega|."""

    name = "mppt"

    def __init__(self, mppt_gain_Nms2: float, rated_power_W: float | None = None):
        super().__init__(rated_power_W)
        if not (mppt_gain_Nms2 > 0 and math.isfinite(mppt_gain_Nms2)):
            raise ValueError(f"mppt_gain_Nms2 = {mppt_gain_Nms2!r} must be a finite number > 0")
        self.k = float(mppt_gain_Nms2)

    def _law(self, omega):
        return self.k * omega * np.abs(omega), 2 * self.k * np.abs(omega)

    @classmethod
    def from_section(cls, g, params):
        return cls(g.mppt_gain_Nms2, g.rated_power_W)


class TorqueTable(GeneratorLaw):
    """A constant torque, or tau(rpm) piecewise linear from 0 rpm, its last torque beyond."""

    name = "torque"

    def __init__(self, torque_Nm: float = 0.0, table_rpm=(), table_torque_Nm=(),
                 rated_power_W: float | None = None):
        super().__init__(rated_power_W)
        self.constant_Nm = float(torque_Nm)
        self.table_omega = np.asarray(table_rpm, float) * RPM
        self.table_torque = np.asarray(table_torque_Nm, float)
        if self.table_omega.shape != self.table_torque.shape or self.table_omega.size == 1:
            raise ValueError("a torque table needs equal columns of at least 2 rows")

    def _law(self, omega):
        if self.table_omega.size == 0:
            return np.full_like(omega, self.constant_Nm), np.zeros_like(omega)
        x, y = self.table_omega, self.table_torque
        tau = np.interp(omega, x, y)  # its last row's torque beyond the table
        i = np.clip(np.searchsorted(x, omega, side="right") - 1, 0, len(x) - 2)
        slope = np.where(omega >= x[-1], 0.0, (y[i + 1] - y[i]) / (x[i + 1] - x[i]))
        return tau, slope

    @classmethod
    def from_section(cls, g, params):
        return cls(g.torque_Nm, g.speeds_rpm or (), g.torques_Nm or (), g.rated_power_W)


class PaperLaw(GeneratorLaw):
    """Eq. (40) at a relative equilibrium: the target spin held (K1 > 0), K2 its speed gain."""

    name = "paper"

    def __init__(self, target_rad_s: float, integral_Nm: float, damping_Nms: float = 0.0):
        super().__init__(None)
        self.target_rad_s, self.K1, self.K2 = float(target_rad_s), float(integral_Nm), float(damping_Nms)

    @property
    def holds_speed(self) -> float | None:
        """The speed [rad/s] its integral action holds (K1 > 0), else None."""
        return self.target_rad_s if self.K1 > 0 else None

    def _law(self, omega):
        if self.holds_speed is not None:
            raise ValueError("the paper's generator law (Eq. 40, controller.k1 > 0) holds the "
                             "rotor at its target spin: its torque is whatever balances the "
                             "rotor's, not a function of the speed (holds_speed)")
        return self.K2 * omega, np.full_like(omega, self.K2)

    @classmethod
    def from_section(cls, g, params):
        """None with the controller off: no generator torque at the ground."""
        c = params.controller
        if not c.active:
            return None
        L0, g_ = params.helix.length_m, params.environment.g_m_s2
        torque_scale, t_scale = params.helix.GJ_Nm2 / L0, math.sqrt(L0 / g_)  # Eqs. 25, 38
        return cls(c.target_rpm * RPM, c.k1 * torque_scale, c.k2 * torque_scale * t_scale)


#: the generator laws by the name a scene gives (generator.law)
LAWS = {law.name: law for law in (PaperLaw, Mppt, TorqueTable)}
NAMES = tuple(LAWS)


def from_params(params) -> GeneratorLaw | None:
    """The generator of a scene (its ``[generator]``, and ``[controller]`` for the paper's
    law); None when the ground carries no generator torque (the paper's law with the
    controller off)."""
    g = params.generator
    return LAWS[g.law].from_section(g, params)
