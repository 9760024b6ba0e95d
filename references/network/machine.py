"""The operating machine's ends on the network (issue 45 item 1): the rotor's torque
and spin inertia on the top ring, the generator's torque on the ground ring, and the
wind the rings' drag sees, from the scene's ``[rotor]``, ``[generator]`` and
``[wind]`` through operation/'s numpy laws (the tables, the MPPT or torque law, the
wind's profile and history).  SI units.

    Q(Omega, t) = 1/2 rho pi R^2 V_n^3 Cp(lambda) / Omega = 1/2 rho pi R^3 V_n^2 Cp(lambda) / lambda
    lambda = Omega R / V_n,  V_n = V_hub(t) n    (Eq. 39's driving torque)
    tau(Omega) = the generator's law at the ground's spin (Eq. 38)

n is the rotor's axis against the wind along the chord (``axis = "tangent"``: the top's
fixed direction, |e3 . i_E|), as the FE run has it.  A generator with a release speed
(``generator.release_rpm``) is off until the ground ring first spins at it, then
ramps in over operation.generator.RELEASE_RAMP_S.

:func:`operating_point` is the rigid shaft's balance Q(Omega) = tau(Omega), solved
here by scipy's brentq between the sign changes of Q - tau on the table's range: the
stable root (d(Q - tau)/dOmega < 0) of the fastest rotor, where a run starts.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.optimize import brentq

from rawehelix.operation import generator as generator_laws
from rawehelix.operation import rotor as rotor_laws
from rawehelix.operation import wind, wind_series
from rawehelix.parameters import end_components
from rawehelix.parameters.checks import ParameterError
from rawehelix.references.network.network import NetworkError

#: the relative step of the torques' derivatives by central differences
DIFFERENCE = 1e-7
#: spins sampled on the table's range to bracket the balance's roots
SAMPLES = 4000


@dataclass(frozen=True)
class RotorEnd:
    """The rotor on the top ring: its law (operation/rotor.py), the air's density
    [kg/m^3], V_n / V_hub [-] and the hub's wind in time, t [s] -> V_hub [m/s]."""

    law: object
    density_kg_m3: float
    normal: float
    hub_m_s: Callable[[float], float]

    @property
    def inertia_kgm2(self) -> float:
        return self.law.spin_inertia_kgm2

    def _q(self, omega: float, v_n: float) -> float:
        lam = omega * self.law.radius_m / v_n
        lo, hi = self.law.tsr_range
        if not lo <= lam <= hi:
            raise NetworkError(str(rotor_laws.OutOfTable(lam, lo, hi, v_n, omega)))
        lam = max(lam, hi * 1e-9)  # Cp / lambda, finite at rest through a table from tsr 0
        scale = 0.5 * self.density_kg_m3 * self.law.area_m2 * self.law.radius_m * v_n * v_n
        return scale * float(self.law.cp(lam)) / lam

    def torque(self, omega: float, t: float) -> tuple[float, float]:
        """(Q [N m], dQ/dOmega [N m s]) at the spin ``omega`` [rad/s] and time t [s]."""
        v_n = self.hub_m_s(t) * self.normal
        d = DIFFERENCE * max(1.0, abs(omega))
        up = min(omega + d, self.law.tsr_range[1] * v_n / self.law.radius_m)
        down = max(omega - d, self.law.tsr_range[0] * v_n / self.law.radius_m)
        return self._q(omega, v_n), (self._q(up, v_n) - self._q(down, v_n)) / (up - down)


@dataclass(frozen=True)
class GeneratorEnd:
    """The generator on the ground ring: its law (operation/generator.py)."""

    law: object

    @property
    def release_rad_s(self) -> float | None:
        return self.law.release_rad_s

    def torque(self, omega: float) -> tuple[float, float]:
        """(tau [N m], dtau/dOmega [N m s]) at the ground's spin [rad/s]."""
        return float(self.law.torque(omega)), float(self.law.dtorque_domega(omega))


