"""The rigid-shaft torque balance of an operating point: the rotor's aerodynamic torque
against the generator's and the helix's spin-drag loss, from the laws of operation/
(numpy only).

At a relative equilibrium without the helix's own distributed loss the twist moment is
constant along s (Eq. 31 with alpha_t uniform and no distributed torque), so the spin
Omega closes

    Q(Omega, V_n) - tau_gen(Omega) - L(Omega) = 0,

Q = 1/2 rho pi R^2 V_n^3 Cp(lambda) / Omega the rotor's torque at the wind V_n along its
axis, tau_gen the generator's, L the helix's integrated spin-drag loss (0 when off).
:class:`Drive` evaluates it, its slope in Omega (the rigid torsional mode's stiffness:
:func:`stable`) and every root in the rotor's table at one V_n.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import scipy.optimize

from rawehelix.errors import SolverError
from rawehelix.operation.rotor import OutOfTable

#: the roots are bracketed on this many spins between two adjacent rows of the table
SAMPLES = 64
#: the scalar Newton at fixed V_n stops at |G| below this (normalised torque)
TOL = 1e-12


class OutsideTable(SolverError):
    """The balance asked the rotor's table for a tip-speed ratio it does not have."""


@dataclasses.dataclass(frozen=True)
class Drive:
    """What turns the helix: the rotor's and the generator's laws (operation/rotor.py,
    operation/generator.py), the air density [kg/m^3] and the helix's spin-drag loss (an
    object with ``torque(Omega)`` and ``dtorque_domega(Omega)`` [N m], None: off)."""

    rotor: object  # operation.rotor.RotorLaw
    generator: object  # operation.generator.GeneratorLaw
    rho_kg_m3: float
    loss: object = None

    def __post_init__(self):
        if not self.rho_kg_m3 > 0:
            raise ValueError(f"Drive: air density {self.rho_kg_m3!r} must be > 0 kg/m^3")

    def held_speed(self) -> float | None:
        """The spin [rad/s] the generator holds (Eq. 40's integral action), or None."""
        return self.generator.holds_speed

    def loss_Nm(self, omega: float) -> float:
        return 0.0 if self.loss is None else float(self.loss.torque(omega))

    def rotor_torque(self, omega: float, v_n: float) -> float:
        """Q = 1/2 rho pi R^2 V_n^3 Cp(lambda) / Omega [N m] (the rotor's law); a ratio
        outside its table raises :class:`OutsideTable`."""
        try:
            return float(self.rotor.torque(omega, v_n, self.rho_kg_m3))
        except OutOfTable as err:
            raise OutsideTable(str(err)) from None

    def balance_Nm(self, omega: float, v_n: float) -> float:
        """Q - tau_gen - L [N m] at Omega [rad/s], V_n [m/s] (rigid shaft)."""
        return self.rotor_torque(omega, v_n) - self.generator.torque(omega) - self.loss_Nm(omega)

    def slope_Nm_s(self, omega: float, v_n: float) -> float:
        """d(Q - tau_gen - L)/dOmega [N m s]: the rigid torsional mode's stiffness, < 0
        where it is stable; the paper's law holding the speed contributes its speed gain
        K2 (operation/rigid_shaft.py)."""
        try:
            dQ = float(self.rotor.dtorque_domega(omega, v_n, self.rho_kg_m3))
        except OutOfTable as err:
            raise OutsideTable(str(err)) from None
        dL = 0.0 if self.loss is None else float(self.loss.dtorque_domega(omega))
        if self.held_speed() is not None:
            return dQ - dL - self.generator.K2
        return dQ - float(self.generator.dtorque_domega(omega)) - dL

    def roots(self, v_n: float) -> list[float]:
        """Every spin [rad/s] where the balance holds at V_n with its tip-speed ratio
        inside the table (a hair, ROUND_OFF, inside its ends), ascending: sign changes on
        SAMPLES spins between adjacent rows, each refined by Brent's method.  The held
        speed of a generator that holds one, where the table has it."""
        lam = self._table_tsr()
        R = self.rotor.radius_m
        held = self.held_speed()
        if held is not None:
            return [held] if lam[0] <= held * R / v_n <= lam[-1] else []
        w = np.unique(np.concatenate([np.linspace(a, b, SAMPLES + 1)
                                      for a, b in zip(lam[:-1], lam[1:])])) * v_n / R
        w = w[w > 0]
        g = (np.asarray(self.rotor.torque(w, v_n, self.rho_kg_m3), dtype=float)
             - np.asarray(self.generator.torque(w), dtype=float)
             - (0.0 if self.loss is None else np.asarray(self.loss.torque(w), dtype=float)))
        out = [float(x) for x, y in zip(w, g) if y == 0.0]
        out += [self.bracketed(w[k], w[k + 1], v_n)
                for k in np.flatnonzero(np.sign(g[:-1]) * np.sign(g[1:]) < 0)]
        return sorted(out)

    def _table_tsr(self) -> np.ndarray:
        """The table's tip-speed ratios, its ends moved a hair inside
        (operation/rotor.py's ROUND_OFF)."""
        return self.rotor.inner_tsr()

    def omega_range(self, v_n: float) -> tuple[float, float]:
        """The spins [rad/s] whose tip-speed ratios the table has at V_n (a hair inside)."""
        lam = self._table_tsr()
        return (float(lam[0] * v_n / self.rotor.radius_m),
                float(lam[-1] * v_n / self.rotor.radius_m))

    def bracketed(self, a: float, b: float, v_n: float) -> float:
        """The root of the balance at V_n between spins a and b where it changes sign
        (Brent's method, to round-off)."""
        return float(scipy.optimize.brentq(self.balance_Nm, a, b, args=(v_n,), xtol=1e-14,
                                           rtol=4 * np.finfo(float).eps))

    def root_near(self, omega: float, v_n: float) -> float:
        """The root of the balance at V_n nearest ``omega`` by Newton (the held speed for
        a generator that holds one); SolverError if it does not converge."""
        held = self.held_speed()
        if held is not None:
            self.rotor_torque(held, v_n)  # OutsideTable where the table has no such ratio
            return held
        x = omega
        for _ in range(50):
            g = self.balance_Nm(x, v_n)
            if abs(g) <= TOL * max(1.0, abs(self.rotor_torque(x, v_n))):
                return x
            step = g / self.slope_Nm_s(x, v_n)
            x = x - step
            if abs(step) <= 1e-15 * abs(x):
                return x
        raise SolverError(f"the torque balance at V_n = {v_n:.6g} m/s did not converge from "
                          f"{omega:.6g} rad/s")


def stable(slope_Nm_s: float, eigenvalues=None) -> bool:
    """Whether an operating point is stable: every eigenvalue of the linearisation
    about it in the left half plane where they are given (the full linearisation), else
    the rigid torsional mode's d(Q - tau_gen - L)/dOmega < 0."""
    if eigenvalues is not None and len(eigenvalues):
        return bool(np.all(np.real(eigenvalues) < 0))
    return bool(slope_Nm_s < 0)
