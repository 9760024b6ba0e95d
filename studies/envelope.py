"""`rawehelix envelope SCENE --vary KEY=LO:HI[:COUNT] --f1 LO:HI`: the operating
envelope in (f1, KEY), a design map (issue 31).

For COUNT values of the dotted scene key KEY (default DEFAULT_VALUES, the "ticks"):

1. the one-parameter branch over the f1 window (``rawehelix orbits``, by harmonic
   balance unless ``method`` says otherwise), with its folds, bifurcations and each
   point's limits block (studies/analysis/branch_limits.py);
2. the boundary where the first limit is reached: the f1 where a point's
   ``first_limit`` changes along the branch, located by bisection in f1 between the
   two branch points (FIRST_LIMIT_BISECTIONS orbits at fixed f1 and KEY, each with its
   limits over a period), reported with its bracket;
3. the fold curves: each fold of a tick continued in KEY to the next tick by the
   minimally augmented system (periodic_orbits/fold_curve.py); its end is checked
   against the next tick's own fold (``fold_check_Hz``), and a fold that has no partner
   there ends at a cusp, said so.  Where the two folds of a resonance exist, two
   stable responses coexist between them;
4. the period-doubling and Neimark-Sacker curves: each tick's PD and NS where the orbit
   loses or regains stability continued in KEY by the stability test function
   (periodic_orbits/bifurcation_curve.py), forward and back where no curve reached them,
   checked the same way (``check_Hz``).  Between two such curves the response is unstable.

The curves: studies/analysis/envelope_curves.py.

MPI: the ticks are dealt to the ranks (a rank's ticks, one branch each); the curves
are traced on rank 0 from the gathered ticks.  Resumable (``outdir``): each
tick's branch is an orbits store (``tick<k>/``), under the envelope's header
(``envelope.json``: scene, KEY and its values, f1 window, method), checked before
any tick: a rerun with any of them changed is refused (:class:`EnvelopeStoreError`)
and changes nothing in the folder.
"""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

from rawehelix.errors import SceneError, SolverError
from rawehelix.parameters import Parameters
from rawehelix.periodic_orbits.bifurcations import critical, stability_changes
from rawehelix.studies import forcing, orbit_method, orbits
from rawehelix.studies.analysis import branch_limits, envelope_curves
from rawehelix.studies.store import writers
from rawehelix.studies.store.orbits_store import OrbitsStoreError
from rawehelix.studies.sampling import Variable

DEFAULT_VALUES = 5  # ticks when --vary gives no COUNT
HEADER = "envelope.json"  # the envelope's identity in its output folder
#: the command-line way to each key of the header
OPTION_OF = {"scene": "SCENE", "fingerprint": "the scene's keys (--set, --elements, --degree, "
             "--scheme)", "key": "--vary KEY", "values": "--vary LO:HI:COUNT",
             "f1_window_Hz": "--f1", "method": "--method"}
#: the order in which a value's first limits are found along its branch
RISING = "f1 rising along the branch, read from LO of --f1"
FIRST_LIMIT_BISECTIONS = 8  # the limit's f1 to 1/256 of the branch's spacing


class EnvelopeStoreError(OrbitsStoreError):
    """The output folder holds another envelope."""


def claim(outdir, header: dict, comm):
    """Lock ``outdir`` and refuse it if it holds another envelope (its header differs),
    before any tick is opened; else write the header (collective).  The lock, held
    by the caller as long as it writes."""
    from rawehelix.studies.store import outdir_lock
    lock = outdir_lock.hold(outdir, comm)
    old = writers.claim_directory(Path(outdir) / HEADER, header, comm)
    if old is not None:
        lock.release()
        changed = writers.changed(old, header, OPTION_OF)
        raise EnvelopeStoreError(
            f"{Path(outdir) / HEADER}: holds another envelope (scene {old.get('scene')!r}, "
            f"--vary {old.get('key')} = {old.get('values')}, --f1 {old.get('f1_window_Hz')}, "
            f"--method {old.get('method')}; changed: {', '.join(changed)}); use another -o "
            f"directory or delete it")
    return lock


def values_of(vary: Variable) -> list[float]:
    from rawehelix.studies.study import cast
    count = vary.count or DEFAULT_VALUES
    if count < 2:
        raise SceneError("--vary", f"{vary.key}={vary.start}:{vary.stop}:{count}",
                         "an envelope needs COUNT >= 2 values of KEY")
    return [cast(vary.key, v) for v in np.linspace(vary.start, vary.stop, count)]


