"""`rawehelix orbits`: the branch of periodic orbits of Sec. 5.3 over f1, with stability.

The first orbit (at the start of the f1 window) is found by shooting from
the stationary state after a few lead-in periods; the branch is then traced
by pseudo-arclength continuation (:mod:`rawehelix.periodic_orbits.continuation`),
through folds, until f1 leaves the window.  Every point carries its Floquet
multipliers' largest modulus and its stability.  The torque ramp (69) is
at its final value (the summary says so).

MPI: the f1 window is cut into one equal window per rank; each rank traces
its own window on one rank (from its own first orbit), and rank 0 joins the
pieces in order.  Where a window starts inside a multi-valued range the
shooting may land on another branch than the one the window before it left
on: ``junctions`` gives T max on both sides of each cut, and the report
says where they differ by more than ``tension_step``.  A failure on one rank
stops the others at their next point, and every rank raises.

Resumable (``outdir``): every point is stored as it is found (its entry,
multipliers and state, and the continuation's state after it), one
directory per window, whole or not at all and checked when read
(:class:`~rawehelix.studies.store.orbits_store.WindowStore`); a rerun continues after the last stored point.

Both schemes: the FE generalised-alpha map (:mod:`rawehelix.solvers.orbits`)
and the paper's spline-Galerkin flow (:mod:`rawehelix.references.spline_galerkin.orbits`),
chosen by ``discretisation.scheme`` (``--scheme spline``); or harmonic balance on the
FE rod (``method``, :mod:`rawehelix.studies.orbit_method`).

Superharmonic sites: the lateral natural frequencies f_n of the scene's
linearisation (the families the end's circle drives; the FE's SLEPc modes or
the spline scheme's eigenvalues, :func:`driven_frequencies`) give the k:1
sites f_n / k (k in ``superharmonics``, default 2 and 3) inside the window,
where the continuation's step closes in on the multiplier's crossing of +1
(the step guards of :mod:`rawehelix.periodic_orbits.resonances`, given to the
continuation by :func:`branch` with T max, the branch's observable).
"""

from __future__ import annotations

import itertools
import json
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from mpi4py import MPI

from rawehelix.errors import SceneError
from rawehelix.parameters import Parameters
from rawehelix.periodic_orbits.floquet import LEAD_IN_PERIODS  # noqa: F401  (benchmarks')
from rawehelix.studies import forcing, orbit_method, schemes
from rawehelix.studies.analysis import branch_limits
from rawehelix.studies.present.orbits_report import report  # noqa: F401  (the command's text)
from rawehelix.studies.store import writers
from rawehelix.studies.store.orbits_store import OrbitsStoreError, WindowStore  # noqa: F401

#: the order of a branch's points, in which its first limits are found
ALONG = "along the branch from the first f1 of --f1"
ABORT_TAG = 713  # a rank's failure, sent to the others


