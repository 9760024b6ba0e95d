"""The study loop: every method over its ladder (in N or dt), the errors
against the reference, the observed orders.

Under ``mpirun -n k`` the runs are dealt round-robin to the ranks, each on
its own communicator; rank 0 gathers them, measures the errors and writes
the report.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from mpi4py import MPI

from rawehelix.parameters import Parameters
from rawehelix.solvers.snes import SolverError
from rawehelix.studies.store import writers
from rawehelix.studies.converge import report
from rawehelix.studies.converge.cache import RunCache
from rawehelix.studies.converge.methods import Method
from rawehelix.studies.converge.quantity import Quantity


@dataclass
class Run:
    method: Method
    value_of_ladder: float
    result: np.ndarray
    wall_s: float
    error: float = math.nan
    order: float = math.nan
    failed: str | None = None  # why the run failed (its value is nan)


def errors_and_orders(runs: list[Run], reference: np.ndarray, scale=None) -> dict:
    """Set each run's error (the largest over its components of |value -
    reference| / |reference|, or / ``scale``) and observed order
    log(e_a / e_b) / log(h_a / h_b) between neighbours of a ladder; returns
    the runs by method label, coarsest first."""
    for run in runs:
        rel = np.abs(run.result - reference) / (np.abs(reference) if scale is None else scale)
        run.error = float(np.nanmax(rel)) if np.any(np.isfinite(rel)) else math.nan
    by_method = {}
    for run in runs:
        by_method.setdefault(run.method.label, []).append(run)
    for series in by_method.values():
        series.sort(key=lambda r: r.method.resolution(r.value_of_ladder), reverse=True)
        for a, b in zip(series[:-1], series[1:]):
            ha, hb = a.method.resolution(a.value_of_ladder), b.method.resolution(b.value_of_ladder)
            if a.error > 0 and b.error > 0:
                b.order = math.log(a.error / b.error) / math.log(ha / hb)
    return by_method


def _timed(evaluate, params, method, value, budget_s: float = 1.0, repeats: int = 3):
    """(value, wall time): the fastest of up to ``repeats`` runs, repeating only
    while the runs together stay under ``budget_s`` (cheap runs are noisy)."""
    walls, spent = [], 0.0
    while True:
        t0 = time.perf_counter()
        result = np.atleast_1d(np.asarray(evaluate(params, method, value), dtype=float))
        walls.append(time.perf_counter() - t0)
        spent += walls[-1]
        if len(walls) >= repeats or spent + walls[-1] > budget_s:
            return result, min(walls)


def step_label(method: Method, value) -> str:
    """'N = 8' or 'N = 8, dt = 0.005 s': what a run resolves."""
    if method.variable == "dt_s":
        return f"N = {method.elements}, dt = {value:g} s"
    return f"N = {int(value)}"


def _my_runs(qty: Quantity, params, jobs, cache: RunCache, comm, log) -> list:
    """(job index, values, wall time, failure) of this rank's share of the jobs."""
    mine, warm, evaluate = [], set(), qty.refinement.evaluate
    for k, (method, value) in enumerate(jobs):
        if k % comm.size != comm.rank:
            continue
        cached = cache.get(method.label, value)
        if cached is not None:
            mine.append((k, *cached))
            log(f"  {method.label:>10} {step_label(method, value)}: {cached[0]} "
                f"(done before, {cached[1]:.2f} s)")
            continue
        try:
            if method.label not in warm:  # just-in-time compilation is not part of the cost:
                evaluate(params, method, method.ladder[0])  # warm up on the cheapest run
                warm.add(method.label)
            result, wall = _timed(evaluate, params, method, value)
            failed = None
        except (SolverError, ArithmeticError, RuntimeError) as err:
            # a run that fails is a result too (a step too long, a mesh too coarse)
            result, wall = np.full(len(qty.refinement.components), math.nan), math.nan
            failed = str(err)
        cache.put(method.label, value, result, wall, failed)
        mine.append((k, result, wall, failed))
        log(f"  {method.label:>10} {step_label(method, value)}: "
            + (f"FAILED: {failed}" if failed else
               f"{np.array2string(result, precision=8)} ({wall:.2f} s)"))
    return mine


def _finest(runs: list[Run], label: str) -> Run | None:
    return min((r for r in runs if r.method.label == label),
               key=lambda r: r.method.resolution(r.value_of_ladder), default=None)


