"""The end torques of a dynamic run as UFL expressions of the state, one per end
component that puts a torque on an end (parameters/end_components.py::torques):

* ``torque_ramp`` (Eq. 69) at the top: the constant c.mN that set_time sets;
* ``controller`` (Eq. 40, integrated) at the ground: ts_forms.controller_torque;
* ``rotor`` at the top: Q(alpha_t(1)) - J alpha_tt(1), the aerodynamic torque of its
  table at the hub's wind and its spin inertia (forms/end_torques.py);
* ``generator`` at the ground: tau(alpha_t(0)) (MPPT, constant or tabulated torque,
  rated-power cap); off at ``law = "paper"``, which is the controller's Eq. (40).

:func:`machine_of` takes the active ones' numpy laws (operation/) through :data:`LAWS`,
the registry's half here; :class:`EndTorques` makes their UFL torques.  Without a rotor
and a generator (their null objects) the formulation keeps the paper's forms untouched
(``Machine.active`` False), bit for bit.

All normalised (Eqs. 25-29): torques by GJ / L0, spins by 1 / t_scale, powers by
M g L0 / t_scale, energies by M g L0."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import ufl

from rawehelix.forms import end_torques as forms
from rawehelix.operation import generator as generator_laws, rotor as rotor_laws, wind, wind_series
from rawehelix.parameters import end_components


class WindBelowRotor(ValueError):
    """The wind along the rotor's axis at the hub fell to zero or reversed in a run."""


@dataclass(frozen=True)
class Machine:
    """The rotor and the generator of a run, as numpy laws (operation/) and the hub's
    wind: what :class:`EndTorques` normalises.  ``rotor`` or ``generator`` None: off."""

    rotor: Any = None  # operation.rotor.RotorLaw: cp, tsr, radius_m, spin_inertia_kgm2, ...
    generator: Any = None  # operation.generator.GeneratorLaw
    wind_n_m_s: float = 0.0  # V_n, the wind along the rotor's axis at the hub [m/s]
    air_density_kg_m3: float = 1.225
    wind_hub_m_s: float = 0.0  # V, the wind's speed at the hub [m/s]
    # the wind in time (operation/wind_series.WindHistory, issue 44); None: steady, the
    # winds above at every time
    history: Any = None
    normal_factor: float = 1.0  # V_n / V: the rotor's axis against the wind (-i_E) [-]

    def __post_init__(self):
        if self.rotor is not None and not (self.wind_n_m_s > 0 and math.isfinite(self.wind_n_m_s)):
            raise WindBelowRotor(
                f"the wind along the rotor's axis is {self.wind_n_m_s:.3g} m/s at the hub "
                f"(V = {self.wind_hub_m_s:.3g} m/s): the rotor's table (tip-speed ratio "
                f"Omega R / V_n) has no such wind")
        if not self.air_density_kg_m3 > 0:
            raise ValueError(f"Machine: air density {self.air_density_kg_m3!r} must be > 0")

    @property
    def active(self) -> bool:
        return self.rotor is not None or self.generator is not None

    def in_wind(self, v_m_s: float) -> "Machine":
        """The machine with V = ``v_m_s`` [m/s] at the hub and V_n = V normal_factor; a
        rotor's V_n at or below zero is :class:`WindBelowRotor` (__post_init__)."""
        return dataclasses.replace(self, wind_hub_m_s=v_m_s, wind_n_m_s=v_m_s * self.normal_factor)

    def at(self, t_s: float) -> "Machine":
        """The machine in the wind at the time ``t_s`` [s] (:meth:`in_wind`): the
        along-wind component u of the history at the hub (its lateral and vertical parts
        load the helix's drag only); turbulence reversing it is :class:`WindBelowRotor`."""
        if self.history is None:
            return self
        return self.in_wind(self.history.hub_u(t_s))

    def thrust_N(self, omega_rad_s: float) -> float:
        """The rotor's thrust at Omega [N] (0 without a rotor); its tip-speed ratio out of
        the table raises operation.rotor.OutOfTable, naming the wind and rotor speeds."""
        if self.rotor is None:
            return 0.0
        return float(self.rotor.thrust(omega_rad_s, self.wind_n_m_s, self.air_density_kg_m3))


def rotor_scales(machine: Machine, q) -> tuple[float, float]:
    """(1/2 rho pi R^2 V_n^3 t_scale / (GJ / L0), R / (V_n t_scale)): the rotor's torque's
    two numbers at the machine's wind, normalised (forms.RotorTorque)."""
    law, v = machine.rotor, machine.wind_n_m_s
    power = 0.5 * machine.air_density_kg_m3 * math.pi * law.radius_m**2 * v**3  # [W]
    return power * q.t_scale / q.torque_scale, law.radius_m / (v * q.t_scale)


def rotor_torque(machine: Machine, q) -> forms.RotorTorque:
    """Q(omega~) of the machine's rotor, normalised (forms/end_torques.py), with its
    thrust's CT(lambda) (the lifted top's end force)."""
    law = machine.rotor
    return forms.RotorTorque(cp_polynomial(law), *rotor_scales(machine, q),
                             ct=forms.PiecewisePolynomial.fit(law.ct, law.table_tsr, 3),
                             thrust_scale=q.torque_scale / (law.radius_m * q.force_scale))


def cp_polynomial(law) -> forms.PiecewisePolynomial:
    """Cp(lambda) of a rotor law as the piecewise cubic that reproduces its interpolation
    (operation/rotor.py: monotone cubic between its table's rows)."""
    return forms.PiecewisePolynomial.fit(law.cp, law.table_tsr, 3)