@dataclass
class OrbitsResult:
    scene: str
    title: str
    elements: int
    degree: int
    dt_s: float
    branch: list[dict]
    folds: list[dict]
    bifurcations: list[dict]
    wall_s: float
    peaks: list[dict] = field(default_factory=list)
    windows: list[dict] = field(default_factory=list)  # per rank: f1 range, points
    junctions: list[dict] = field(default_factory=list)  # T max on both sides of each cut
    tension_step: float = 0.0
    scheme: str = "fe"  # "fe" (generalised-alpha, dt_s) or "spline" (Radau, adaptive)
    superharmonics: tuple = ()  # the orders k of the sites the step closed in on
    method: str = orbit_method.SHOOTING.name  # the method that ran (a store without one: shot)
    method_reason: str = ""  # why (studies/orbit_method.py::choose)
    orbits: list = field(default_factory=list, repr=False)  # the Orbits, in branch order

    @property
    def method_reported(self) -> bool:
        """Whether the report names the method (studies/orbit_method.py: its ``reported``)."""
        return orbit_method.get(self.method).reported

    @property
    def discretisation(self) -> str:
        scheme = schemes.get(self.scheme)
        if not scheme.has_degree:  # the spline reference: N and its adaptive integrator
            return f"{scheme.name} N = {self.elements}, {scheme.integrator}"
        return orbit_method.get(self.method).discretisation(self.elements, self.degree,
                                                            self.dt_s, self.branch)

    @property
    def summary(self) -> dict:
        return {"scene": self.scene, "scheme": self.scheme, "elements": self.elements,
                "degree": self.degree,
                "dt_s": self.dt_s if orbit_method.get(self.method).steps_in_time else None,
                "method": self.method, "method_reason": self.method_reason,
                "torque": "the ramp (69) at its final value",
                "tension_step": self.tension_step,
                "superharmonic_orders": list(self.superharmonics),
                "branch": self.branch, "folds": self.folds, "bifurcations": self.bifurcations,
                "peaks": self.peaks, "windows": self.windows, "junctions": self.junctions,
                "limits": branch_limits.over_points(self.branch, order=ALONG),
                "limits_first_by_kind": branch_limits.first_by_kind(self.branch),
                "wall_s": self.wall_s}

    def write(self, outdir, sweep_dir=None) -> Path:
        outdir = Path(outdir)
        outdir.mkdir(parents=True, exist_ok=True)
        writers.write_json(outdir / "summary.json", self.summary)
        sweep = _sweep_points(sweep_dir) if sweep_dir else []
        diagram_png(outdir / "orbits.png", self.branch, self.folds, sweep,
                    f"{self.title}: periodic orbits, {self.discretisation}",
                    firsts=self.summary["limits_first_by_kind"])
        return outdir


def check_sweep_dir(sweep_dir):
    """Refuse (SceneError, before any orbit) a ``--sweep`` folder without a
    sweep's summary.json and its points."""
    from rawehelix.errors import SceneError
    path = Path(sweep_dir) / "summary.json"
    try:
        points = json.loads(path.read_text())["points"]
        if not all("f1_Hz" in p and "tension_max_N" in p for p in points):
            raise KeyError("f1_Hz, tension_max_N")
    except (OSError, ValueError, KeyError, TypeError) as err:
        why = ("no such file" if isinstance(err, FileNotFoundError)
               else f"not a sweep's summary ({type(err).__name__}: {err})")
        raise SceneError("--sweep", str(sweep_dir), f"{path}: {why}; give the -o folder of a "
                         f"finished 'rawehelix sweep'") from None


def _sweep_points(sweep_dir) -> list[dict]:
    with open(Path(sweep_dir) / "summary.json") as fh:
        return json.load(fh)["points"]


def diagram_png(path: Path, branch, folds, sweep_points, title: str,
                firsts: dict | None = None) -> Path:
    """Bifurcation diagram: T max against f1, stable solid, unstable dashed,
    folds marked, the brute-force sweep's points overlaid, each limit's first along
    the branch (``firsts``: the summary's limits_first_by_kind) a vertical line."""
    plt = writers._pyplot()
    fig, ax = plt.subplots(figsize=(7, 4.2))
    f = np.array([p["f1_Hz"] for p in branch])
    T = np.array([p["tension_max_N"] for p in branch])
    stable = np.array([p["stable"] for p in branch])
    # a segment is solid where both its ends are stable; each run of like segments is
    # one line, so that the dashes of a densely traced unstable branch still show
    k = 0
    for solid, run in itertools.groupby(stable[:-1] & stable[1:]):
        n = len(list(run))  # segments k .. k + n - 1: points k .. k + n
        ax.plot(f[k:k + n + 1], T[k:k + n + 1], "-" if solid else "--", color="C0", lw=1.6)
        k += n
    ax.plot([], [], "-", color="C0", label="stable orbits")
    ax.plot([], [], "--", color="C0", label="unstable orbits")
    if folds:
        ax.plot([x["f1_Hz"] for x in folds], [x["tension_max_N"] for x in folds], "kx",
                ms=8, label="folds")
    if sweep_points:
        ax.plot([p["f1_Hz"] for p in sweep_points], [p["tension_max_N"] for p in sweep_points],
                "o", mfc="none", color="C3", label="brute-force sweep")
    branch_limits.mark_firsts((ax,), firsts or {})
    ax.set_xlabel("f1 [Hz]")
    ax.set_ylabel("T max at s = 0 [N]")
    ax.grid(alpha=0.3)
    ax.legend()
    return writers._finish(fig, path, title)


