"""`rawehelix converge`: refinement studies and work-precision figures.

For one quantity of interest, runs every method over its refinement ladder
(elements N for the space discretisations, time step dt for the time
integrators), and records for each run the value, the error, the observed
order and the wall time.

Error: relative to the **finest run of the reference method** (the most
accurate one: FE with the highest degree at the largest N for stationary and
modal quantities), not a Richardson extrapolation; the reference's own
distance to an independent reference (shooting, where one exists) is printed
so that the floor of the table is known.  For a vector of values (the lowest
eigenvalue of each family) the error is the largest relative error.

Under ``mpirun -n k`` the runs are dealt round-robin to the ranks, each on
its own communicator; rank 0 gathers and writes ``converge.csv``,
``converge.md``, ``work_precision.png`` and ``summary.json``.
"""

from __future__ import annotations

import csv
import dataclasses
import json
import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from mpi4py import MPI

from rawehelix.families import VIBRATIONS
from rawehelix.parameters import Parameters
from rawehelix.solvers.snes import SolverError
from rawehelix.studies import writers


@dataclass(frozen=True)
class Method:
    """One curve of the work-precision figure."""

    label: str  # "FE p=3", "spline", ...
    scheme: str  # "fe" or "spline"
    degree: int | None = None
    ladder: tuple = ()  # refinement values: elements N (or dt in s for time schemes)
    variable: str = "elements"  # what the ladder refines: "elements" or "dt_s"
    ts_type: str | None = None  # PETSc TS type for the FE dynamics (default alpha2)
    elements: int | None = None  # fixed N of a time-step ladder

    def resolution(self, value) -> float:
        """A mesh size h (or dt) whose ratio gives the observed order."""
        return 1.0 / value if self.variable == "elements" else float(value)


@dataclass
class Run:
    method: Method
    value_of_ladder: float
    result: np.ndarray
    wall_s: float
    error: float = math.nan
    order: float = math.nan
    failed: str | None = None  # why the run failed (its value is nan)


@dataclass
class Quantity:
    name: str
    unit: str
    methods: list
    reference: str  # label of the reference method (its finest run is the reference)
    evaluate: object  # (params, method, ladder value) -> np.ndarray of values
    components: list = field(default_factory=list)
    independent: object = None  # params -> independent reference value, or None
    # label of the method whose finest run is the reference of the dt ladders
    # (their time error alone, at their N); None: the main reference
    time_reference: str | None = None
    # params -> the scale of the error (|value - reference| / scale) where the
    # value itself can be ~0; None: relative to the reference value
    error_scale: object = None
    scale_note: str = ""


# -- quantities ------------------------------------------------------------------

def _with(params: Parameters, method: Method, value) -> Parameters:
    if method.variable == "elements":
        disc = {"scheme": method.scheme, "elements": int(value)}
        if method.degree is not None:
            disc["degree"] = method.degree
        return params.replace(discretisation=disc)
    disc = {"scheme": method.scheme, "elements": method.elements or params.discretisation.elements}
    if method.degree is not None:
        disc["degree"] = method.degree
    return params.replace(discretisation=disc, time={"dt_s": float(value)})


def tension_s0(params: Parameters, method: Method, value) -> np.ndarray:
    """Stationary tension at s = 0 [N] (Sec. 5.1)."""
    p = _with(params, method, value)
    q = p.normalised()
    if method.scheme == "spline":
        from rawehelix.solvers.spline_galerkin import stationary
        from rawehelix.solvers.spline_galerkin.system import SplineGalerkin
        system = SplineGalerkin(q, p.discretisation.elements)
        x = stationary.solve(system).x
        return np.array([q.tension_N(system.tension(x, 0.0, s=np.array([0.0]))[0])])
    from rawehelix.solvers.stationary import StationarySolver
    result = StationarySolver(p, MPI.COMM_SELF).solve()
    return np.array([q.tension_N(result.tension[0])])


def _shooting_tension_s0(params: Parameters):
    from rawehelix.solvers import shooting
    q = params.normalised()
    return np.array([q.tension_N(shooting.solve(q).tension(0.0))])


def eigenvalues(params: Parameters, method: Method, value) -> np.ndarray:
    """|lambda| [1/s] of the lowest mode of each family (Sec. 5.1, Table 3)."""
    from rawehelix.studies import modes
    lowest = {}
    for m in modes.compute(_with(params, method, value), comm=MPI.COMM_SELF):
        lam = abs(m.eigenvalue_per_s)
        if m.family in VIBRATIONS and lam > 1e-9:
            lowest[m.family] = min(lowest.get(m.family, math.inf), lam)
    return np.array([lowest.get(f, math.nan) for f in VIBRATIONS])


