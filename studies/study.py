"""`rawehelix study`: named quantities over a design of scene keys, on MPI ranks.

    rawehelix study SCENE --vary KEY=START:STOP:COUNT [--vary ...]
                    [--sample grid|lhs|sobol --points N] --quantity Q[,Q...] [-o DIR]

``KEY`` is any dotted scene key (``helix.EI_Nm2``, ``damping.bending_s``);
every point's scene is validated like a scene file before anything runs (a
bad key or value: the scene loader's message, exit status 2).  The design:

* ``grid``: the Cartesian product of ``numpy.linspace(START, STOP, COUNT)``
  over the keys (the first key varies slowest);
* ``lhs``: N points of a Latin hypercube (``scipy.stats.qmc.LatinHypercube``)
  in the box [START, STOP]^d (COUNT is not used);
* ``sobol``: Saltelli's design for Sobol' indices from SALib
  (``SALib.sample.sobol``, built on ``scipy.stats.qmc.Sobol``): N base points,
  N (d + 2) scenes (first-order and total indices, no second-order ones).

Besides the design, the base point (the scene's own values) and, for each key,
two points p0 (1 -+ h) (``fd_step`` h, default 1e-2) give the normalised
sensitivities at the base point by central differences,

    d ln Q / d ln p ~ (Q(p0 (1 + h)) - Q(p0 (1 - h))) / (Q(p0) ln((1 + h) / (1 - h))),

exact for Q ~ p^a; none for a key whose base value is 0 or an integer.  When
sampled, the variance-based indices come from SALib: Sobol' S1 and ST
(``SALib.analyze.sobol``) for ``sobol``, S1 by RBD-FAST
(``SALib.analyze.rbd_fast``, any sample) for ``lhs``.

Every point is one evaluation (:mod:`rawehelix.studies.quantities`) on
COMM_SELF, taken by the ranks from a shared counter and stored as it ends
(:mod:`rawehelix.studies.pool`: resumable, failures recorded).  Outputs in
``DIR``: ``study.csv`` (one row per point in point order: the keys, the
quantities, then id, kind, status and the reason of a failure; the same
bytes for any number of ranks), ``summary.json``, ``study.png`` (each
quantity against each key) and ``tornado.png`` (the sensitivities).

The summary's ``status`` is "all done" or "done with failures" (``failed``
lists each failed point and its reasons).  Exit status: 0 all done; 3
(``EXIT_UNMET``, "done with failures"; the outputs are written); 2 bad
input, refused before any point runs (a design past the memory or time
limits of :mod:`rawehelix.studies.resources` too).

The design and its analysis (sensitivities, SALib's indices) are
:mod:`rawehelix.studies.sampling`; this module runs them and writes the outputs.
"""

from __future__ import annotations

import csv
import dataclasses
import io
import math
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from mpi4py import MPI

from rawehelix.errors import SceneError
from rawehelix.parameters import Parameters
from rawehelix.studies import pool, quantities, scene, seeds
# the design and its analysis; parse_vary, design and variance_indices are the study's too
from rawehelix.studies.store import writers
from rawehelix.studies.sampling import (SAMPLES, SEED, Variable, design, design_size,  # noqa: F401
                                        parse_vary, sensitivities, variance_indices)

FD_STEP = 1e-2  # relative step of the central differences at the base point
#: exit status of a study or a calibration that ran to its end but did not do all it
#: was asked: failed points ("done with failures"), missed targets (calibrate), a fit
#: whose data could not determine its parameters (calibrate, labtest --fit: fits.py)
EXIT_UNMET = 3
STATUS = {False: "all done", True: "done with failures"}


@dataclass(frozen=True)
class Source:
    """How every point's scene is made: the scene file (or shipped name), the
    discretisation and the base overrides (``--set``), plus the point's keys."""

    path: str
    elements: int | None = None
    degree: int | None = None
    scheme: str | None = None
    overrides: dict = field(default_factory=dict)

    def load(self, extra: dict | None = None) -> Parameters:
        return scene.load(self.path, elements=self.elements, degree=self.degree,
                          scheme=self.scheme, overrides={**self.overrides, **(extra or {})})


key_type = scene.key_type  # the key's value type; an optional number's is the number's


def cast(key: str, value: float):
    """A design value for the key: a float, or for an integer key the integer it is
    (SceneError on --vary if it is not one: a grid of an integer key is refused, never
    rounded)."""
    if key_type(key) != "int":
        return float(value)
    nearest = round(value)
    if abs(value - nearest) > 1e-9 * max(1.0, abs(value)):
        raise SceneError("--vary", key, f"is an integer key, and its range gives it {value:g}: "
                         "choose START, STOP and COUNT whose values are integers (STOP - START "
                         f"a multiple of COUNT - 1), e.g. {key}=2:4:3")
    return int(nearest)