def _rotor(params) -> dict:
    law = rotor_laws.from_params(params)
    history = wind_series.from_params(params)
    top = params.normalised().top_position(0.0)
    normal = float(law.normal_speed(1.0, top / np.linalg.norm(top)))
    return {"rotor": RotorEnd(law, wind.air_density(params), normal,
                              lambda t: float(history.hub(t)[0]))}


def _generator(params) -> dict:
    return {"generator": GeneratorEnd(generator_laws.from_params(params))}


#: the end components that put a torque on an end (parameters/end_components.py), by
#: name: the ramp (Eq. 69) and the controller (Eq. 40) are dynamics.Drive's own
LAWS = {"torque_ramp": lambda p: {}, "controller": lambda p: {}, "rotor": _rotor,
        "generator": _generator}


def ends_of(params) -> dict:
    """{"rotor": RotorEnd, "generator": GeneratorEnd} of the scene's active ones."""
    out = {}
    for component in end_components.torques(params):
        out.update(LAWS[component.name](params))
    return out


def wind_of(params, heights_m: np.ndarray) -> Callable[[float], np.ndarray] | None:
    """t [s] -> the wind's velocity at the rings' heights (rings, 3) [m/s] along -i_E
    (the along-wind part u of the scene's history: its lateral and vertical parts are
    left out), or None where the wind is steady (the network's own)."""
    history = wind_series.moving(params)
    if history is None:
        return None
    z = np.asarray(heights_m, dtype=float)
    return lambda t: np.outer(-np.asarray(history.along(t, z), dtype=float), [1.0, 0.0, 0.0])


def operating_point(rotor: RotorEnd, generator: GeneratorEnd | None, t: float = 0.0,
                    holds_rad_s: float | None = None) -> float:
    """Omega [rad/s] of the rigid shaft's balance Q = tau at the time t: the stable
    root of the fastest rotor (module docstring), or ``holds_rad_s`` (the paper's
    Eq. 40 holds its target)."""
    if holds_rad_s is not None:
        return holds_rad_s
    v_n = rotor.hub_m_s(t) * rotor.normal
    lo, hi = (x * v_n / rotor.law.radius_m * (1 + s * 1e-9)
              for x, s in zip(rotor.law.tsr_range, (1, -1)))
    lo = max(lo, hi * 1e-6)

    def balance(omega):
        tau = generator.law.torque(omega) if generator is not None else 0.0
        lam = np.asarray(omega) * rotor.law.radius_m / v_n
        scale = 0.5 * rotor.density_kg_m3 * rotor.law.area_m2 * rotor.law.radius_m * v_n * v_n
        return scale * rotor.law.cp(lam) / lam - tau

    omegas = np.linspace(lo, hi, SAMPLES)
    values = balance(omegas)
    falling = np.nonzero((values[:-1] > 0) & (values[1:] <= 0))[0]  # stable: Q - tau falls
    if not falling.size:  # the scene asks for what its rotor cannot do: bad input
        raise ParameterError("wind.speed_m_s", rotor.hub_m_s(t),
                             "the rotor has no stable operating point at this hub wind inside "
                             "its table against the generator: choose a wind speed (or a "
                             "generator law) whose operating point the table covers")
    i = falling[-1]
    return float(brentq(lambda w: float(balance(w)), omegas[i], omegas[i + 1], xtol=1e-14,
                        rtol=1e-15))


def spin_kick(spin: float, inertia: float, h: float, torque: Callable, implicit: bool) -> float:
    """An end ring's spin after a half-kick of h: J (s' - s) = h T(s*), s* the start's
    spin (explicit) or the end's (implicit: Newton on s'); ``torque(s)`` -> (T, dT/ds)."""
    if not implicit:
        return spin + h * torque(spin)[0] / inertia
    s = spin + h * torque(spin)[0] / inertia
    for _ in range(50):
        T, dT = torque(s)
        step = (s - spin - h * T / inertia) / (1 - h * dT / inertia)
        s -= step
        if abs(step) <= 1e-14 * (1 + abs(s)):
            return s
    raise NetworkError("the network's end spin half-step did not converge: lower time.dt_s")


__all__ = ["GeneratorEnd", "RotorEnd", "ends_of", "operating_point", "spin_kick", "wind_of"]