def _has(holder, name: str) -> bool:
    """``holder`` is a scene section (a dataclass) with a field ``name``."""
    return dataclasses.is_dataclass(holder) and name in {f.name for f in dataclasses.fields(holder)}


def params_at(params: Parameters, key: str, value) -> Parameters:
    """``params`` with the dotted scene key set (SceneError for a key the scene has not)."""
    section, _, name = key.partition(".")
    holder = params if _has(params, section) else params.model  # [damping], ...: the model's
    if not _has(holder, section) or not _has(getattr(holder, section), name):
        raise SceneError("--vary", key, "is not a scene key (example.toml lists them)")
    try:
        return params.replace(**{section: {name: value}})
    except (TypeError, ValueError) as err:
        raise SceneError("--vary", f"{key}={value}", str(err)) from None


@dataclasses.dataclass
class EnvelopeResult:
    scene: str
    title: str
    key: str
    values: list
    f1_window_Hz: list
    method: str
    method_reason: str
    elements: int
    ticks: list  # per value: branch (f1, T max, stable, first_limit), folds, ...
    fold_curves: list
    limit_curve: list
    wall_s: float
    fold_curves_wall_s: float = 0.0
    bifurcation_curves: list = dataclasses.field(default_factory=list)

    @property
    def summary(self) -> dict:
        worst = envelope_curves.worst_check
        return {"scene": self.scene, "key": self.key, "values": self.values,
                "f1_window_Hz": self.f1_window_Hz, "method": self.method,
                "method_reason": self.method_reason, "elements": self.elements,
                "ticks": self.ticks, "fold_curves": self.fold_curves,
                "limit_curve": self.limit_curve,
                "fold_check_max_Hz": worst(self.fold_curves, "fold_check_Hz"),
                "bifurcation_curves": self.bifurcation_curves,
                "bifurcation_check_max_Hz": worst(self.bifurcation_curves),
                "fold_curves_wall_s": self.fold_curves_wall_s, "wall_s": self.wall_s}

    def write(self, outdir) -> Path:
        from rawehelix.studies.present.envelope_figure import envelope_png
        outdir = Path(outdir)
        outdir.mkdir(parents=True, exist_ok=True)
        writers.write_json(outdir / "summary.json", self.summary)
        envelope_png(outdir / "envelope.png", self.summary, self.title)
        return outdir


def _tick(params, key, value, f1_window, method, outdir, progress, f1_step_Hz):
    """One value of KEY: its branch, limit crossings, and its folds' and bifurcations' starts."""
    p = params_at(params, key, value)
    lo, hi = f1_window
    branch = orbits.compute(p, hi, lo, comm=MPI.COMM_SELF, method=method, superharmonics=(),
                            outdir=None if outdir is None else Path(outdir),
                            progress=progress, f1_step_Hz=f1_step_Hz,
                            every_point=True)  # its PD / NS bands: every point's own Hill
    points = branch.orbits
    m = orbits.problem(p, branch.method)
    limits = branch_limits.OrbitLimits(m, p)
    crossings = [_crossing(m, limits, a, b, ea["first_limit"], eb["first_limit"], value)
                 for a, b, ea, eb in zip(points, points[1:], branch.branch, branch.branch[1:])
                 if (ea["first_limit"] is None) != (eb["first_limit"] is None)]
    starts = []
    for fold in branch.folds:
        fa, fb = fold["bracket_Hz"]
        for a, b in zip(points, points[1:]):
            if a.f1_Hz == fa and b.f1_Hz == fb:
                starts.append({"f1_Hz": fold["f1_Hz"], "Xa": a.X, "Xb": b.X,
                               "resolution": a.steps})
    bifurcation_starts = []  # where stability is lost or regained other than at a fold
    for a, b in zip(points, points[1:]):
        if stability_changes(a, b):
            inside = [e for e in branch.bifurcations
                      if min(a.f1_Hz, b.f1_Hz) <= e["f1_Hz"] <= max(a.f1_Hz, b.f1_Hz)]
            worse = max((a, b), key=lambda o: critical(o.multipliers)[0])
            kind = critical(worse.multipliers)[2]
            bifurcation_starts.append({"bracket_Hz": (a.f1_Hz, b.f1_Hz), "X": a.X,
                                       "resolution": a.steps, "kind": kind,
                                       "f1_Hz": inside[0]["f1_Hz"] if inside else a.f1_Hz})
    # the continuation's last point may land past the window's end (the step that leaves
    # it): the tick reports what lies in [LO, HI] only (the tester's D7)
    inside = lambda e: lo <= e["f1_Hz"] <= hi  # noqa: E731
    entries = [e for e in branch.branch if inside(e)]
    crossings = [c for c in crossings if inside(c)]
    rising = entries[::-1] if entries and entries[0]["f1_Hz"] > \
        entries[-1]["f1_Hz"] else entries  # traced from HI: read from LO
    tick = {"value": value, "branch": [
        {k: e.get(k) for k in ("f1_Hz", "tension_max_N", "stable", "first_limit")}
        for e in entries], "folds": [f for f in branch.folds if inside(f)],
        "bifurcations": [b for b in branch.bifurcations if inside(b)],
        "limits": branch_limits.over_points(rising, order=RISING),
        "limits_first_by_kind": branch_limits.first_by_kind(rising),
        "f1_gap_max_Hz": max((abs(b.f1_Hz - a.f1_Hz) for a, b in zip(points, points[1:])),
                             default=0.0),
        "wall_s": branch.wall_s}
    return tick, crossings, (starts, bifurcation_starts), branch.method, branch.method_reason