def fd_points(base: dict, fd_step: float) -> tuple[list, dict]:
    """The tasks of the sensitivities at the base point, and why a key has none."""
    tasks, skipped = [pool.Task("base", {}, "base")], {}
    if fd_step <= 0:
        return [], {k: "fd_step = 0" for k in base}
    for key, p0 in base.items():
        if isinstance(p0, bool) or not isinstance(p0, (int, float)) or key_type(key) == "int":
            skipped[key] = "not a real-valued key"
        elif p0 == 0:
            skipped[key] = "base value 0 (no logarithmic derivative)"
        else:
            tasks += [pool.Task(f"fd_{key}_{side}", {key: p0 * (1 + sign * fd_step)}, "fd")
                      for side, sign in (("minus", -1), ("plus", 1))]
    return tasks, skipped


def make_tasks(source: Source, variables: list[Variable], sample: str, points, fd_step: float,
               check=None):
    """(tasks, design (n, d), base values, skipped keys), every scene validated
    (and passed to ``check(params)``, e.g. the resources' check)."""
    from rawehelix.studies import resources
    keys = [v.key for v in variables]
    if len(set(keys)) != len(keys):
        raise SceneError("--vary", ", ".join(keys), "each key once")
    integers = [v.key for v in variables if key_type(v.key) == "int"]
    if integers and sample != "grid":
        raise SceneError("--sample", sample, f"{integers[0]} is an integer key, and {sample} "
                         "samples real values: use --sample grid with integer values")
    base_params = source.load()
    base = {}
    for v in variables:
        source.load({v.key: cast(v.key, v.start)})  # an unknown key: the loader's message
        base[v.key] = base_params.value(v.key)
    resources.check_count("--vary/--points", design_size(variables, sample, points))
    X = design(variables, sample, points)
    tasks = [pool.Task(f"p{k:05d}", {key: cast(key, x) for key, x in zip(keys, row)})
             for k, row in enumerate(X)]
    extra, skipped = fd_points(base, fd_step)
    tasks += extra
    for task in tasks:  # every point's scene, validated before anything runs
        params = source.load(task.overrides)
        if check:
            check(params)
    return tasks, X, base, skipped


@dataclass
class StudyResult:
    scene: str
    title: str
    variables: list
    wanted: list
    sample: str
    records: dict  # id -> record, in point order
    summary: dict

    @property
    def exit_status(self) -> int:
        """0: all done; EXIT_UNMET: done with failures."""
        return EXIT_UNMET if self.summary["failed"] else 0

    def column(self, name: str, kind: str = "design") -> np.ndarray:
        return np.array([np.nan if r["values"][name] is None else r["values"][name]
                         for r in self.records.values() if r["kind"] == kind])

    def keys_of(self, kind: str = "design") -> np.ndarray:
        return np.array([[r["overrides"][v.key] for v in self.variables]
                         for r in self.records.values() if r["kind"] == kind], dtype=float)

    def csv_text(self) -> str:
        """study.csv: the same bytes for the same points, whichever rank computed them."""
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        keys = [v.key for v in self.variables]
        w.writerow([*keys, *self.wanted, "id", "kind", "status", "error"])
        for r in self.records.values():
            over = r["overrides"]
            w.writerow([repr(over[k]) if k in over else repr(self.summary["base"][k])
                        for k in keys]
                       + ["" if r["values"][q] is None else repr(r["values"][q])
                          for q in self.wanted]
                       + [r["id"], r["kind"], r["status"], "; ".join(r["errors"].values())])
        return buf.getvalue()

    def write(self, outdir) -> Path:
        outdir = Path(outdir)
        outdir.mkdir(parents=True, exist_ok=True)
        writers.write_text(outdir / "study.csv", self.csv_text())
        writers.write_json(outdir / "summary.json", self.summary)
        scatter_png(outdir / "study.png", self)
        rows = self.summary.get("seeds")
        if rows:  # a seed study (issue 44): the statistics over seeds against the key
            from rawehelix.studies.present.seeds_figure import seeds_png
            x_key = seeds.WIND_KEY if seeds.WIND_KEY in rows[0]["keys"] else next(
                iter(rows[0]["keys"]), None)
            if x_key is not None:  # a key besides the seed (the scene's wind at least)
                seeds_png(outdir / "seeds.png", rows, self.wanted, x_key,
                          self.summary.get("operating_curve"), seeds.CURVE_FIELDS,
                          f"{self.title}: over {self.summary['seed_count']} seeds")
        tornado_png(outdir / "tornado.png", self.summary["sensitivities"],
                    f"{self.title}: d ln Q / d ln p at the base point "
                    f"(h = {self.summary['fd_step']:g})")
        return outdir


