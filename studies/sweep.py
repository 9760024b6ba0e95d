"""The frequency sweep of Sec. 5.3 (Fig. 8): resumable and MPI-parallel.

For each f1 the response is integrated until periodic (see
:mod:`rawehelix.solvers.periodic`) and the maximum, minimum and mean tension at
s = 0 over the last periods are recorded.  Each f1 continues from the final
state of the previous one, as in the paper.

Under ``mpirun -n k`` the sorted frequency list is cut into k contiguous
chunks of about equal estimated cost (:func:`chunks`); each rank runs its chunk
on its own communicator (COMM_SELF), with continuation inside the chunk; the
first point of a chunk starts from the stationary state with a lead-in
(``sweep.lead_in_s``).  Rank 0 gathers.

:func:`compute` returns a :class:`SweepResult` and writes nothing, unless the
caller names a ``checkpoint`` directory, which makes the sweep resumable:

    sweep.json          the results file: fingerprint and finished points,
                        rewritten atomically after every point
    points/f1_*.json    one finished point (entry and its tension series)
    points/f1_*.npz     its final state, for continuation and resuming
    computed.log        one line per point computed (to check resuming)

The same call again skips finished points; a checkpoint of another scene or
discretisation is refused.  :meth:`SweepResult.write` writes summary.json
(points, resonance_Hz, elements, degree, ranks, wall_s) and sweep.png (Fig. 8,
with T(t) near 10 Hz in a panel of its own).
"""

from __future__ import annotations

import logging
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from mpi4py import MPI

from rawehelix.parameters import Parameters, Sweep
from rawehelix.solvers import stepsize
from rawehelix.solvers.periodic import periodic_response
from rawehelix.solvers.snes import SolverError
from rawehelix.studies import forcing, limits, schemes, sweep_advice
from rawehelix.studies.analysis import branch_limits
from rawehelix.studies.store import writers
from rawehelix.studies.store.sweep_store import DirectoryStore, MemoryStore, _key, fingerprint, scene_keys
from rawehelix.studies.store.writers import SCENE_KEYS
from rawehelix.studies.scene import SceneError

def make_backend(params: Parameters, comm, track: bool = True):
    """The integrator for the scene's scheme; with ``track``, and a backend that has
    the rod's fields along s (FE), it samples the section for the limits block."""
    backend = schemes.of(params).forced_backend(params, comm)
    if track:
        backend.track_sections()
    return backend


def validate_frequencies(f1_Hz) -> list[float]:
    """The f1 list, checked once: finite numbers > 0 [Hz], sorted, without repeats."""
    try:
        values = [float(f) for f in f1_Hz]
    except (TypeError, ValueError):
        raise SceneError("sweep", "f1_Hz", f"{f1_Hz!r}: must be a list of numbers [Hz]") from None
    if not values:
        raise SceneError("sweep", "f1_Hz", "must hold at least one frequency")
    bad = [f for f in values if not (f > 0 and np.isfinite(f))]
    if bad:
        raise SceneError("sweep", "f1_Hz", f"{bad[0]!r}: every f1 must be a finite number > 0 [Hz]")
    return sorted({round(f, 10) for f in values})


