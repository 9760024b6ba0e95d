"""A start-up's generator release (issue 44, ``generator.release_rpm``): the ground's
torque is zero until the ground end first spins at the release speed, then ramps in
linearly over operation/generator.RELEASE_RAMP_S (a soft start), and stays on.

The latch is explicit in time: after each accepted step (:meth:`Release.latch`) the
ground's spin is compared with the release speed; the ramp starts at that step's
time, so the step that crossed it ran unloaded and every later residual and energy
evaluation reads the ramp at its own time (set_time: :meth:`Release.__call__`).
Normalised: spins by 1 / t_scale, times by t_scale."""

from __future__ import annotations

import dataclasses

import numpy as np
from petsc4py import PETSc

import dolfinx.fem

from rawehelix.operation.generator import RELEASE_RAMP_S
from rawehelix.solvers.end_torques import EndTorques, Machine


class Release:
    """The engaged fraction of the generator's torque, a Constant, and its latch."""

    def __init__(self, machine: Machine, q, mesh):
        self.q = q
        self.spin = machine.generator.release_rad_s * q.t_scale  # normalised
        self.ramp = RELEASE_RAMP_S / q.t_scale
        self.engaged = dolfinx.fem.Constant(mesh, PETSc.ScalarType(0.0))
        self.released_at = None  # normalised time of the release, None before

    def install(self, ends: EndTorques) -> EndTorques:
        """The end torques with the generator's torque scaled by :attr:`engaged`."""
        return dataclasses.replace(ends, generator=dataclasses.replace(ends.generator,
                                                                       engaged=self.engaged))

    def __call__(self, t: float):
        """Set the engaged fraction at the normalised time ``t`` (0 before the release)."""
        if self.released_at is None:
            self.engaged.value = 0.0
        else:
            self.engaged.value = float(np.clip((t - self.released_at) / self.ramp, 0.0, 1.0))

    def latch(self, solver):
        """After an accepted step: release once the ground end spins at the speed."""
        if self.released_at is None and float(solver.probes.value("spin0")) >= self.spin:
            self.released_at = solver.t

    def summary(self) -> dict:
        """The start-up's release: its speed [rpm] and time [s] (None: never released)."""
        return {"release_rpm": float(self.q.spin_rpm(self.spin)),
                "released_at_s": None if self.released_at is None
                else float(self.q.time_s(self.released_at))}


def of(machine: Machine, q, mesh) -> Release | None:
    """The run's release, or None: a generator on from the start."""
    g = machine.generator
    return None if g is None or g.release_rad_s is None else Release(machine, q, mesh)


__all__ = ["Release", "of"]