def scatter_png(path: Path, result: StudyResult):
    """Each quantity (rows) against each key (columns), the base point marked."""
    plt = writers._pyplot()
    nq, nv = len(result.wanted), len(result.variables)
    # each key's column shares its range: a quantity given at one point alone keeps it
    # (at least 6.4 in wide, so that one key's column keeps the whole title)
    fig, axes = plt.subplots(nq, nv, figsize=(max(3.4 * nv + 0.6, 6.4), 2.6 * nq + 0.6),
                             squeeze=False, sharex="col")
    X = result.keys_of()
    base = result.records.get("base")
    for i, name in enumerate(result.wanted):
        Y = result.column(name)
        for j, v in enumerate(result.variables):
            ax = axes[i, j]
            if len(X):
                order = np.argsort(X[:, j], kind="stable")
                ax.plot(X[order, j], Y[order], "o", ms=3.5, color="C0")
            x0 = result.summary["base"][v.key]  # None: a key whose default is another's
            if base and base["values"][name] is not None and x0 is not None:
                ax.plot(x0, base["values"][name], "*", ms=10, color="C3", label="base point")
            ax.grid(alpha=0.3)
            if i == nq - 1:
                ax.set_xlabel(v.key)
            if j == 0:
                ax.set_ylabel(f"{name}")
    if base and axes[0, 0].get_legend_handles_labels()[0]:
        axes[0, 0].legend(fontsize=8)
    return writers._finish(fig, path, f"{result.title}: {result.sample} design, "
                           f"{len(X)} points")


def tornado_png(path: Path, sens: dict, title: str):
    """Horizontal bars of d ln Q / d ln p, one panel per quantity, largest on top."""
    plt = writers._pyplot()
    fig, axes = plt.subplots(1, len(sens), figsize=(4.2 * len(sens) + 0.8, 0.5 * max(
        len(next(iter(sens.values()))), 2) + 1.6), squeeze=False)
    for ax, (name, row) in zip(axes[0], sens.items()):
        items = sorted(((k, v) for k, v in row.items() if v is not None), key=lambda kv: abs(kv[1]))
        y = np.arange(len(items))
        ax.barh(y, [v for _, v in items], color=["C3" if v < 0 else "C0" for _, v in items])
        ax.set_yticks(y, [k for k, _ in items], fontsize=8)
        ax.axvline(0, color="k", lw=0.8)
        ax.set_title(name, fontsize=9)
        ax.grid(axis="x", alpha=0.3)
    return writers._finish(fig, path, title)


def header(source: Source, params: Parameters, variables, sample, points, wanted, fd_step):
    disc = params.discretisation
    return {"scene": params.name, "fingerprint": writers.digest(params.as_dict()),
            "scheme": disc.scheme, "elements": disc.elements, "degree": disc.degree,
            "variables": [dataclasses.asdict(v) for v in variables], "sample": sample,
            "points": points, "seed": SEED, "quantities": list(wanted), "fd_step": fd_step}


