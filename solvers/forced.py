"""The FE dynamics (PETSc TS) as a backend of :mod:`rawehelix.solvers.periodic`.

One :class:`DynamicsSolver` serves a whole chunk of a sweep.  Each forcing
frequency restarts the time integrator from the current (U, V) at the start of
its periods, with the first step ``time.dt_s``; so a point continued in memory
and a point resumed from its predecessor's state file take the same steps."""

from __future__ import annotations

import math

import dolfinx.fem
import dolfinx.fem.petsc
import numpy as np
from mpi4py import MPI

from rawehelix import compat
from rawehelix.solvers.fields import set_constant
from rawehelix.parameters import Normalised, Parameters
from rawehelix.solvers.dynamics import DynamicsSolver


class FEBackend:
    scheme = "fe"

    #: fixed steps: with a moving end the initial velocity and acceleration of
    #: the end dofs jump at every new f1, and alpha2's adaptive error estimate
    #: cannot get below its tolerance however small the step; a Newton failure
    #: still cuts the step (by 4), with no limit on their count over a sweep
    OPTIONS = {"ts_adapt_type": "none", "ts_max_snes_failures": -1, "ts_snes_max_it": 25}

    def __init__(self, params: Parameters, comm=MPI.COMM_SELF, options: dict | None = None):
        self.params = params
        self.solver = DynamicsSolver(params, comm, options={**self.OPTIONS, **(options or {})})
        self.dt = params.time.dt_s / params.normalised().t_scale
        rod = self.solver.rod
        self.v_top = dolfinx.fem.Function(rod.V_r)
        self.bc_v = dolfinx.fem.dirichletbc(self.v_top, rod.end_dofs["top"], rod.W.sub(0))
        self._stationary = self.pack(None)

    def _vectors(self):
        form = self.solver.form
        return (form.u, form.v) if form.second_order else (form.x,)

    def stationary(self):
        """The state the solver was built with: stationary, top at phase 0, at rest."""
        return self._stationary

    def advance(self, state, q: Normalised, t0: float, t1: float, t_out):
        solver = self.solver
        solver.q = solver.rod.q = q  # the circle of Eq. (70) at this f1 and phase
        self.unpack_into(state, q.top_velocity(t0))
        ts = solver.ts
        ts.setTime(t0)
        # uniform steps of at most time.dt_s that end exactly at t1: no step is
        # cut to land on a sample time (a cut step costs a third Newton
        # iteration and spoils the next step's predictor); the tension is
        # recorded at every step and interpolated to t_out
        step = (t1 - t0) / math.ceil((t1 - t0) / self.dt - 1e-9)
        ts.setTimeStep(step)
        ts.restartStep()
        samples = [(t0, solver.probes.value("tension0"))]  # (above 31 Hz a step > T/64)

        def record(s):
            samples.append((s.t, s.probes.value("tension0")))
            s.ts.setTimeStep(step)  # back to the fixed step after a cut (failed Newton)

        solver.advance(t1, on_step=record)
        times = np.array([t for t, _ in samples])
        values = np.array([v for _, v in samples])
        tension = np.interp(np.asarray(t_out), times, values) if len(times) else np.full(len(t_out), np.nan)
        return self.pack(None), tension

    def pack(self, _state) -> dict:
        """The current (U, V) of this rank's solver (COMM_SELF in a sweep)."""
        return {f"v{k}": compat.petsc_vec(f).array.copy() for k, f in enumerate(self._vectors())}

    def unpack_into(self, state: dict, top_velocity=None):
        """(U, V) <- state; the upper end's velocity <- that of the circle now."""
        form = self.solver.form
        for k, f in enumerate(self._vectors()):
            compat.petsc_vec(f).array[:] = state[f"v{k}"]
            f.x.scatter_forward()
        if top_velocity is not None and form.second_order:
            set_constant(self.v_top, top_velocity)
            dolfinx.fem.petsc.set_bc(compat.petsc_vec(form.v), [self.bc_v])
            form.v.x.scatter_forward()
        if form.second_order:
            self.solver.ts.setSolution2(compat.petsc_vec(form.u).copy(),
                                        compat.petsc_vec(form.v).copy())
        else:
            self.solver.ts.setSolution(compat.petsc_vec(form.x).copy())

    @staticmethod
    def unpack(data) -> dict:
        return {k: np.asarray(data[k]) for k in data.files if k.startswith("v")}