def windows(f1_start_Hz: float, f1_stop_Hz: float, ranks: int) -> list[list[float]]:
    """The f1 window cut into ``ranks`` equal windows, each traced from its first end."""
    edges = np.linspace(f1_start_Hz, f1_stop_Hz, ranks + 1)
    return [[float(edges[k]), float(edges[k + 1])] for k in range(ranks)]


def problem(params: Parameters, method: str = orbit_method.default_for("orbits"),
            every_point: bool = False):
    """The scene's periodic-orbit problem of ``method`` on this rank, from the methods'
    registry (studies/orbit_method.py: shooting on its scheme's period map, the FE
    generalised-alpha map or the paper's spline-Galerkin flow, or harmonic balance);
    a turning ring refused.  ``every_point``: the multipliers of every point of a
    branch its own (harmonic balance: Hill at every point, not the guarded step)."""
    refuse_turning_ring(params)
    return orbit_method.get(method).problem(params, every_point)


def refuse_turning_ring(params: Parameters) -> None:
    """A turning ring's slack members make the response quasi-periodic (the spin turns
    them through the bending plane): no orbit of period 1/f1 exists to find."""
    if params.model.section.ring == "turning":
        from rawehelix.errors import SceneError
        raise SceneError(params.name, "section.ring",
                         "'turning' breaks the rotation symmetry in alpha that a periodic orbit of "
                         "the spinning helix needs (docs/explanation/section.md): trace it with "
                         "rawehelix sweep, or set section.ring = 'worst'")


def driven_frequencies(params: Parameters, m, f_max_Hz: float) -> tuple[list[float], float]:
    """The lateral natural frequencies [Hz] up to f_max of the scene's linearisation
    about its stationary state, in its scheme, on this rank (``m``: the scene's
    period map, whose stationary state the spline scheme linearises about), and
    that state's tension at s = 0 [N] (where the sites' predictions hold)."""
    from rawehelix.studies.response import natural_modes
    return schemes.of(params).driven_frequencies(params, m, f_max_Hz, natural_modes)


def tension_max(m):
    """T max [N] over a period, the branch's observable: of the samples of the
    period map ``m`` (the tension at s = 0, normalised) or of a finished orbit."""
    from rawehelix.periodic_orbits.problem import Observable
    return Observable("tension_max_N", lambda samples: m.q.tension_N(samples).max(),
                      lambda orbit: orbit.tension_max_N)


def branch(m, tension_step: float | None = None, sites=(), f1_step_Hz=None, **options):
    """The continuation of the periodic-orbit problem ``m`` with this study's
    observable (T max) and step guards: T max's relative step (``tension_step``,
    default TENSION_STEP) and its peaks, the superharmonic ``sites`` and the most a
    step moves f1 (periodic_orbits/resonances.py); ``options``: Branch's (ds, ds_min,
    ds_max, tol, max_it)."""
    from rawehelix.periodic_orbits.continuation import Branch
    from rawehelix.periodic_orbits.resonances import TENSION_STEP, MaxStep, Peaks, Sites
    observable = tension_max(m)
    step = TENSION_STEP if tension_step is None else tension_step
    return Branch(m, observable=observable,
                  guards=(Peaks(observable, step), Sites(sites), MaxStep(f1_step_Hz)),
                  **options)