def compute(source: Source, variables: list[Variable], wanted: list[str], outdir,
            sample: str = "grid", points: int | None = None, fd_step: float | None = None,
            comm=MPI.COMM_WORLD, log=None, point_timeout: float | None = None) -> StudyResult:
    """Run (or resume) the study in ``outdir`` on the ranks of ``comm``
    (collective); the result on every rank.  ``fd_step``: None is FD_STEP, 0
    no sensitivities.  ``point_timeout``: seconds (wall) after which a point
    fails (:func:`rawehelix.studies.pool.time_limit`; a rerun with a longer
    limit or none computes it again).  Raises SceneError for bad input before
    anything is computed or written."""
    start = time.perf_counter()
    fd_step = FD_STEP if fd_step is None else fd_step
    if sample not in SAMPLES:
        raise SceneError("--sample", sample, f"must be one of {', '.join(SAMPLES)}")
    if not variables:
        raise SceneError("--vary", "", "give at least one KEY=START:STOP:COUNT")
    wanted = [q for q in wanted]
    for name in wanted:
        quantities.parse(name)
    if not 0 <= fd_step < 1:
        raise SceneError("--fd-step", fd_step, "must be in [0, 1)")
    if point_timeout is not None and not (point_timeout > 0 and math.isfinite(point_timeout)):
        raise SceneError("--point-timeout", point_timeout, "must be a number of seconds > 0")
    if point_timeout is not None and threading.current_thread() is not threading.main_thread():
        raise SceneError("--point-timeout", point_timeout, "needs the main thread (SIGALRM)")
    from rawehelix.studies import resources
    tasks, X, base, skipped = make_tasks(
        source, variables, sample, points, fd_step,
        check=lambda p: resources.check_quantities(p, wanted, copies=comm.size))
    params = source.load()
    # the points' records on the disk (a seed study's seeds x winds too), before any runs
    from rawehelix.studies import needs
    from rawehelix.studies.store import outdir as outdir_check
    outdir_check.check(outdir, needs.get("study"), points=len(tasks))
    store = pool.Store(outdir, header(source, params, variables, sample, points, wanted,
                                      fd_step)).open(comm)
    out = pool.run(tasks, source.load, wanted, store, comm=comm, log=log,
                   point_timeout=point_timeout)
    records = out["records"]
    loops = comm.allgather({"rank": comm.rank, **{k: v for k, v in out.items()
                                                  if k.startswith("loop_")}})
    sens = sensitivities(records, base, wanted, fd_step)
    design_records = [r for r in records.values() if r["kind"] == "design"]
    indices = {}
    for name in wanted:
        Y = np.array([np.nan if r["values"][name] is None else r["values"][name]
                      for r in design_records])
        indices[name] = variance_indices(sample, variables, X, Y)
    cost = {}
    for r in records.values():
        for stage, c in r["cpu_s"].items():
            cost.setdefault(stage, []).append(c)
    failed = {r["id"]: r["errors"] for r in records.values() if r["status"] == "failed"}
    summary = {**store.header, "status": STATUS[bool(failed)], "base": base,
               "design_points": len(X),
               "points_total": len(tasks),
               "sensitivity": "d ln Q / d ln p = (Q(p0 (1 + h)) - Q(p0 (1 - h))) / "
                              "(Q(p0) ln((1 + h) / (1 - h))), h = fd_step",
               "sensitivities": sens, "sensitivities_skipped": skipped,
               "variance_indices": indices if sample != "grid" else None,
               "failed": failed,
               "cpu_s_per_point_by_stage": {s: float(np.median(c)) for s, c in cost.items()},
               "point_timeout_s": point_timeout,
               "computed_now": out["computed"], "ranks": comm.size, "loops": loops,
               "wall_s": time.perf_counter() - start}
    from rawehelix.operation.wind import reference_speed
    rows = seeds.statistics(records, variables, wanted, reference_speed(params))
    if rows is not None:  # a seed study (issue 44): statistics over the seeds
        summary["seeds"] = rows
        summary["seed_count"] = len({r["overrides"][seeds.SEED_KEY] for r in records.values()
                                     if r["kind"] == "design"})
        speeds = seeds.winds(rows)
        summary["operating_curve"] = (seeds.operating_curve(params, speeds, comm) if speeds
                                      and params.rotor.active else None)
    return StudyResult(params.name, params.title or params.name, variables, wanted, sample,
                       records, summary)


def report(result: StudyResult) -> str:
    s = result.summary
    lines = [f"{result.title}: {s['design_points']} design points + {s['points_total'] - s['design_points']} "
             f"for the sensitivities ({s['computed_now']} computed now, {s['ranks']} rank(s), "
             f"{s['wall_s']:.1f} s); {len(s['failed'])} failed: {s['status']}"]
    for name, row in s["sensitivities"].items():
        shown = ", ".join(f"{k} {v:+.3f}" for k, v in row.items() if v is not None)
        if shown:
            lines.append(f"  d ln {name} / d ln p: {shown}")
    for row in s.get("seeds") or []:  # a seed study: the statistics over the seeds
        at = ", ".join(f"{k} = {v:g}" for k, v in row["keys"].items())
        shown = "; ".join(f"{name} {q['mean']:.4g} +- {q['std'] or 0:.3g} (max {q['max']:.4g})"
                          for name, q in row["quantities"].items() if q["mean"] is not None)
        lines.append(f"  over {s['seed_count']} seeds at {at or 'the base'}: {shown}")
    for pid, errors in list(s["failed"].items())[:5]:
        lines.append(f"  failed {pid}: {'; '.join(errors.values())}")
    return "\n".join(lines)