def _crossing(m, limits, a, b, ka, kb, value) -> dict:
    """The f1 between branch points a and b where the first limit is reached (or left),
    by bisection at fixed f1 from the nearer point's orbit."""
    X, H = a.X, a.steps
    reached = lambda o: limits.block(o)["first_limit"] is not None  # noqa: E731
    side_a = reached(a)
    f_lo, f_hi, kind = a.f1_Hz, b.f1_Hz, kb or ka
    try:
        for _ in range(FIRST_LIMIT_BISECTIONS):
            mid = 0.5 * (f_lo + f_hi)
            o = m.orbit(X, mid, steps=H)
            if reached(o) == side_a:
                f_lo, X = mid, o.X
            else:
                f_hi = mid
                kind = limits.block(o)["first_limit"]["kind"] if reached(o) else kind
    except SolverError:  # near a fold f1 does not parametrise the branch: the bracket stands
        pass
    return {"value": value, "f1_Hz": 0.5 * (f_lo + f_hi), "f1_error_Hz": 0.5 * abs(f_hi - f_lo),
            "kind": kind if isinstance(kind, str) else None, "entering": not side_a}


def compute(params: Parameters, vary: Variable, f1_lo: float, f1_hi: float,
            comm=MPI.COMM_WORLD, outdir=None, method: str = orbit_method.default_for("envelope"),
            progress=None,
            substeps: int = envelope_curves.SUBSTEPS,
            f1_step_Hz: float | None = None) -> EnvelopeResult:
    """The envelope (module docstring); ``progress(value, orbit)`` at every branch point;
    ``f1_step_Hz``: the most a branch steps in f1 (None: as its step control takes it).
    Stability is judged at the branches' points, so an unstable band narrower than
    their spacing (each tick's ``f1_gap_max_Hz``) may fall between two of them: the
    curves from other ticks still cross it."""
    if not (0 < f1_lo < f1_hi):
        raise SceneError("--f1", f"{f1_lo}:{f1_hi}", "must be LO:HI with 0 < LO < HI [Hz]")
    if params.ends.tension_N is not None:
        # continuing in KEY holds the elongation found for the scene's ends.tension_N
        # (solvers/tension_target.py), as an elongation scene holds its own
        if vary.key in ("ends.tension_N", "ends.elongation"):
            raise SceneError("--vary", vary.key, "an envelope in the end's stretch needs a "
                             "scene with ends.elongation (vary ends.elongation); 'rawehelix "
                             "stationary' prints the elongation each ends.tension_N gives")
        params = params.replace(ends={"elongation": params.ends.elongation})
    values = values_of(vary)
    for v in values:  # every value checked before any work
        at = params_at(params, vary.key, v)
        forcing.require(at, "envelope", where=f"--vary {vary.key}={v}" if vary.key
                        == "ends.circle_radius_m" else None)
        orbit_method.choose(at, method)
    lock = None
    if outdir is not None:
        from rawehelix.studies.store.sweep_store import fingerprint, scene_keys
        lock = claim(outdir, {"scene": params.name, "fingerprint": fingerprint(params),
                              writers.SCENE_KEYS: scene_keys(params),
                              "key": vary.key, "values": values, "f1_window_Hz": [f1_lo, f1_hi],
                              "method": method, "f1_step_Hz": f1_step_Hz}, comm)
    start = time.perf_counter()
    mine, error = [], None
    for k in range(comm.rank, len(values), comm.size):
        tick_dir = None if outdir is None else Path(outdir) / f"tick{k}"
        each = None if progress is None else (lambda o, v=values[k]: progress(v, o))
        try:
            mine.append((k, _tick(params, vary.key, values[k], (f1_lo, f1_hi), method,
                                  tick_dir, each, f1_step_Hz)))
        except Exception as err:  # noqa: BLE001 - raised on every rank below
            if comm.size == 1:
                raise
            error = f"rank {comm.rank} ({vary.key} = {values[k]}): {type(err).__name__}: {err}"
            break
    errors = [e for e in comm.allgather(error) if e]
    if errors:
        raise SolverError("envelope: " + "; ".join(errors))
    gathered = comm.gather(mine, root=0)
    result = None
    if comm.rank == 0:
        pieces = dict(kv for part in gathered for kv in part)
        ticks = [pieces[k][0] for k in range(len(values))]
        crossings = [c for k in range(len(values)) for c in pieces[k][1]]
        folds_at = [pieces[k][2][0] for k in range(len(values))]
        bifurcations_at = [pieces[k][2][1] for k in range(len(values))]
        used, reason = pieces[0][3], pieces[0][4]
        problem_at = envelope_curves.Problems(
            lambda v: orbits.problem(params_at(params, vary.key, v), used, every_point=True))
        clock = time.perf_counter()
        curves = envelope_curves.fold_curves(problem_at, vary.key, values, ticks, folds_at,
                                             substeps)
        fold_wall = time.perf_counter() - clock
        others = envelope_curves.bifurcation_curves(problem_at, vary.key, values,
                                                    bifurcations_at, substeps)
        result = EnvelopeResult(scene=params.name, title=params.title, key=vary.key,
                                values=values, f1_window_Hz=[f1_lo, f1_hi], method=used,
                                method_reason=reason,
                                elements=params.discretisation.elements, ticks=ticks,
                                fold_curves=curves, limit_curve=crossings,
                                wall_s=time.perf_counter() - start,
                                fold_curves_wall_s=fold_wall, bifurcation_curves=others)
    result = comm.bcast(result, root=0)
    if lock is not None:
        lock.release()
    return result