def _trace_window(params, window, tension_step, max_points, store, progress, stop,
                  superharmonics=(), method=orbit_method.default_for("orbits"), f1_step_Hz=None,
                  every_point=False):
    """One window on this rank: (entries, folds, bifurcations, peaks, its sites)."""
    from rawehelix.periodic_orbits.resonances import sites_for
    from rawehelix.solvers.snes import SolverError

    start_f1, stop_f1 = window
    lo, hi = sorted(window)
    m = problem(params, method, every_point)
    sites, about = (), {"sites": []}
    if superharmonics:
        try:
            f_n, T0 = driven_frequencies(params, m, max(superharmonics) * hi)
        except SolverError as err:  # the step control's aid only: trace without it, and say so
            about["sites_error"] = (f"superharmonic sites not computed ({err}); the T max "
                                    f"step alone, which may step over a narrow superharmonic "
                                    f"resonance")
        else:
            sites = sites_for(f_n, lo, hi, superharmonics, tension_N=T0)
            about["sites"] = [{"f1_Hz": x.f1_Hz, "f_n_Hz": x.f_n_Hz, "order": x.k} for x in sites]
    traced = branch(m, tension_step, sites, f1_step_Hz)
    stored = store.load() if store else None
    if stored:
        traced.resume(*stored)
    else:
        first = m.first_orbit(start_f1)
        traced.start(first, direction=1.0 if stop_f1 > start_f1 else -1.0)
        if store:
            store.save(first, [], traced.state)
        if progress:
            progress(first)

    def each(orbit):
        stop()
        if progress:
            progress(orbit)

    traced.trace(None, stop_f1, max_points=max_points, progress=each,
                 on_point=store.save if store else None)
    limits = branch_limits.OrbitLimits(m, params)  # one period more an orbit (AlphaMap.sections)
    entries = [limits.entry(o) for o in traced.points]
    if traced.stopped:  # a point that was not an orbit ended the window early
        about["stopped"] = traced.stopped
    about["orbits"] = traced.points  # for the envelope (not in the summary)
    return entries, traced.folds, traced.bifurcations, traced.peaks, about


