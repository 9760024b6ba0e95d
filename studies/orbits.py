"""`rawehelix orbits`: the branch of periodic orbits of Sec. 5.3 over f1, with stability.

The first orbit (at the start of the f1 window) is found by shooting from
the stationary state after a few lead-in periods; the branch is then traced
by pseudo-arclength continuation (:mod:`rawehelix.solvers.continuation`),
through folds, until f1 leaves the window.  Every point carries its Floquet
multipliers' largest modulus and its stability.  The torque ramp (69) is
at its final value (the summary says so).

Not yet: resuming a stopped branch, the spline backend, the free twist
rotation without a controller (refused), bisection of period doubling and
Neimark-Sacker points (flagged between two points).
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from mpi4py import MPI

from rawehelix.parameters import Parameters
from rawehelix.studies import writers

LEAD_IN_PERIODS = 5  # before the first shooting: the scheme's start-up transient decays


def peaks(points: list[dict]) -> list[dict]:
    """Local maxima of T max along the branch (in branch order)."""
    T = [p["tension_max_N"] for p in points]
    return [{"f1_Hz": points[k]["f1_Hz"], "tension_max_N": T[k]}
            for k in range(1, len(T) - 1) if T[k] > T[k - 1] and T[k] >= T[k + 1]]


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

    @property
    def summary(self) -> dict:
        return {"scene": self.scene, "elements": self.elements, "degree": self.degree,
                "dt_s": self.dt_s, "torque": "the ramp (69) at its final value",
                "branch": self.branch, "folds": self.folds, "bifurcations": self.bifurcations,
                "peaks": peaks(self.branch), "wall_s": self.wall_s}

    def write(self, outdir, sweep_dir=None) -> Path:
        outdir = Path(outdir)
        outdir.mkdir(parents=True, exist_ok=True)
        writers.write_json(outdir / "summary.json", self.summary)
        sweep = _sweep_points(sweep_dir) if sweep_dir else []
        diagram_png(outdir / "orbits.png", self.branch, self.folds, sweep,
                    f"{self.title}: periodic orbits, N = {self.elements}, p = {self.degree}")
        return outdir


def _sweep_points(sweep_dir) -> list[dict]:
    with open(Path(sweep_dir) / "summary.json") as fh:
        return json.load(fh)["points"]


def diagram_png(path: Path, branch, folds, sweep_points, title: str) -> Path:
    """Bifurcation diagram: T max against f1, stable solid, unstable dashed,
    folds marked, the brute-force sweep's points overlaid."""
    plt = writers._pyplot()
    fig, ax = plt.subplots(figsize=(7, 4.2))
    f = np.array([p["f1_Hz"] for p in branch])
    T = np.array([p["tension_max_N"] for p in branch])
    stable = np.array([p["stable"] for p in branch])
    for k in range(len(f) - 1):
        solid = stable[k] and stable[k + 1]
        ax.plot(f[k:k + 2], T[k:k + 2], "-" if solid else "--", color="C0", lw=1.6)
    ax.plot([], [], "-", color="C0", label="stable orbits")
    ax.plot([], [], "--", color="C0", label="unstable orbits")
    if folds:
        ax.plot([x["f1_Hz"] for x in folds], [x["tension_max_N"] for x in folds], "kx",
                ms=8, label="folds")
    if sweep_points:
        ax.plot([p["f1_Hz"] for p in sweep_points], [p["tension_max_N"] for p in sweep_points],
                "o", mfc="none", color="C3", label="brute-force sweep")
    ax.set_xlabel("f1 [Hz]")
    ax.set_ylabel("T max at s = 0 [N]")
    ax.grid(alpha=0.3)
    ax.legend()
    return writers._finish(fig, path, title)


def compute(params: Parameters, f1_start_Hz: float, f1_stop_Hz: float, comm=MPI.COMM_WORLD,
            progress=None) -> OrbitsResult:
    """The branch from f1_start to f1_stop (either order) on one rank."""
    from rawehelix.solvers.continuation import Branch
    from rawehelix.solvers.orbits import AlphaMap
    from rawehelix.solvers.snes import SolverError

    if not (f1_start_Hz > 0 and f1_stop_Hz > 0 and f1_start_Hz != f1_stop_Hz):
        raise SolverError(f"orbits: the f1 window {f1_start_Hz}:{f1_stop_Hz} must be two "
                          f"different frequencies > 0 [Hz]")
    start = time.perf_counter()
    m = AlphaMap(params, comm=comm if comm.size == 1 else MPI.COMM_SELF)
    first = m.orbit(m.X_stationary, f1_start_Hz, lead_in=LEAD_IN_PERIODS)
    branch = Branch(m)
    branch.trace(first, f1_stop_Hz, direction=1.0 if f1_stop_Hz > f1_start_Hz else -1.0,
                 progress=progress)
    disc = params.discretisation
    return OrbitsResult(scene=params.name, title=params.title, elements=disc.elements,
                        degree=disc.degree, dt_s=params.time.dt_s,
                        branch=[o.entry() for o in branch.points], folds=branch.folds,
                        bifurcations=branch.bifurcations, wall_s=time.perf_counter() - start)


def report(result: OrbitsResult) -> str:
    s = result.summary
    lines = [f"{result.title}: {len(s['branch'])} periodic orbits, N = {result.elements}, "
             f"p = {result.degree}, dt = {result.dt_s * 1e3:g} ms, in {result.wall_s:.1f} s "
             f"(torque: {s['torque']})"]
    unstable = [p["f1_Hz"] for p in s["branch"] if not p["stable"]]
    lines.append(f"  largest Floquet multiplier modulus: "
                 f"{max(p['max_multiplier'] for p in s['branch']):.6f}; unstable points: "
                 f"{len(unstable)}")
    for kind, items in (("fold", s["folds"]), ("bifurcation", s["bifurcations"]),
                        ("peak", s["peaks"])):
        for x in items:
            lines.append(f"  {x.get('kind', kind)} at f1 = {x['f1_Hz']:.4f} Hz, "
                         f"T max = {x['tension_max_N']:.2f} N")
    return "\n".join(lines)