def run_chunk(params: Parameters, store, chunk: list[float], backend=None, log=None,
              track: bool = True, show_progress: bool = False) -> int:
    """Run one rank's contiguous chunk with continuation; return the points computed.
    ``track``: each point's limits block over its recorded periods (branch_limits.py);
    ``show_progress``: a bar of the periods within each point (:class:`PeriodBar`)."""
    log = log or logging.getLogger("rawehelix").info

    def backend_factory():
        return make_backend(params, MPI.COMM_SELF, track)

    backend = backend or backend_factory()
    q = params.normalised()
    state, t, computed = None, 0.0, 0
    for i, f1 in enumerate(chunk):
        if store.finished(f1) is not None:
            state = None  # the next unfinished point reloads its predecessor's state
            continue
        lead_in = True
        if state is None:
            prev = store.state(chunk[i - 1]) if i > 0 else None
            if prev is not None:
                state, t = backend.unpack(prev), float(prev["t"])
                lead_in = False
            else:
                state, t = backend.stationary(), 0.0
        else:
            lead_in = False
        try:
            with PeriodBar(f1, params.sweep, show_progress) as bar:
                result, state, t = periodic_response(backend, q, f1, state, t, params.sweep,
                                                     lead_in, progress=bar)
        except (SolverError, FloatingPointError, RuntimeError) as err:
            # the point is recorded as failed; the next one starts afresh
            entry = {"f1_Hz": f1, "tension_max_N": None, "tension_min_N": None,
                     "tension_mean_N": None, "periods": 0, "periodic": False, "slack": None,
                     "failed": str(err), "wall_s": None, "start": "stationary" if lead_in
                     else "continuation"}
            entry = branch_limits.with_block(entry, branch_limits.absent(branch_limits.FAILED))
            store.save(f1, {"entry": entry}, None, " failed")
            log(f"  f1 = {f1:6.2f} Hz: FAILED: {err}")
            backend, state, computed = backend_factory(), None, computed + 1
            continue
        block = (branch_limits.point_block(params, result.sections) if track
                 else branch_limits.absent("not recorded (tracking off)"))
        if result.unsettled is not None:  # why, and what to try (studies/sweep_advice.py)
            result.unsettled["advice"] = sweep_advice.advice(params, result.unsettled, f1)
        store.save(f1, {"entry": branch_limits.with_block(result.entry(), block),
                        "period_maxima_N": result.period_maxima_N,
                        "period_minima_N": result.period_minima_N,
                        "series_t_s": result.series_t_s, "series_tension_N": result.series_tension_N},
                   {**backend.pack(state), "t": t})
        computed += 1
        flag = ("" if result.periodic else "  NOT PERIODIC (hit max_periods)") + \
            ("  SLACK (T <= 0)" if result.slack else "")
        log(f"  f1 = {f1:6.2f} Hz: T max {result.tension_max_N:8.2f} N, min "
            f"{result.tension_min_N:8.2f} N, {result.periods:3d} periods, "
            f"{result.wall_s:6.1f} s ({result.start}){flag}"
            + (f", M/(NR) max {block['moment_ratio_max']['value']:.3f}"
               if isinstance(block.get("moment_ratio_max"), dict) else ""))
        if result.unsettled is not None:
            for line in sweep_advice.lines(params, result.unsettled, f1):
                log(line)
    return computed


class PeriodBar:
    """Periods done of ``sweep.max_periods`` at one f1 and the periodicity test's
    measure (what remains of the transient over what is allowed), as a tqdm bar on
    a terminal (``show``), cleared when the point ends; nothing otherwise (a log
    file gets the point's one line).  Entered, it is periodic_response's
    ``progress``."""

    def __init__(self, f1: float, sweep: Sweep, show: bool):
        self.f1, self.sweep, self.show, self.bar = f1, sweep, show, None

    def __enter__(self):
        if self.show:
            from tqdm import tqdm
            self.bar = tqdm(total=self.sweep.max_periods, unit="period", leave=False,
                            desc=f"  f1 = {self.f1:6.2f} Hz",
                            bar_format="{desc}: {n}/{total} periods{postfix} |{bar}| "
                                       "[{elapsed}<{remaining}]")
        return self if self.bar is not None else None

    def __call__(self, k: int, measure):
        self.bar.update(k - self.bar.n)
        if measure is not None:
            left = ("not decaying" if measure.remainder is None
                    else f"{measure.remainder / max(measure.allowed, 1e-300):.3g}")
            self.bar.set_postfix_str(f"remainder / allowed {left}", refresh=False)

    def __exit__(self, *exc):
        if self.bar is not None:
            self.bar.close()
        return False


#: estimated forcing periods for one point to become periodic after
#: continuation, beyond its minimum periods; measured on Sec. 5.3 (N = 8, the
#: periodicity test of issue 13, 2026-12-03): 200-260 below 3 Hz, 30-130 over
#: 4.5-12.5 Hz, 180-280 past the resonance where the response jumps branch
SETTLE_PERIODS = 150