def rotor_inertia(machine: Machine, q) -> float:
    """j = J L0 / (GJ t_scale^2): the rotor's spin inertia, normalised like -J alpha_tt
    in the top's torque (Eq. 39)."""
    return machine.rotor.spin_inertia_kgm2 / (q.torque_scale * q.t_scale**2)


def generator_torque(machine: Machine, q) -> forms.GeneratorTorque:
    """tau(omega~) of the machine's generator law (operation/generator.py: MPPT k Omega
    |Omega|, a constant or tabulated torque held at its last row beyond it, the rated
    cap), normalised."""
    law = machine.generator
    T, Mq = q.t_scale, q.torque_scale
    rated = law.rated_power_W
    table = None
    if len(law.table_omega):  # its last row's torque beyond the table: one flat piece more
        x, y = np.asarray(law.table_omega, float), np.asarray(law.table_torque, float)
        x, y = np.append(x, x[-1] + max(1.0, x[-1])), np.append(y, y[-1])
        table = forms.PiecewisePolynomial.linear(x, y).scaled(T, 1 / Mq)
    return forms.GeneratorTorque(gain=law.k / (T**2 * Mq), constant=law.constant_Nm / Mq,
                                 table=table, rated=None if rated is None else rated * T / Mq)


@dataclass
class EndTorques:
    """The machine's torques at s = 0 (``ground``) and s = 1 (``top``) of a
    formulation, normalised (built once: :meth:`of`)."""

    machine: Machine = field(default_factory=Machine)
    rotor: forms.RotorTorque | None = None
    inertia: float = 0.0  # j, normalised
    generator: forms.GeneratorTorque | None = None

    @classmethod
    def of(cls, q, machine: Machine) -> "EndTorques":
        out = cls(machine)
        if machine.rotor is not None:
            out.rotor, out.inertia = rotor_torque(machine, q), rotor_inertia(machine, q)
        if machine.generator is not None:
            out.generator = generator_torque(machine, q)
        return out

    def driving(self, c, fields, time):
        """The top's driving torque: the ramp's c.mN (Eq. 69) + the rotor's Q(alpha_t)
        (a law of the spin; forms.RampTorque: of the time)."""
        return c.mN if self.rotor is None else c.mN + self.rotor(fields.alpha_t, time)

    def thrust(self, fields):
        """The rotor's thrust at the top's spin alpha_t [M g] (0 without a rotor)."""
        return 0.0 if self.rotor is None else self.rotor.thrust(fields.alpha_t)

    def given(self, c, fields, time):
        """The part of the top's torque that is a given function of time, m_N(t) of the
        paper (the ramp, and a rotor's law of time): what Eq. (40) feeds forward."""
        if self.rotor is None or not self.rotor.given_in_time:
            return c.mN
        return self.driving(c, fields, time)

    def top(self, c, fields, time):
        """The top's torque (Eq. 39): the driving torque - J alpha_tt (the rotor's inertia)."""
        if self.rotor is None:
            return self.driving(c, fields, time)
        return self.driving(c, fields, time) + forms.lumped_inertia(self.inertia, fields.alpha_tt)

    def ground(self, fields, paper):
        """The ground's torque (Eq. 38): the generator's law, or ``paper``, Eq. (40)'s
        (ts_forms.controller_torque), where it holds a speed or there is none."""
        return paper if self.generator is None else self.generator(fields.alpha_t)


def machine_of(params) -> Machine:
    """The scene's machine: the laws (operation/) of its active end components that
    put a torque on an end (parameters/end_components.py::torques, through
    :data:`LAWS`), the wind at the hub along the rotor's axis (the chord's direction for
    ``axis = "tangent"``, the fixed top's) and the air's density."""
    laws = {}
    for component in end_components.torques(params):
        laws.update(LAWS[component.name](params))
    rotor = laws.get("rotor")
    history = wind_series.moving(params)  # None: a steady wind
    v_hub = wind.from_params(params).hub_speed if history is None else float(history.hub(0.0)[0])
    if rotor is None:
        return Machine(generator=laws.get("generator"), wind_hub_m_s=v_hub, history=history)
    top = params.normalised().top_position(0.0)
    factor = float(rotor.normal_speed(1.0, top / np.linalg.norm(top)))
    return Machine(rotor, laws.get("generator"), v_hub * factor, wind.air_density(params), v_hub,
                   history, factor)


def _rotor_law(params) -> dict:
    return {"rotor": rotor_laws.from_params(params)}


def _generator_law(params) -> dict:
    return {"generator": generator_laws.from_params(params)}


#: the laws of the end components that load an end with a torque, by the registry's
#: name: the ramp (Eq. 69, c.mN) and the controller (Eq. 40) are the forms' own
LAWS = {"torque_ramp": lambda p: {}, "controller": lambda p: {}, "rotor": _rotor_law,
        "generator": _generator_law}


def end_weights(mesh):
    """(top, ground): UFL indicators of s = 1 and s = 0 on the end facets, which keep
    each end's law off the other end (Q / alpha_t is singular at a ground at rest)."""
    x = ufl.SpatialCoordinate(mesh)[0]
    return ufl.gt(x, 0.5), ufl.lt(x, 0.5)


__all__ = ["EndTorques", "LAWS", "Machine", "cp_polynomial", "end_weights", "generator_torque",
           "machine_of", "rotor_inertia", "rotor_scales", "rotor_torque"]
