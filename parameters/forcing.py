"""The forcing laws of the ends: the circle of Eq. (70) and the torque ramp of Eq. (69)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np


class EndForcing:
    """The boundary data of :class:`~rawehelix.parameters.normalised.Normalised`
    (its fields eps0, Gamma0, r1, omega1, phase0, mN0, t0, sigma)."""

    # -- boundary data ------------------------------------------------------
    def top_position(self, t: float = 0.0) -> np.ndarray:
        """r~(1, t~): Eq. (66), with the circle of Eq. (70) when r1 > 0."""
        c, s = math.cos(self.Gamma0), math.sin(self.Gamma0)
        a = 1.0 + self.eps0
        sw, cw = math.sin(self.phase(t)), math.cos(self.phase(t))
        r1 = self.r1
        return np.array([-(a * c + r1 * s * sw), r1 * cw, -(a * s - r1 * c * sw)])

    def phase(self, t: float) -> float:
        """omega1 t~ + phase0, the angle of the upper end on its circle, Eq. (70)."""
        return self.omega1 * t + self.phase0

    def at_frequency(self, f1_Hz: float, t_start: float = 0.0) -> "Normalised":
        """The same scene with the circle at f1, at phase 0 at time t~ = t_start.

        A sweep keeps time running (torque ramp, controller) and restarts the
        circle's phase at each new frequency, so the end does not jump."""
        omega1 = 2 * math.pi * f1_Hz * self.t_scale
        return dataclasses.replace(self, omega1=omega1, phase0=-omega1 * t_start)

    @property
    def moving_end(self) -> bool:
        """Does the upper end move on its circle (Eq. 70: R1 > 0 and f1 > 0)?"""
        return self.r1 > 0 and self.omega1 > 0

    def top_velocity(self, t: float = 0.0) -> np.ndarray:
        """d r~(1, t~)/dt~ of Eq. (70)."""
        c, s, w, r1 = math.cos(self.Gamma0), math.sin(self.Gamma0), self.omega1, self.r1
        cw, sw = math.cos(self.phase(t)), math.sin(self.phase(t))
        return r1 * w * np.array([-s * cw, -sw, c * cw])

    def top_acceleration(self, t: float = 0.0) -> np.ndarray:
        """d^2 r~(1, t~)/dt~^2 of Eq. (70)."""
        c, s, w, r1 = math.cos(self.Gamma0), math.sin(self.Gamma0), self.omega1, self.r1
        cw, sw = math.cos(self.phase(t)), math.sin(self.phase(t))
        return r1 * w**2 * np.array([s * sw, -cw, -c * sw])

    def top_torque(self, t: float) -> float:
        """m_N(t~) = m_N0 [1 - exp(-t~/t~0)], Eq. (69); m_N0 at all times if t~0 = 0
        (:meth:`steady_torque`)."""
        if self.t0 == 0:
            return self.mN0
        return self.mN0 * (1.0 - math.exp(-t / self.t0))

    def steady_torque(self) -> "Normalised":
        """The same scene with the torque ramp (69) at its final value m_N0 from t~ = 0
        (periodic orbits: the forcing must be periodic)."""
        return dataclasses.replace(self, t0=0.0)

    def top_torque_rate(self, t: float) -> float:
        """d m_N / dt~ of Eq. (69)."""
        return 0.0 if self.t0 == 0 else self.mN0 / self.t0 * math.exp(-t / self.t0)

    def top_torque_accel(self, t: float) -> float:
        """d^2 m_N / dt~^2 of Eq. (69)."""
        return 0.0 if self.t0 == 0 else -self.mN0 / self.t0**2 * math.exp(-t / self.t0)

    def chord_tension(self) -> float:
        """sigma eps0: the tension of the straight chord, normalised (Eq. 29)."""
        return self.sigma * self.eps0