def point_cost(f1: float, sweep: Sweep) -> float:
    """Estimated simulated time of one point [s]: the cost model of :func:`chunks`."""
    return (sweep.min_periods + SETTLE_PERIODS) / f1


def chunks(frequencies: list[float], k: int, sweep: Sweep | None = None) -> list[list[float]]:
    """k contiguous chunks of the sorted list.

    Without ``sweep``: sizes differing by at most one.  With it: the largest
    estimated simulated time of a chunk is as small as it can be, counting
    ``point_cost`` per point and ``sweep.lead_in_s`` once per chunk (a low f1
    has long periods, so the low chunk gets fewer points).  Time steps have a
    fixed length, so the wall time of a chunk follows its simulated time."""
    f = sorted(frequencies)
    if sweep is None or k <= 1 or len(f) <= k:
        return [list(c) for c in np.array_split(np.array(f), k)]
    w = np.array([point_cost(x, sweep) for x in f])
    prefix = np.concatenate([[0.0], np.cumsum(w)])
    n = len(f)
    # best[j][i]: the smallest largest cost of the first i points in j chunks
    best = np.full((k + 1, n + 1), np.inf)
    cut = np.zeros((k + 1, n + 1), dtype=int)
    best[0][0] = 0.0
    for j in range(1, k + 1):
        for i in range(j, n + 1):
            for m in range(j - 1, i):
                cost = max(best[j - 1][m], sweep.lead_in_s + prefix[i] - prefix[m])
                if cost < best[j][i]:
                    best[j][i], cut[j][i] = cost, m
    bounds, i = [], n
    for j in range(k, 0, -1):
        bounds.append((cut[j][i], i))
        i = cut[j][i]
    return [f[a:b] for a, b in reversed(bounds)]


@dataclass
class SweepResult:
    """The points of a sweep (rank 0; empty elsewhere) and its summary."""

    params: Parameters
    points: list  # summary entries, sorted by f1: f1_Hz, tension_max_N, ..., periodic
    series: dict = field(default_factory=dict)  # f1 -> (t_s, tension_N) over the recorded periods
    summary: dict = field(default_factory=dict)
    rank: int = 0

    def write(self, outdir, series: bool = False) -> Path:
        """summary.json and sweep.png (and, with ``series``, each point's T(t) as CSV)."""
        outdir = Path(outdir)
        if self.rank != 0:
            return outdir
        outdir.mkdir(parents=True, exist_ok=True)
        writers.write_json(outdir / "summary.json", self.summary)
        sweep_png(outdir / "sweep.png", self.points, self.series, self.params.name,
                  firsts=self.summary.get("limits_first_by_kind", {}))
        if series:
            write_series(outdir, self.series)
        return outdir


