"""`rawehelix campbell`'s cost, as a ratio (the issue's target: the Campbell diagram of
the power curve's points at most 2x more than the power curve):

the Campbell diagram of operate's 25 wind speeds at N = 8 (rotor_example, MPPT; the
same points as benchmarks/operate.py), CPU time in this process after a run that
compiles the forms, against the power curve alone; the ratio is (campbell - operate) /
operate, the Campbell's own part (a stationary solve and an eigenproblem a point).

    .venv/bin/python benchmarks/run.py --only campbell      (into results.json)
"""

from __future__ import annotations

import time

import numpy as np
from mpi4py import MPI

from operate import WINDS, _stats  # benchmarks/operate.py: the same points

TARGET_RATIO = 2.0  # the issue's: the Campbell diagram of those points at most 2x more


def _cpu(fn, repeats):
    cpu, wall, out = [], [], None
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        out = fn()
        wall.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    return out, cpu, wall


def bench_campbell(elements: int = 8, repeats: int = 3) -> dict:
    import rawehelix as rh
    scene = rh.load_scene("rotor_example", elements=elements)
    rh.campbell(scene, WINDS[:2], comm=MPI.COMM_SELF)  # compiles the forms
    _, op_cpu, op_wall = _cpu(lambda: rh.operate(scene, WINDS, comm=MPI.COMM_SELF), repeats)
    result, cb_cpu, cb_wall = _cpu(lambda: rh.campbell(scene, WINDS, comm=MPI.COMM_SELF),
                                   repeats)
    op, cb = float(np.median(op_cpu)), float(np.median(cb_cpu))
    return {"elements": elements, "winds": len(WINDS), "points": len(result.points),
            "operate_cpu_s": _stats(op_cpu), "campbell_cpu_s": _stats(cb_cpu),
            "operate_wall_s": _stats(op_wall), "campbell_wall_s": _stats(cb_wall),
            "extra_over_operate": (cb - op) / op, "target": TARGET_RATIO}


def markdown(c: dict) -> list[str]:
    """The section's row of benchmarks/results.md."""
    return [f"| 16. `campbell` rotor_example, {c['winds']} wind speeds, N = {c['elements']} "
            f"(CPU, median of {c['campbell_cpu_s']['runs']}) | {c['campbell_cpu_s']['median']:.2f} s "
            f"with operate's {c['operate_cpu_s']['median']:.2f} s: the Campbell's own part "
            f"{c['extra_over_operate']:.2f} x the power curve's | <= {c['target']:g} x |"]