def _summarise(qty: Quantity, params, runs: list[Run], name: str):
    """(summary, runs by method): errors of the space ladders against the
    finest run of the reference method, of the dt ladders against the finest
    run of the time reference (when the quantity has one)."""
    how = qty.refinement
    ref_run = _finest(runs, how.reference)
    reference = ref_run.result
    time_ref = _finest(runs, how.time_reference) if how.time_reference else None
    space = [r for r in runs if time_ref is None or r.method.variable != "dt_s"]
    scale = how.error_scale(params) if how.error_scale else None
    by_method = errors_and_orders(space, reference, scale)
    if time_ref is not None:
        by_method.update(errors_and_orders([r for r in runs if r not in space], time_ref.result,
                                           scale))
    # the independent reference, where it applies and within its budget: its status
    # is reported beside the runs, never instead of them (studies/reference_check.py)
    independent, independent_status = how.independent(params) if how.independent else (None, None)
    summary = {
        "scene": name, "quantity": qty.name, "unit": qty.unit,
        "components": how.components,
        "reference": {"method": how.reference, how.methods[0].variable: ref_run.value_of_ladder,
                      "value": reference,
                      "independent": independent,
                      "independent_status": independent_status,
                      "independent_rel_diff": None if independent is None else
                      float(np.max(np.abs(reference - independent) / np.abs(independent)))},
        "error_scale": scale,
        "time_reference": None if time_ref is None else {
            "method": time_ref.method.label, "elements": time_ref.method.elements,
            "dt_s": time_ref.value_of_ladder, "value": time_ref.result},
        "runs": [{"method": r.method.label, "refined": r.method.variable,
                  "elements": r.method.elements if r.method.variable == "dt_s" else r.value_of_ladder,
                  "dt_s": r.value_of_ladder if r.method.variable == "dt_s" else None,
                  "step": step_label(r.method, r.value_of_ladder),
                  "value": r.result, "error": r.error, "order": r.order, "wall_s": r.wall_s,
                  "failed": r.failed}
                 for r in runs],
    }
    return summary, by_method


def write_outputs(outdir: Path, summary: dict, by_method: dict, qty: Quantity,
                  name: str):
    """summary.json, converge.csv, converge.md and work_precision.png in ``outdir``."""
    outdir.mkdir(parents=True, exist_ok=True)
    writers.write_json(outdir / "summary.json", summary)
    writers.write_text(outdir / "converge.csv",
                       report.csv_text(summary, qty.unit, qty.refinement.components))
    writers.write_text(outdir / "converge.md", report.markdown(summary, qty, name))
    report.work_precision_png(outdir / "work_precision.png", by_method, qty, name)


def run(params: Parameters, qty: Quantity, outdir: Path | None, name: str = "scene",
        comm=MPI.COMM_WORLD, log=print, methods: list | None = None) -> dict:
    """Run the refinement study of the refined quantity ``qty`` (studies/quantities.py's
    ``refined()``; ``methods``: its own by default); finished runs are kept in
    ``outdir/runs/``.  Returns the summary on every rank."""
    start = time.perf_counter()
    methods = methods or qty.refinement.methods
    jobs = [(m, v) for m in methods for v in m.ladder]
    cache = RunCache(Path(outdir) / "runs" if outdir is not None else None, params, qty.name)
    gathered = comm.gather(_my_runs(qty, params, jobs, cache, comm, log), root=0)
    summary = None
    if comm.rank == 0:
        results = sorted((item for part in gathered for item in part), key=lambda i: i[0])
        runs = [Run(jobs[k][0], jobs[k][1], result, wall, failed=failed)
                for k, result, wall, failed in results]
        summary, by_method = _summarise(qty, params, runs, name)
        summary.update({"ranks": comm.size, "wall_s": time.perf_counter() - start})
        if outdir is not None:
            write_outputs(Path(outdir), summary, by_method, qty, name)
            log(f"  wrote {outdir}/converge.csv, converge.md, work_precision.png, summary.json")
        for label, series in by_method.items():
            orders = [f"{r.order:.2f}" for r in series if np.isfinite(r.order)]
            log(f"  {label:>10}: errors {' '.join(f'{r.error:.1e}' for r in series)}; "
                f"observed orders {' '.join(orders)}")
        ref = summary["reference"]
        if ref["independent_status"] is not None:
            log(f"  independent reference (shooting): " + (
                f"compared, {ref['independent_rel_diff']:.1e} from the finest run"
                if ref["independent"] is not None else ref["independent_status"]))
    return comm.bcast(summary, root=0)