def compute(params: Parameters, f1_start_Hz: float, f1_stop_Hz: float, comm=MPI.COMM_WORLD,
            progress=None, outdir=None, tension_step: float | None = None,
            max_points: int = 400, superharmonics=None,
            method: str = orbit_method.default_for("orbits"),
            f1_step_Hz: float | None = None, every_point: bool = False) -> OrbitsResult:
    """The branch from f1_start to f1_stop (either order), one window per rank
    of ``comm``; with ``outdir``, stored point by point and resumed from it.
    ``superharmonics``: the orders k of the k:1 sites the step closes in on
    (default SUPERHARMONIC_ORDERS; () for none); ``method``: "shooting", "hb" or
    "auto" (studies/orbit_method.py); ``f1_step_Hz``: the most a step moves f1 (None: as
    the step control takes it); ``every_point``: every point's multipliers its own
    (:func:`problem`)."""
    from rawehelix.periodic_orbits.resonances import SUPERHARMONIC_ORDERS, TENSION_STEP
    from rawehelix.solvers.snes import SolverError

    if not (f1_start_Hz > 0 and f1_stop_Hz > 0 and f1_start_Hz != f1_stop_Hz
            and np.isfinite(f1_start_Hz + f1_stop_Hz)):
        raise SolverError(f"orbits: the f1 window {f1_start_Hz}:{f1_stop_Hz} must be two "
                          f"different finite frequencies > 0 [Hz]")
    forcing.require(params, "orbits")  # before any output
    if isinstance(max_points, bool) or not (isinstance(max_points, int) and max_points >= 1):
        raise SceneError("--max-points", str(max_points), "must be an integer >= 1 (the most "
                         "points of each rank's window)")
    if tension_step is not None and not 0 < tension_step < 1:
        raise SceneError("--tension-step", str(tension_step), "must be a fraction in (0, 1): "
                         f"the largest relative change of T max between two points (default "
                         f"{TENSION_STEP})")
    refuse_turning_ring(params)
    method, method_reason = orbit_method.choose(params, method)
    tension_step = TENSION_STEP if tension_step is None else tension_step
    superharmonics = tuple(SUPERHARMONIC_ORDERS if superharmonics is None else superharmonics)
    if any(int(k) != k or k < 2 for k in superharmonics):
        raise SolverError(f"orbits: superharmonic orders {superharmonics} must be integers >= 2")
    start = time.perf_counter()
    cuts = windows(f1_start_Hz, f1_stop_Hz, comm.size)
    store = None
    if outdir is not None:
        from rawehelix.studies.store.sweep_store import fingerprint, scene_keys
        from rawehelix.studies.store.writers import SCENE_KEYS
        header = {"scene": params.name, "fingerprint": fingerprint(params), "windows": cuts,
                  SCENE_KEYS: scene_keys(params),
                  "tension_step": tension_step, "superharmonics": list(superharmonics),
                  **orbit_method.get(method).store_header(),
                  **({"f1_step_Hz": f1_step_Hz} if f1_step_Hz else {})}
        store = WindowStore.open(Path(outdir), header, comm)

    def stop():  # another rank failed: stop here too
        if comm.size > 1 and comm.Iprobe(source=MPI.ANY_SOURCE, tag=ABORT_TAG):
            raise _Stopped()

    error, sent, piece = None, [], None
    try:
        piece = _trace_window(params, cuts[comm.rank], tension_step, max_points, store,
                              progress, stop, superharmonics, method, f1_step_Hz, every_point)
    except _Stopped:
        error = (False, f"rank {comm.rank}: stopped")
    except Exception as err:  # noqa: BLE001 - reported on every rank below
        if comm.size == 1:
            raise
        error = (True, f"rank {comm.rank} (f1 {cuts[comm.rank][0]:g}:{cuts[comm.rank][1]:g} "
                       f"Hz): {type(err).__name__}: {err}")
        sent = [comm.isend(error[1], dest=r, tag=ABORT_TAG) for r in range(comm.size)
                if r != comm.rank]
    errors = comm.allgather(error)
    failed = [r for r, e in enumerate(errors) if e and e[0]]
    for r in failed:
        if r != comm.rank:
            comm.recv(source=r, tag=ABORT_TAG)
    for req in sent:
        req.wait()
    if failed:
        raise SolverError("orbits: " + "; ".join(errors[r][1] for r in failed))
    pieces = comm.gather(piece, root=0)
    result = None
    if comm.rank == 0:
        result = _join(params, cuts, pieces, tension_step, time.perf_counter() - start)
        result.superharmonics = superharmonics
        result.method, result.method_reason = method, method_reason
    return comm.bcast(result, root=0)


class _Stopped(Exception):
    """Another rank failed."""


def _join(params, cuts, pieces, tension_step, wall_s) -> OrbitsResult:
    """The windows' pieces in order, with T max on both sides of each cut."""
    branch, folds, bifurcations, found, info, junctions = [], [], [], [], [], []
    orbits = []
    for k, (entries, f, b, p, sites) in enumerate(pieces):
        orbits += sites.pop("orbits", [])
        if k > 0:
            left, right, x = branch[-2:], entries[0], cuts[k][0]
            if len(left) < 2:
                continue
            (fa, Ta), (fb, Tb) = [(e["f1_Hz"], e["tension_max_N"]) for e in left]
            T_left = Ta + (x - fa) / (fb - fa) * (Tb - Ta)
            junctions.append({"f1_Hz": x, "tension_max_N_left": T_left,
                              "tension_max_N_right": right["tension_max_N"],
                              "same_branch": abs(T_left / right["tension_max_N"] - 1)
                              <= tension_step})
        branch += entries
        folds += f
        bifurcations += b
        found += p
        info.append({"rank": k, "f1_Hz": cuts[k], "points": len(entries), **sites})
    disc = params.discretisation
    scheme = schemes.of(params)
    return OrbitsResult(scene=params.name, title=params.title, elements=disc.elements,
                        degree=disc.degree if scheme.has_degree else None,
                        dt_s=params.time.dt_s if scheme.fixed_time_step else None,
                        scheme=disc.scheme,
                        branch=branch, folds=folds,
                        bifurcations=bifurcations, wall_s=wall_s, peaks=found, windows=info,
                        junctions=junctions, tension_step=tension_step, orbits=orbits)