def compute(params: Parameters, f1_Hz=None, comm=MPI.COMM_WORLD, checkpoint=None,
            log=None, track: bool = True) -> SweepResult:
    """The periodic response at each f1 [Hz] (default: the scene's [sweep] list).

    ``checkpoint``: a directory that keeps finished points, so that the same
    call resumes a stopped sweep (see the module docstring); without it the
    sweep writes nothing.  Returns the :class:`SweepResult` (summary on every rank)."""
    start = time.perf_counter()
    forcing.require(params, "sweep")
    limits.check_bending_resolution(params, "sweep")
    frequencies = validate_frequencies(params.sweep.frequencies() if f1_Hz is None else f1_Hz)
    stepsize.check(params, frequencies)  # FE: fixed steps resolve the forcing and omega_L
    disc = params.discretisation
    header = {"scene": params.name, "fingerprint": fingerprint(params), "scheme": disc.scheme,
              "elements": disc.elements, "degree": disc.degree if schemes.of(params).has_degree else None}
    if checkpoint is not None:
        store = DirectoryStore(Path(checkpoint), {**header, SCENE_KEYS: scene_keys(params)})
        store.open(comm)
    else:
        store = MemoryStore()
    mine = chunks(frequencies, comm.size, params.sweep)[comm.rank]
    rank_log = log or logging.getLogger("rawehelix").info
    if comm.size > 1:
        rank_log = (lambda m, _log=rank_log: _log(f"[rank {comm.rank}]{m}"))
    if comm.rank == 0 and sweep_advice.too_few_periods(params.sweep):
        logging.getLogger("rawehelix").warning(sweep_advice.too_few_periods(params.sweep))
    if mine:
        rank_log(f"  chunk {mine[0]:.2f}-{mine[-1]:.2f} Hz ({len(mine)} points)")
    show = sys.stderr.isatty() and comm.size == 1  # a terminal, not a log file (or ranks)
    computed = run_chunk(params, store, mine, log=rank_log, track=track, show_progress=show)
    computed = comm.allreduce(computed, op=MPI.SUM)
    records = store.all_records(comm)
    result = SweepResult(params, [], rank=comm.rank)
    summary = None
    if comm.rank == 0:
        wanted = {round(f, 5) for f in frequencies}
        records = sorted((r for r in records if round(r["entry"]["f1_Hz"], 5) in wanted),
                         key=lambda r: r["entry"]["f1_Hz"])
        points = [branch_limits.loaded(r["entry"]) for r in records]
        result.points = points
        result.series = {r["entry"]["f1_Hz"]: (np.asarray(r["series_t_s"]),
                                                np.asarray(r["series_tension_N"]))
                         for r in records if r.get("series_t_s") is not None
                         and len(r["series_t_s"])}
        good = [p for p in points if p.get("tension_max_N") is not None]
        peak = max(good, key=lambda p: p["tension_max_N"]) if good else None
        summary = {**header, "points": points,
                   "resonance_Hz": peak["f1_Hz"] if peak else None,
                   "peak_tension_N": peak["tension_max_N"] if peak else None,
                   "not_periodic_Hz": [p["f1_Hz"] for p in points if not p["periodic"]],
                   "slack_Hz": [p["f1_Hz"] for p in points if p.get("slack")],
                   "failed_Hz": [p["f1_Hz"] for p in points if p.get("failed")],
                   "limits": branch_limits.over_points(points),
                   "limits_first_by_kind": branch_limits.first_by_kind(points),
                   "ranks": comm.size, "computed_now": computed,
                   "model": params.describe_model(),
                   "wall_s": time.perf_counter() - start}
    result.summary = comm.bcast(summary, root=0)
    return result


def write_series(outdir: Path, series: dict):
    """Per-point time series of the tension at s = 0 (CSV) over the recorded periods."""
    (Path(outdir) / "points").mkdir(parents=True, exist_ok=True)
    for f1, (t, T) in series.items():
        path = Path(outdir) / "points" / f"{_key(f1)}_tension.csv"
        np.savetxt(path, np.column_stack([t, T]), delimiter=",", header="t_s,tension_s0_N",
                   comments="")


def sweep_png(path: Path, points: list[dict], series: dict, title: str, inset_Hz: float = 10.0,
              firsts: dict | None = None):
    """Fig. 8 (:func:`sweep_figure`) written to ``path``; None without a finished point."""
    fig = sweep_figure(points, series, title, inset_Hz, firsts)
    if fig is None:
        return None
    fig.savefig(path, dpi=120)
    writers._pyplot().close(fig)
    return path


def _legend_beside(ax, **kw):
    """A legend right of the axes, never on the data."""
    return ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, **kw)


