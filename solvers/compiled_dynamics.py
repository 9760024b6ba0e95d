"""The dynamics' compiled steps (issue 46), ``-rawehelix_ts_compiled 1``: the
DynamicsSolver's integration between its outputs by
:class:`~rawehelix.solvers.compiled_step.CompiledChordAlpha` instead of PETSc TS.

The scheme is TSALPHA2's (same rho_inf, same start, same fixed steps), so a run
gives TS's numbers to the Newton tolerance (tests/test_compiled_steps.py); the
TS keeps the state (its solution vectors and time are set after every stretch of
steps), so the outputs, the states and the failures go through the solver as
before.  One rank, alpha2 with fixed steps (a moving end's default): anything
else is refused before the run.
"""

from __future__ import annotations

import math

from rawehelix.solvers.snes import SolverError

OPTION = "-rawehelix_ts_compiled"


def refusal(ts_type: str, adapt: str, comm_size: int, end_twist) -> str | None:
    """Why the compiled steps cannot run this solver (None: they can)."""
    if comm_size > 1:
        return "run on one rank (drop it, or run without mpirun)"
    if ts_type != "alpha2":
        return f"steps alpha2 only, not -rawehelix_ts_type {ts_type}"
    if adapt != "none":
        return ("take fixed steps: a scene with a moving upper end (ends.circle_radius_m > 0), "
                "or -rawehelix_ts_adapt_type none")
    if end_twist is not None:
        return "does not run the prescribed end twist of the torsion test"
    return None


class CompiledAdvance:
    """``DynamicsSolver.advance`` by compiled steps (module docstring)."""

    def __init__(self, solver, rho_inf: float):
        from rawehelix.solvers.compiled_step import CompiledChordAlpha
        from rawehelix.solvers.generalised_alpha import TOL
        self.solver = solver
        # Hairer's test at the orbits' 1e-14, not ChordAlpha's 1e-11: the energy balance
        # of an undamped free vibration is then TS's (2.9e-7 against 3.1e-7 over 2000
        # steps; 1e-11: 4.2e-5, 1e-13: 7.0e-6), for 2.8 iterations a step instead of 2.0
        self.stepper = CompiledChordAlpha(solver.params, rho_inf, solver=solver, tol=TOL)
        self._last = None  # (t, U) where the last advance ended, with its acceleration

    def __call__(self, t_end: float, on_step=None, on_output=None, output_every=None):
        solver, stepper = self.solver, self.stepper
        ts, form = solver.ts, solver.form
        t = ts.getTime()
        eps = 1e-9 * max(1.0, t_end)
        h0 = ts.getTimeStep()
        steps = max(1, math.ceil((t_end - t) / h0 - 1e-9))
        h_end = (t_end - t) / steps
        if on_step is not None:  # every step is an output
            ends = [t + k * h_end for k in range(1, steps + 1)]
        elif output_every:
            n = int(math.floor((t_end - t) / output_every + 1e-9))
            ends = [t + k * output_every for k in range(1, n + 1)]
            if not ends or ends[-1] < t_end - eps:
                ends.append(t_end)
        else:
            ends = [t_end]
        U, V = ts.getSolution2()
        u, v = form.u.x.array.copy(), form.v.x.array.copy()
        last = self._last
        a = last[2] if (last is not None and abs(last[0] - t) <= eps
                        and (last[1] == u).all()) else None
        solver._on_step, solver._on_output = on_step, on_output
        if solver._fresh:
            solver._fresh = False
            solver._pending = []
            solver._accepted(t, first=True)
        it0, st0 = stepper.iterations, stepper.steps
        try:
            for end in ends:
                n = max(1, math.ceil((end - t) / h0 - 1e-9))
                try:
                    u, v, _ = stepper.run(t, (end - t) / n, n, u, v, a)
                except SolverError as err:
                    solver._restore_good()
                    t_s = solver.q.time_s(solver._good[0] if solver._good else t)
                    raise SolverError(f"dynamics stopped at t = {float(t_s):.6g} s (simulated): "
                                      f"{err}; or run without {OPTION}") from None
                a, t = stepper.acceleration, end
                U.array[:] = u
                V.array[:] = v
                ts.setTime(t)
                solver._pending = [t]
                solver._accepted(t)
        finally:
            solver.newton_iterations += stepper.iterations - it0
            solver.steps += stepper.steps - st0
        self._last = (t, u.copy(), a)
