"""Probes of the FE sweep's time step (docs/explanation/step_size.md): one f1 path at one dt.

    python benchmarks/step_size_probes.py --dt 1e-3 --f1 0.5:7.5:0.5
    python benchmarks/step_size_probes.py --dt 1e-3 --f1 7.5 --lead-in 2
    python benchmarks/step_size_probes.py --dt 1e-3 --f1 0.5:7.5:0.5 --cut   # the old stepping

A path is one chunk with continuation (the first point starts from the
stationary state with the lead-in); a descending path is given in descending
order.  ``--cut`` replays the stepping of the sweep before commit 7da9ccb:
steps of time.dt_s cut to land on each of the 64 tension samples per period
(then restored), instead of today's uniform steps ending on the period.
Prints one line per point: T max, T min [N], periods, wall [s]; a line
"FAILED" when the point blew up.  No refusal check (the probes go past it)."""

from __future__ import annotations

import argparse
import logging
import math
import time

import numpy as np

from rawehelix.solvers.forced import FEBackend
from rawehelix.solvers.periodic import periodic_response
from rawehelix.solvers.snes import SolverError
from rawehelix.studies import scene


class CutStepBackend(FEBackend):
    """FEBackend with the stepping of the old sweep (steps cut onto the samples)."""

    def advance(self, state, t0, t1, t_out):
        import dataclasses
        solver = self.solver
        solver.set_state(dataclasses.replace(state, t=t0))
        solver.set_end_motion(*self._motion)
        every = (t1 - t0) / len(t_out) if len(t_out) > 1 else t1 - t0
        step = min(self.dt, every)
        solver.ts.setTimeStep(step)
        solver.ts.restartStep()
        samples = []

        def record(s):
            if s.t > t0 + 1e-12 * max(1.0, t1):
                samples.append((s.t, s.probes.value("tension0")))
            s.ts.setTimeStep(step)

        solver.advance(t1, on_output=record, output_every=every)
        times = np.array([t for t, _ in samples])
        values = np.array([v for _, v in samples])
        tension = np.interp(np.asarray(t_out), times, values) if len(times) else np.full(len(t_out), np.nan)
        return solver.state(), tension


def frequencies(text: str) -> list[float]:
    if ":" not in text:
        return [float(f) for f in text.split(",")]
    a, b, c = (float(x) for x in text.split(":"))
    n = int(math.floor(abs(b - a) / abs(c) + 1e-9))
    return [round(a + math.copysign(k * abs(c), b - a), 10) for k in range(n + 1)]


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--dt", type=float, required=True, help="time.dt_s [s]")
    ap.add_argument("--f1", required=True, help="a,b,c or START:STOP:STEP (descending allowed)")
    ap.add_argument("--elements", type=int, default=8)
    ap.add_argument("--lead-in", type=float, default=None, help="sweep.lead_in_s [s]")
    ap.add_argument("--min-periods", type=int, default=None)
    ap.add_argument("--max-periods", type=int, default=None)
    ap.add_argument("--tol", type=float, default=None, help="sweep.periodic_tolerance")
    ap.add_argument("--cut", action="store_true", help="the old stepping (cut onto the samples)")
    ap.add_argument("--trace", action="store_true", help="print T max, min [N] of every period")
    ap.add_argument("--alpha-rho", type=float, default=None, help="ts_alpha_radius (rho_inf)")
    a = ap.parse_args(argv)
    logging.basicConfig(level=logging.WARNING)
    over = {"time.dt_s": a.dt}
    for key, val in (("sweep.lead_in_s", a.lead_in), ("sweep.min_periods", a.min_periods),
                     ("sweep.max_periods", a.max_periods), ("sweep.periodic_tolerance", a.tol)):
        if val is not None:
            over[key] = val
    params = scene.load("mobile_end", elements=a.elements, overrides=over)
    options = {"ts_alpha_radius": a.alpha_rho} if a.alpha_rho is not None else None
    cls = CutStepBackend if a.cut else FEBackend

    def make():
        backend = cls(params, options=options)
        if a.trace:
            advance = backend.advance

            def traced(state, t0, t1, t_out):
                state, tension = advance(state, t0, t1, t_out)
                T = q.tension_N(tension)
                print(f"    t = {q.time_s(t1):8.3f} s: T max {np.max(T):10.3f} min {np.min(T):10.3f} N",
                      flush=True)
                return state, tension
            backend.advance = traced
        return backend

    q = params.normalised()
    backend, state, t = make(), None, 0.0
    print(f"dt = {a.dt:g} s, N = {a.elements}, {'cut' if a.cut else 'uniform'} steps, "
          f"f1 = {frequencies(a.f1)}", flush=True)
    start = time.perf_counter()
    for f1 in frequencies(a.f1):
        lead_in = state is None
        if lead_in:
            state, t = backend.stationary(), 0.0
        try:
            r, state, t = periodic_response(backend, q, f1, state, t, params.sweep, lead_in)
        except (SolverError, FloatingPointError, RuntimeError) as err:
            print(f"f1 = {f1:6.2f} Hz: FAILED: {str(err).splitlines()[0][:200]}", flush=True)
            backend, state = make(), None
            continue
        print(f"f1 = {f1:6.2f} Hz: T max {r.tension_max_N:10.3f} N  min {r.tension_min_N:10.3f} N "
              f"{r.periods:3d} periods{'' if r.periodic else ' NOT PERIODIC'} {r.wall_s:6.1f} s "
              f"({r.start})", flush=True)
    print(f"total {time.perf_counter() - start:.1f} s", flush=True)


if __name__ == "__main__":
    main()
