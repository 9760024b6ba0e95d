"""Small stand-ins for the rotor's and the generator's laws (operation/, i43-rotor's)
used by the operating-point tests: a piecewise-linear Cp/CT table and the MPPT and
constant-torque generators, written from the issue's formulas alone."""

from __future__ import annotations

import math

import numpy as np


class OutOfTable(ValueError):
    pass


class TableRotor:
    """Q = 1/2 rho pi R^2 V_n^3 Cp(lambda) / Omega, lambda = Omega R / V_n; Cp and CT
    piecewise linear in the table."""

    def __init__(self, tsr, cp, ct, radius_m=1.0, spin_inertia_kgm2=2.0):
        self.tsr, self.cp_table, self.ct_table = (np.asarray(x, float) for x in (tsr, cp, ct))
        self.radius_m, self.spin_inertia_kgm2 = radius_m, spin_inertia_kgm2

    def _in(self, lam, omega, v_n):
        if not self.tsr[0] <= lam <= self.tsr[-1]:
            raise OutOfTable(f"tsr {lam:g} at V_n = {v_n:g} m/s, {omega:g} rad/s")

    def tsr_of(self, omega, v_n):
        return omega * self.radius_m / v_n

    def cp(self, lam):
        return float(np.interp(lam, self.tsr, self.cp_table))

    def torque(self, omega, v_n, rho):
        lam = self.tsr_of(omega, v_n)
        self._in(lam, omega, v_n)
        return 0.5 * rho * math.pi * self.radius_m**2 * v_n**3 * self.cp(lam) / omega

    def dtorque_domega(self, omega, v_n, rho):
        h = 1e-7 * omega
        return (self.torque(omega + h, v_n, rho) - self.torque(omega - h, v_n, rho)) / (2 * h)

    def thrust(self, omega, v_n, rho):
        lam = self.tsr_of(omega, v_n)
        self._in(lam, omega, v_n)
        return 0.5 * rho * math.pi * self.radius_m**2 * v_n**2 * float(
            np.interp(lam, self.tsr, self.ct_table))


class Mppt:
    def __init__(self, k):
        self.k = k
        self.holds_speed = None

    def torque(self, omega):
        return self.k * omega**2

    def dtorque_domega(self, omega):
        return 2 * self.k * omega


class ConstantTorque:
    def __init__(self, torque_Nm):
        self.torque_Nm = torque_Nm
        self.holds_speed = None

    def torque(self, omega):
        return self.torque_Nm

    def dtorque_domega(self, omega):
        return 0.0


def hump(lam_opt=5.0, cp_max=0.4, n=41):
    """A Cp table peaked at lam_opt: cp_max (2 x - x^2) on x = lam / lam_opt in (0, 2),
    sampled at n ratios (piecewise linear between them)."""
    x = np.linspace(0.05, 1.95, n)
    lam = x * lam_opt
    cp = cp_max * (2 * x - x**2)
    return lam, cp, 0.8 * x / (1 + x)