def sweep_figure(points: list[dict], series: dict, title: str, inset_Hz: float = 10.0,
                 firsts: dict | None = None):
    """Fig. 8: maximum tension at s = 0 against f1, the section's moment ratio
    below it, and T(t) near ``inset_Hz`` in a panel of its own; each limit's first
    f1 (``firsts``: the summary's limits_first_by_kind) a vertical line; the legends
    stand beside the axes, so nothing is drawn over the data."""
    failed = [p["f1_Hz"] for p in points if p.get("tension_max_N") is None]
    points = [p for p in points if p.get("tension_max_N") is not None]
    if not points:
        return None
    plt = writers._pyplot()
    f = np.array([p["f1_Hz"] for p in points])
    tmax = np.array([p["tension_max_N"] for p in points])
    tmin = np.array([p["tension_min_N"] for p in points])
    ok = np.array([p["periodic"] for p in points])
    rows = [3, 2, 1.6] if series else [3, 2]
    fig = plt.figure(figsize=(10, 8 + 2.4 * bool(series)))
    grid = fig.add_gridspec(len(rows), 1, height_ratios=rows)
    ax = fig.add_subplot(grid[0])
    ax_m = fig.add_subplot(grid[1], sharex=ax)
    ax.fill_between(f, tmin, tmax, color="C0", alpha=0.15, label="min-max over the last periods")
    ax.plot(f, tmax, "-", color="C0")
    ax.plot(f[ok], tmax[ok], "o", color="C0", label="T max (periodic)")
    if np.any(~ok):
        ax.plot(f[~ok], tmax[~ok], "x", color="C3", ms=9, label="T max (not periodic: cap hit)")
    for k, f1 in enumerate(failed):
        ax.axvline(f1, color="C3", ls="--", lw=1, label="failed (see summary)" if k == 0 else None)
    branch_limits.mark_firsts((ax, ax_m), firsts or {})
    ax.set_ylabel("tension at s = 0 [N]")
    ax.set_title(f"{title}: maximum tension against f1 (Fig. 8)")
    ax.grid(True, alpha=0.3)
    ax.tick_params(labelbottom=False)
    _legend_beside(ax, fontsize=9)
    branch_limits.moment_ratio_panel(ax_m, points)
    _legend_beside(ax_m, fontsize=8)
    ax_m.set_title("the section: max |M| / (N R) over the recorded periods (limits block)",
                   fontsize=9)
    if series:
        near = min(series, key=lambda f1: abs(f1 - inset_Hz))
        t, T = series[near]
        ax_t = fig.add_subplot(grid[2])
        ax_t.plot(t - t[0], T, "-", lw=1)
        ax_t.set_title(f"T(t) at s = 0, f1 = {near:g} Hz", fontsize=9)
        ax_t.set_xlabel("t [s]")
        ax_t.set_ylabel("T [N]")
        ax_t.grid(True, alpha=0.3)
    fig.tight_layout()
    return fig


def report(result: SweepResult) -> str:
    """The lines a user reads after a sweep."""
    s = result.summary
    lines = [f"{s['scene']}: {len(s['points'])} points ({s['computed_now']} computed now), "
             f"{s['scheme']} N = {s['elements']}, {s['ranks']} rank(s), {s['wall_s']:.1f} s"]
    if s["resonance_Hz"] is not None:
        lines.append(f"  largest T max at f1 = {s['resonance_Hz']} Hz: {s['peak_tension_N']:.1f} N")
    ratio = s.get("limits", {}).get("moment_ratio_max")
    if ratio:
        lines.append(f"  largest |M| / (N R): {ratio['value']:.3f} at f1 = {ratio['f1_Hz']:g} Hz")
    for key, what in (("not_periodic_Hz", "not periodic (hit sweep.max_periods)"),
                      ("slack_Hz", "slack (T <= 0)"), ("failed_Hz", "failed (see summary.json)")):
        if s[key]:
            lines.append(f"  {what}: f1 = {', '.join(f'{f:g}' for f in s[key])} Hz")
    unsettled = [p for p in s["points"] if p.get("not_periodic")]
    if unsettled:  # the first one's reason and advice (each point's: summary.json)
        first = unsettled[0]
        lines.append(f"  at f1 = {first['f1_Hz']:g} Hz: {sweep_advice.reason(first['not_periodic'])}")
        lines += [f"    try: {a}" for a in first["not_periodic"].get("advice", [])]
        lines.append("    (each point's reason and advice: points[].not_periodic in summary.json)")
    if "limits_first_by_kind" in s:
        lines += branch_limits.first_lines(s["limits_first_by_kind"], s["limits"],
                                            scene=s["scene"])
    return "\n".join(lines)