# -- dynamics (Sec. 5.2) -------------------------------------------------------------

SPIN_RUN_S = 15.0  # the spin settles in ~5 s (Fig. 6)


def _spin_series(params: Parameters, method: Method, value):
    """(t [s], spin [rpm] at s = 0, L0/2, L0) of the Sec. 5.2 run, sampled every
    5 ms, or at every step of a fixed-step (dt ladder) run: cutting its steps to
    land on the sample times would make every dt above 5 ms a 5 ms run."""
    p = _with(params, method, value)
    q = p.normalised()
    every = 0.005 / q.t_scale
    if method.scheme == "spline":
        from rawehelix.solvers.spline_galerkin.dynamics import time_series
        ts = time_series(p, until_s=SPIN_RUN_S, output_every_s=0.005, rtol=1e-9)
        return ts.time_s, ts.spin_rpm
    from rawehelix.solvers.dynamics import DynamicsSolver
    options = {"ts_type": method.ts_type} if method.ts_type else {}
    if method.variable == "dt_s":
        options["ts_adapt_type"] = "none"
    else:  # adaptive steps, tight enough that space dominates the error
        options.update({"ts_rtol": 1e-6, "ts_atol": 1e-6})
    solver = DynamicsSolver(p, MPI.COMM_SELF, options=options)
    rows = []

    def sample(s):
        v = s.probes.values()
        rows.append((s.t, v["spin0"], v["spin_mid"], v["spin1"]))

    if method.variable == "dt_s":
        sample(solver)
        solver.advance(SPIN_RUN_S / q.t_scale, on_step=sample)
    else:
        solver.advance(SPIN_RUN_S / q.t_scale, on_output=sample, output_every=every)
    rows = np.array(rows)
    return q.time_s(rows[:, 0]), q.spin_rpm(rows[:, 1:])


def spin_overshoot(params: Parameters, method: Method, value) -> np.ndarray:
    """Largest spin at s = 0 above the target [rpm] (Sec. 5.2)."""
    t, spin = _spin_series(params, method, value)
    return np.array([spin[:, 0].max() - params.controller.target_rpm])


def settling_time(params: Parameters, method: Method, value) -> np.ndarray:
    """When all three spins stay within 2 % of the target [s] (Sec. 5.2); the
    last exit from the band is located by linear interpolation."""
    t, spin = _spin_series(params, method, value)
    target = params.controller.target_rpm
    dev = np.max(np.abs(spin - target), axis=1) - 0.02 * target
    outside = np.nonzero(dev > 0)[0]
    if len(outside) == 0:
        return np.array([0.0])
    k = outside[-1]
    if k + 1 >= len(t):
        return np.array([math.inf])
    return np.array([t[k] + (t[k + 1] - t[k]) * dev[k] / (dev[k] - dev[k + 1])])


# -- mobile end (Sec. 5.3) -------------------------------------------------------------

TENSION_MAX_F1_HZ = 10.0
#: fixed step of the FE runs refined in space [s]: its time error in T max at
#: 10 Hz is ~0.02 N (1e-4), from 244.658 / 244.460 / 244.397 N at 0.5 / 0.25 /
#: 0.125 ms (N = 8, p = 3, alpha2); the scene's 0.5 ms would put 0.28 N into
#: every space error
TENSION_MAX_SPACE_DT_S = 1.25e-4


def tension_max(params: Parameters, method: Method, value) -> np.ndarray:
    """Maximum tension at s = 0 [N] of the periodic response at f1 = 10 Hz
    (Fig. 8 inset), from the stationary state with a 3 s lead-in; periodic to
    1e-5 (which moves T max by 2e-6 relative against 1e-4 and 1e-6)."""
    from rawehelix.solvers.periodic import periodic_response
    p = _with(params, method, value).replace(sweep={"lead_in_s": 3.0, "periodic_tolerance": 1e-5})
    if method.variable == "elements" and method.scheme == "fe":
        p = p.replace(time={"dt_s": TENSION_MAX_SPACE_DT_S})
    q = p.normalised()
    if method.scheme == "spline":
        from rawehelix.solvers.spline_galerkin.forced import SplineBackend
        backend = SplineBackend(q, p.discretisation.elements, rtol=1e-9, atol=1e-11)
    else:
        from rawehelix.solvers.forced import FEBackend
        backend = FEBackend(p, MPI.COMM_SELF,
                            options={"ts_type": method.ts_type} if method.ts_type else None)
    result, _, _ = periodic_response(backend, q, TENSION_MAX_F1_HZ, backend.stationary(), 0.0,
                                     p.sweep, lead_in=True)
    return np.array([result.tension_max_N])