def report(result: EnvelopeResult) -> str:
    s = result.summary
    lines = [f"{result.title}: envelope in (f1, {result.key}) over {len(result.values)} "
             f"values, {result.method} ({result.method_reason}), N = {result.elements}, "
             f"in {result.wall_s:.1f} s"]
    for t in s["ticks"]:
        folds = ", ".join(f"{f['f1_Hz']:.4f}" for f in t["folds"])
        lines.append(f"  {result.key} = {t['value']:g}: {len(t['branch'])} orbits "
                     f"(stability at their points, at most {t['f1_gap_max_Hz']:.3g} Hz apart), "
                     + (f"folds at {folds} Hz" if folds else "no fold in the window"))
    for t in s["ticks"]:
        if "limits_first_by_kind" in t:
            lines.append(f"  {result.key} = {t['value']:g}, "
                         + branch_limits.first_line(t["limits_first_by_kind"], t["limits"]))
    for c in s["limit_curve"]:
        lines.append(f"  first limit ({c['kind']}) {'reached' if c['entering'] else 'left'} at "
                     f"f1 = {c['f1_Hz']:.4f} Hz (+- {c['f1_error_Hz']:.1e}) for "
                     f"{result.key} = {c['value']:g}")
    for c in s["fold_curves"]:
        lines.append(f"  fold curve from {c['from_value']:g} to {c['to_value']:g}: "
                     f"{len(c['points'])} points, {c['end']}")
    for c in s["bifurcation_curves"]:
        lines.append(f"  {c['kind'].replace('_', '-')} curve from {c['from_value']:g} toward "
                     f"{c['to_value']:g}: {len(c['points'])} points, {c['end']}")
    for what, worst in (("fold curves", s["fold_check_max_Hz"]),
                        ("period-doubling and Neimark-Sacker curves",
                         s["bifurcation_check_max_Hz"])):
        if worst is not None:
            limit = envelope_curves.CHECK_HZ
            flag = "" if worst <= limit else f"  WARNING: above {limit:g} Hz"
            lines.append(f"  {what} against the ticks' own: within {worst:.2e} Hz{flag}")
    return "\n".join(lines)
