"""The FE dynamics (PETSc TS) as a backend of :mod:`rawehelix.solvers.periodic`.

One :class:`DynamicsSolver` serves a whole chunk of a sweep.  Each forcing
frequency restarts the time integrator from the given state at the start of
its periods, with the first step ``time.dt_s``; so a point continued in memory
and a point resumed from its predecessor's saved state take the same steps.
Within one frequency the periods continue the integration: alpha2's restart
(two half backward-Euler steps for the acceleration, PETSc's TSAlpha_Restart)
perturbs the state by O(dt), and done every period it moved the periodic state
below 1.5 Hz, where a transient decays by 4 % a period, by 30 % of the
oscillation T max - T min (docs/explanation/orbits.md, "The sweep against the orbits").
States are :class:`~rawehelix.solvers.state.RodState`; the backend reads and
writes no files (``pack``/``unpack`` convert to and from plain arrays)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from rawehelix.parameters import Parameters
from rawehelix.solvers.dynamics import PREFIX, TS_DEFAULTS, DynamicsSolver
from rawehelix.solvers.state import RodState


class FEBackend:
    scheme = "fe"

    #: fixed steps: with a moving end the initial velocity and acceleration of
    #: the end dofs jump at every new f1, and alpha2's adaptive error estimate
    #: cannot get below its tolerance however small the step; a Newton failure
    #: still cuts the step (by 4), with no limit on their count over a sweep;
    #: and modified Newton: one LU for many fixed steps (snes.ReusedJacobian),
    #: rebuilt when an iteration contracts |F| by less than 10x, at rtol 1e-8.
    #: (At 1e-6 its error, ~3e-5 of T a period and not periodic, kept the 1 Hz
    #: point 0.2-0.5 of its oscillation off the orbit for 400 periods; 1e-8 costs
    #: x1.19 at 10 Hz, N = 8, and the same at 1 Hz, N = 4: docs/explanation/orbits.md,
    #: "The sweep against the orbits".)
    #: ``FULL_NEWTON`` switches it off (the converge study's reference runs).
    OPTIONS = {"ts_adapt_type": "none", "ts_max_snes_failures": -1, "ts_snes_max_it": 25,
               "ts_jacobian_reuse": 0.1, "ts_snes_rtol": 1.0e-8}
    FULL_NEWTON = {"ts_jacobian_reuse": 0.0, "ts_snes_rtol": 1.0e-8}

    def __init__(self, params: Parameters, comm=MPI.COMM_SELF, options: dict | None = None):
        self.params = params
        self.solver = DynamicsSolver.from_stationary(
            params, comm, options={**self.OPTIONS, **(options or {})})
        if self.solver.compiled_wanted:  # -rawehelix_ts_compiled 1: registers the steps
            import rawehelix.solvers.compiled_step  # noqa: F401
        self.dt = params.time.dt_s / params.normalised().t_scale
        self._stationary = self.solver.state()
        self._motion = (params.ends.circle_frequency_Hz, 0.0)
        self._last = None  # (the state the last advance returned, the motion it ran)
        #: an optional step hook with ``expect(t_out)`` (solvers/section_samples.py)
        self.section_sampler = None
        self._part_dofs = None  # (centre line, twist) dofs, for :meth:`parts`

    def track_sections(self) -> None:
        """Sample the section along s over the recorded periods (the limits block)."""
        from rawehelix.solvers.section_samples import SectionSampler
        self.section_sampler = SectionSampler(self.solver)

    def stationary(self) -> RodState:
        """The state the solver was built with: stationary, top at phase 0, at rest."""
        return self._stationary

    def set_frequency(self, f1_Hz: float, t_start: float):
        """The circle of Eq. (70) at f1, at phase 0 at the normalised time t_start."""
        self._motion = (f1_Hz, t_start)

    def continues(self, state: RodState) -> bool:
        """True if ``state`` is what the last :meth:`advance` returned, at the same
        circle: the integration goes on from the solver's own state (with its
        acceleration) instead of restarting."""
        return self._last is not None and state is self._last[0] and self._last[1] == self._motion

    def _begin(self, state: RodState, t0: float) -> bool:
        """Start an advance from ``state`` at t0: the solver set to it and to the
        circle, unless it :meth:`continues`; True if it restarts.  Until the advance
        ends (:meth:`_end`), nothing continues (a failed advance leaves the solver
        elsewhere)."""
        restart = not self.continues(state)
        self._last = None
        if restart:
            self.solver.set_state(dataclasses.replace(state, t=t0))
            self.solver.set_end_motion(*self._motion)  # the end's velocity: that of the circle now
        return restart

    def _end(self, out: RodState) -> RodState:
        """The state an advance returns, which the next one may continue."""
        self._last = (out, self._motion)
        return out

    def advance(self, state: RodState, t0: float, t1: float, t_out):
        solver = self.solver
        if (solver.compiled is not None and self.section_sampler is None
                and solver.compiled.stepper.tension_known):  # else T(0) by the probe, each step
            return self._advance_compiled(state, t0, t1, t_out)
        restart = self._begin(state, t0)
        ts = solver.ts
        ts.setTime(t0)  # (the sum of the steps may differ from t0 by round-off)
        # uniform steps of at most time.dt_s that end exactly at t1: no step is
        # cut to land on a sample time (a cut step costs a third Newton
        # iteration and spoils the next step's predictor); the tension is
        # recorded at every step and interpolated to t_out
        step = (t1 - t0) / math.ceil((t1 - t0) / self.dt - 1e-9)
        ts.setTimeStep(step)
        if restart:
            ts.restartStep()
        samples = [(t0, solver.probes.value("tension0"))]  # (above 31 Hz a step > T/64)
        sampler = self.section_sampler
        if sampler is not None:
            sampler.expect(t_out)

        def record(s):
            samples.append((s.t, s.probes.value("tension0")))
            if sampler is not None:
                sampler(s)
            s.ts.setTimeStep(step)  # back to the fixed step after a cut (failed Newton)

        solver.advance(t1, on_step=record)
        times = np.array([t for t, _ in samples])
        values = np.array([v for _, v in samples])
        tension = np.interp(np.asarray(t_out), times, values) if len(times) else np.full(len(t_out), np.nan)
        return self._end(solver.state()), tension

    def _advance_compiled(self, state: RodState, t0: float, t1: float, t_out):
        """:meth:`advance` by the solver's compiled steps (``-rawehelix_ts_compiled 1``):
        the same uniform steps, the tension at every step from the compiled loop."""
        solver, form = self.solver, self.solver.form
        compiled = solver.compiled
        restart = self._begin(state, t0)
        steps = math.ceil((t1 - t0) / self.dt - 1e-9)
        h = (t1 - t0) / steps
        it0, st0 = compiled.stepper.iterations, compiled.stepper.steps
        u, v, tension = compiled.stepper.run(t0, h, steps, form.u.x.array.copy(),
                                             form.v.x.array.copy(),
                                             a=None if restart else compiled.stepper.acceleration)
        solver.newton_iterations += compiled.stepper.iterations - it0
        solver.steps += compiled.stepper.steps - st0
        form.u.x.array[:] = u
        form.v.x.array[:] = v
        solver.ts.setTime(t1)
        times = t0 + h * np.arange(steps + 1)
        out = solver.rod.get_state(form.u, form.v, t1)
        out.offset = float(form.offset.value)
        return self._end(out), np.interp(np.asarray(t_out), times, tension)

    def parts(self, state: RodState) -> dict:
        """The state's parts whose change over a period says what is still moving
        (solvers/periodic.py, ``unsettled``), normalised: the twist without its mean
        (a spinning helix's twist grows by the rotation a period) and the rates."""
        if self._part_dofs is None:
            rod = self.solver.rod
            self._part_dofs = (rod.dofs("centre_line"), rod.dofs("twist"))
        r, a = self._part_dofs
        out = {"the centre line": state.w[r]}
        if a.size:
            out["the twist about its mean"] = state.w[a] - state.w[a].mean()
        if state.w_t is not None:
            out["the centre line's velocity"] = state.w_t[r]
            if a.size:
                out["the twist's rotation rate"] = state.w_t[a]
        return out

    @staticmethod
    def pack(state: RodState) -> dict:
        return state.arrays()

    @staticmethod
    def unpack(data) -> RodState:
        return RodState.from_arrays(data)


class ChordBackend(FEBackend):
    """FEBackend's periods with :class:`~rawehelix.solvers.chord.ChordAlpha`'s
    step loop instead of PETSc TS: the same scheme, start and uniform steps, so
    the same numbers to the Newton tolerance; one rank, dense LU (small N).
    Where the TS path cuts a step after a Newton failure, this one raises
    SolverError.  Like the TS path it continues within a frequency (alpha2's
    start only at a new state or circle).  Not the sweep's backend: it is 1.8x
    faster, not the 5x of issue 12 (docs/explanation/speed.md, section 5); ``chord``
    options go to ChordAlpha."""

    def __init__(self, params: Parameters, comm=MPI.COMM_SELF, options: dict | None = None,
                 **chord):
        from rawehelix.solvers.chord import ChordAlpha
        super().__init__(params, comm, options)
        radius = PETSc.Options().getReal(PREFIX + "ts_alpha_radius", TS_DEFAULTS["ts_alpha_radius"])
        self.stepper = ChordAlpha(params, radius, solver=self.solver, **chord)

    def advance(self, state: RodState, t0: float, t1: float, t_out):
        solver, form = self.solver, self.solver.form
        a = None if self._begin(state, t0) else self.stepper.acceleration
        steps = math.ceil((t1 - t0) / self.dt - 1e-9)
        h = (t1 - t0) / steps
        u, v, tension = self.stepper.run(t0, h, steps, form.u.x.array.copy(), form.v.x.array.copy(),
                                         a=a)
        form.u.x.array[:] = u
        form.v.x.array[:] = v
        times = t0 + h * np.arange(steps + 1)
        out = solver.rod.get_state(form.u, form.v, t1)
        out.offset = float(form.offset.value)
        return self._end(out), np.interp(np.asarray(t_out), times, tension)