#: the Sec. 5.2 spin approaches its target from below (the PD controller of
#: Eq. 40 is well damped): the overshoot is ~0 and its error is measured
#: against the target spin instead
SPIN_SCALE = {"error_scale": lambda params: params.controller.target_rpm,
              "scale_note": "the spin at s = 0 never rises above the target; its largest "
                            "value is within 1e-3 rpm of it at every resolution"}

FE_LADDER = (2, 4, 8, 16, 32, 64)
SPLINE_LADDER = (2, 4, 8, 16, 32)


def quantities() -> dict:
    fe = [Method(f"FE p={p}", "fe", p, FE_LADDER) for p in (2, 3, 4)]
    spline = Method("spline", "spline", None, SPLINE_LADDER)
    return {
        "tension_s0": Quantity("tension_s0", "N", fe + [spline], "FE p=4", tension_s0,
                               ["T(0)"], _shooting_tension_s0),
        "eigenvalues": Quantity("eigenvalues", "1/s",
                                [Method(f"FE p={p}", "fe", p, (2, 4, 8, 16, 32)) for p in (2, 3, 4)]
                                + [Method("spline", "spline", None, (2, 4, 8, 16))],
                                "FE p=4", eigenvalues, list(VIBRATIONS)),
        **{name: Quantity(name, unit, _dynamic_methods(ladder_fe, ladder_spline, dts, N), "FE p=4",
                          fn, [label], time_reference=f"FE N={N} p=3 alpha2 (dt)",
                          **(SPIN_SCALE if name == "spin_overshoot" else {}))
           for name, unit, fn, label, ladder_fe, ladder_spline, dts, N in (
               ("spin_overshoot", "rpm", spin_overshoot, "overshoot", (2, 4, 8, 16), (2, 4, 8),
                {"alpha2": (0.02, 0.01, 0.005, 0.00125), "cn": (0.02, 0.01, 0.005)}, 8),
               ("settling_time", "s", settling_time, "settling", (2, 4, 8, 16), (2, 4, 8),
                {"alpha2": (0.02, 0.01, 0.005, 0.00125), "cn": (0.02, 0.01, 0.005)}, 8),
               # cn works on the first-order form, whose Jacobian costs ~9x alpha2's
               # to assemble (twice the fields): it gets the longer steps
               ("tension_max", "N", tension_max, "T max at 10 Hz", (4, 8, 16), (2, 3, 4, 6),
                {"alpha2": (5e-4, 2.5e-4, 1.25e-4, 3.125e-5), "cn": (1e-3, 5e-4, 2.5e-4)}, 8))},
    }


def _dynamic_methods(ladder_fe, ladder_spline, dts, N):
    """FE p = 2, 3, 4 in space (adaptive alpha2), the spline reference, and two
    TS schemes with fixed steps at N elements, p = 3 (the dt ladder)."""
    return ([Method(f"FE p={p}", "fe", p, ladder_fe) for p in (2, 3, 4)]
            + [Method("spline", "spline", None, ladder_spline)]
            + [Method(f"FE N={N} p=3 {ts} (dt)", "fe", 3,
                      dts[ts] if isinstance(dts, dict) else dts, "dt_s", ts, N)
               for ts in ("alpha2", "cn")])


# -- the study ---------------------------------------------------------------------

def _errors_and_orders(runs: list[Run], reference: np.ndarray, scale=None):
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


def _step(method: Method, value) -> str:
    if method.variable == "dt_s":
        return f"N = {method.elements}, dt = {value:g} s"
    return f"N = {int(value)}"


