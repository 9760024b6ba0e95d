"""The wind in time in a dynamic run (issue 44): the helix's drag and the rotor take
the scene's wind history (operation/wind_series.WindHistory) at each time.

* the drag (Eq. 14) at each point's height: forms/wind.MovingWind, whose V_ref(t),
  G(t) and u', v', w' at the history's heights are Constants;
* the rotor (forms/end_torques.RotorTorque): its 1/2 rho pi R^2 V_n^3 and R / V_n
  Constants, V_n the along-wind u at the hub times the axis' factor (Machine.at).

:class:`Weather` sets them all at a time; the formulation calls it from set_time, so
every residual, Jacobian and energy evaluation (the energy account sets the step's own
time) sees the wind of its own time.  The drag's power int F_A . r_t is the helix's
exchange with the moving air, in the energy account's drag term (dissipation, or work
in when a gust pushes the helix): nothing else changes in the balance.

All normalised: speeds by sqrt(g L0) = L0 / t_scale, heights by L0."""

from __future__ import annotations

import dataclasses

import numpy as np
from petsc4py import PETSc

import dolfinx.fem

from rawehelix.forms.wind import MovingWind
from rawehelix.solvers import release
from rawehelix.solvers.end_torques import EndTorques, Machine, rotor_scales


#: V_n / V_n(0) for a wind along the rotor's axis at or below zero [-]
NO_WIND = 1e-9


class Weather:
    """The wind's Constants of one formulation and how to set them at a time."""

    def __init__(self, machine: Machine, q, mesh, steady):
        self.machine, self.q = machine, q
        history = machine.history
        self.speed_scale = q.L0 / q.t_scale  # sqrt(g L0) [m/s]

        def constant(value):
            return dolfinx.fem.Constant(mesh, np.asarray(value, dtype=PETSc.ScalarType))
        m = len(history.heights_m)
        self.wind = MovingWind(steady, np.asarray(history.heights_m) / q.L0, constant(0.0),
                               constant(0.0), constant(np.zeros((m, 3))))
        self._rotor = None
        if machine.rotor is not None:
            self._rotor = (constant(0.0), constant(0.0))  # power_n, lam_per_omega
            # the two at the machine's V_n: power ~ V_n^3, lam_per_omega ~ 1 / V_n
            self._scales0 = rotor_scales(machine, q), machine.wind_n_m_s
        self(0.0)

    def install(self, c, ends: EndTorques):
        """(the coefficients with the moving wind, the end torques with the rotor's
        wind as Constants)."""
        c = dataclasses.replace(c, wind=self.wind)
        if self._rotor is not None:
            ends = dataclasses.replace(ends, rotor=dataclasses.replace(
                ends.rotor, power_n=self._rotor[0], lam_per_omega=self._rotor[1]))
        return c, ends

    def __call__(self, t: float):
        """Set the wind of the normalised time ``t``."""
        t_s = float(self.q.time_s(t))
        reference, gust, fluctuation = self.machine.history.parts(t_s)
        w = self.wind
        w.reference.value = reference / self.speed_scale
        w.gust.value = gust / self.speed_scale
        w.fluctuation.value[:] = fluctuation / self.speed_scale
        if self._rotor is not None:  # Machine.at(t_s)'s V_n, without a new Machine
            (power, lam), v0 = self._scales0
            hub = self.machine.history.hub_of(reference, gust, fluctuation)
            # the wind along the axis at or below zero (turbulence reversing it): the
            # step runs with no wind on the rotor (lambda -> infinity, past the table's
            # end) and studies/machine.py's check after it stops the run with its time
            ratio = max(hub * self.machine.normal_factor / v0, NO_WIND)
            self._rotor[0].value, self._rotor[1].value = power * ratio**3, lam / ratio


def of(machine: Machine, q, mesh, steady) -> Weather | None:
    """The run's weather, or None in a steady wind (the forms unchanged)."""
    return None if machine.history is None else Weather(machine, q, mesh, steady)


def install(machine: Machine, q, rod, ends: EndTorques):
    """(weather, release, end torques) of a dynamic run on ``rod``: the wind in time
    (the rod's coefficients then take its MovingWind) and a start-up's generator
    release (solvers/release.py), each None when off; both set at each time."""
    moving = of(machine, q, rod.mesh, rod.c.wind)
    if moving is not None:
        rod.c, ends = moving.install(rod.c, ends)
    latch = release.of(machine, q, rod.mesh)
    if latch is not None:
        ends = latch.install(ends)
    return moving, latch, ends


__all__ = ["Weather", "install", "of"]