class _RunCache:
    """Finished runs as files in ``outdir/runs/``: a study stopped (or crashed)
    part-way is resumed by the same command, and a run is never done twice.
    A file counts only for the same scene, discretisation and quantity."""

    def __init__(self, folder: Path | None, params: Parameters, quantity: str):
        self.folder = folder
        self.fingerprint = writers.digest([dataclasses.asdict(params), quantity])

    def _path(self, method: Method, value) -> Path:
        slug = "".join(c if c.isalnum() else "_" for c in method.label)
        return self.folder / f"{slug}_{value:g}.json"

    def get(self, method: Method, value):
        if self.folder is None or not self._path(method, value).exists():
            return None
        data = json.loads(self._path(method, value).read_text())
        if data.get("fingerprint") != self.fingerprint:
            return None
        return (np.asarray(data["result"], dtype=float),
                math.nan if data["wall_s"] is None else data["wall_s"], data["failed"])

    def put(self, method: Method, value, result, wall, failed):
        if self.folder is not None:
            writers.write_json(self._path(method, value), {
                "fingerprint": self.fingerprint, "method": method.label, "value": value,
                "result": [None if not np.isfinite(v) else float(v) for v in result],
                "wall_s": None if not np.isfinite(wall) else wall, "failed": failed})


def run(params: Parameters, quantity: str, outdir: Path | None, name: str = "scene",
        comm=MPI.COMM_WORLD, log=print, methods: list | None = None) -> dict:
    """Run the refinement study of ``quantity``; returns the summary on every rank."""
    start = time.perf_counter()
    qty = quantities()[quantity]
    methods = methods or qty.methods
    jobs = [(m, v) for m in methods for v in m.ladder]
    cache = _RunCache(Path(outdir) / "runs" if outdir is not None else None, params, quantity)
    mine, warm = [], set()
    for k, (method, value) in enumerate(jobs):
        if k % comm.size != comm.rank:
            continue
        cached = cache.get(method, value)
        if cached is not None:
            mine.append((k, *cached))
            log(f"  {method.label:>10} {_step(method, value)}: {cached[0]} (done before, {cached[1]:.2f} s)")
            continue
        try:
            if method.label not in warm:  # just-in-time compilation is not part of the cost:
                qty.evaluate(params, method, method.ladder[0])  # warm up on the cheapest run
                warm.add(method.label)
            result, wall = _timed(qty.evaluate, params, method, value)
            failed = None
        except (SolverError, ArithmeticError, RuntimeError) as err:
            # a run that fails is a result too (a step too long, a mesh too coarse)
            result, wall, failed = np.full(len(qty.components), math.nan), math.nan, str(err)
        cache.put(method, value, result, wall, failed)
        mine.append((k, result, wall, failed))
        log(f"  {method.label:>10} {_step(method, value)}: "
            + (f"FAILED: {failed}" if failed else
               f"{np.array2string(result, precision=8)} ({wall:.2f} s)"))
    gathered = comm.gather(mine, root=0)
    summary = None
    if comm.rank == 0:
        results = sorted((item for part in gathered for item in part), key=lambda i: i[0])
        runs = [Run(jobs[k][0], jobs[k][1], result, wall, failed=failed)
                for k, result, wall, failed in results]
        ref_runs = [r for r in runs if r.method.label == qty.reference]
        ref_run = max(ref_runs, key=lambda r: 1.0 / r.method.resolution(r.value_of_ladder))
        reference = ref_run.result
        time_ref = None
        if qty.time_reference:
            t_runs = [r for r in runs if r.method.label == qty.time_reference]
            time_ref = min(t_runs, key=lambda r: r.method.resolution(r.value_of_ladder),
                           default=None)
        space = [r for r in runs if time_ref is None or r.method.variable != "dt_s"]
        scale = qty.error_scale(params) if qty.error_scale else None
        by_method = _errors_and_orders(space, reference, scale)
        if time_ref is not None:
            by_method.update(_errors_and_orders([r for r in runs if r not in space], time_ref.result,
                                                scale))
        independent = qty.independent(params) if qty.independent else None
        summary = {
            "scene": name, "quantity": quantity, "unit": qty.unit,
            "components": qty.components,
            "reference": {"method": qty.reference, qty.methods[0].variable: ref_run.value_of_ladder,
                          "value": reference,
                          "independent": independent,
                          "independent_rel_diff": None if independent is None else
                          float(np.max(np.abs(reference - independent) / np.abs(independent)))},
            "error_scale": scale,
            "time_reference": None if time_ref is None else {
                "method": time_ref.method.label, "elements": time_ref.method.elements,
                "dt_s": time_ref.value_of_ladder, "value": time_ref.result},
            "runs": [{"method": r.method.label, "refined": r.method.variable,
                      "elements": r.method.elements if r.method.variable == "dt_s" else r.value_of_ladder,
                      "dt_s": r.value_of_ladder if r.method.variable == "dt_s" else None,
                      "step": _step(r.method, r.value_of_ladder),
                      "value": r.result, "error": r.error, "order": r.order, "wall_s": r.wall_s,
                      "failed": r.failed}
                     for r in runs],
            "ranks": comm.size, "wall_s": time.perf_counter() - start,
        }
        if outdir is not None:
            write_outputs(Path(outdir), summary, by_method, qty, name)
            log(f"  wrote {outdir}/converge.csv, converge.md, work_precision.png, summary.json")
        for label, series in by_method.items():
            orders = [f"{r.order:.2f}" for r in series if np.isfinite(r.order)]
            log(f"  {label:>10}: errors {' '.join(f'{r.error:.1e}' for r in series)}; "
                f"observed orders {' '.join(orders)}")
    return comm.bcast(summary, root=0)


def write_outputs(outdir: Path, summary: dict, by_method: dict, qty: Quantity, name: str):
    outdir.mkdir(parents=True, exist_ok=True)
    writers.write_json(outdir / "summary.json", summary)
    var = qty.methods[0].variable
    with open(outdir / "converge.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["method", "elements", "dt_s", *[f"{c} [{qty.unit}]" for c in qty.components],
                    "rel_error", "observed_order", "wall_s", "failed"])
        for r in summary["runs"]:
            w.writerow([r["method"], r["elements"], "" if r["dt_s"] is None else r["dt_s"],
                        *[f"{v:.12g}" for v in r["value"]],
                        f"{r['error']:.3e}", "" if not np.isfinite(r["order"]) else f"{r['order']:.2f}",
                        f"{r['wall_s']:.3f}", r["failed"] or ""])
    ref = summary["reference"]
    lines = [f"# Convergence of `{qty.name}` ({name})", "",
             f"Error: relative to the finest run of {ref['method']} ({var} = {ref[var]}), "
             f"value {np.array2string(np.asarray(ref['value']), precision=10)} {qty.unit}."]
    if summary.get("error_scale") is not None:
        lines.append(f"Errors are |value - reference| / {summary['error_scale']:g} {qty.unit} (the "
                     f"value itself is near zero): {qty.scale_note}")
    tref = summary.get("time_reference")
    if tref is not None:
        lines.append(f"The dt ladders (fixed steps) are measured against {tref['method']} at "
                     f"dt = {tref['dt_s']:g} s (N = {tref['elements']}), value "
                     f"{np.array2string(np.asarray(tref['value']), precision=10)} {qty.unit}: "
                     f"their error is the time error alone, at that N.")
    if ref["independent"] is not None:
        lines.append(f"That reference differs from the independent one by "
                     f"{ref['independent_rel_diff']:.1e} (relative).")
    lines += ["", f"| method | run | value [{qty.unit}] | rel. error | observed order | wall [s] |",
              "| --- | --- | --- | --- | --- | --- |"]
    for r in summary["runs"]:
        value = ", ".join(f"{v:.8g}" for v in r["value"])
        order = "" if not np.isfinite(r["order"]) else f"{r['order']:.2f}"
        wall = f"{r['wall_s']:.3f}" if not r["failed"] else f"failed: {r['failed'][:80]}"
        lines.append(f"| {r['method']} | {r['step']} | {value} | {r['error']:.2e} | {order} | {wall} |")
    (outdir / "converge.md").write_text("\n".join(lines) + "\n")
    work_precision_png(outdir / "work_precision.png", by_method, qty, name)


def work_precision_png(path: Path, by_method: dict, qty: Quantity, name: str):
    """Error against wall time, one curve per method."""
    plt = writers._pyplot()
    fig, ax = plt.subplots(figsize=(7.5, 5))
    for label, series in by_method.items():
        pts = [(r.wall_s, r.error) for r in series if r.error > 0 and np.isfinite(r.error)]
        if pts:
            w, e = zip(*pts)
            timed = qty.time_reference and series[0].method.variable == "dt_s"
            ax.loglog(w, e, "s--" if timed else "o-",
                      label=f"{label}: time error only" if timed else label)
    for level in (1e-2, 1e-3, 1e-4):
        ax.axhline(level, color="0.7", lw=0.8, ls=":")
    ax.set_xlabel("wall time per run [s]")
    ax.set_ylabel("relative error")
    ax.set_title(f"work-precision: {qty.name} ({name})")
    ax.grid(True, which="both", alpha=0.2)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
