"""Issue 44's cost, ``make bench``'s section ``weather`` (benchmarks/run.py; not a test):

(a) ``simulate turbulent_rated`` at N = 8 for ten simulated minutes, the tensegrity
    section against the solid one: the real-time factor (simulated / solve time), median
    of 3 runs each with their spread, each run the whole compute in this process after
    a warm-up run that compiles the forms;
(b) the whole seeds study of the issue, ``rawehelix study turbulent_rated --vary
    wind.seed=1:6:6 --vary wind.speed_m_s=5:9:3`` with its seven quantities (3 winds x
    6 seeds, ten minutes each, N = 8, and its 3 sensitivity points) on 2 MPI ranks, its
    wall time as a command.

Reduced (``run.py --only weather --reduced``, or ``RAWEHELIX_BENCH_REDUCED=1``, or this
script's ``--reduced``): the same runs shortened to :data:`REDUCED_S` simulated seconds
(a) and :data:`REDUCED_STUDY_S` a study point (b), for a trial in a few minutes.  The
full size takes hours on a shared 2-core machine (the report of the run that added it
gives the estimate).

    .venv/bin/python benchmarks/weather.py [--reduced] [--repeats 3]
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np

SCENE = "turbulent_rated"
ELEMENTS = 8  # N of both parts [-]
FULL_S = 600.0  # ten simulated minutes [s]
REDUCED_S = 10.0  # (a) reduced [s]
REDUCED_STUDY_S = 5.0  # (b) reduced, a point [s]
RANKS = 2
#: how a scene gets the tensegrity section (docs/explanation/section_laws, example.toml's
#: [section]): its members' energy, on the extensible kinematics it needs
TENSEGRITY = {"section.law": "tensegrity", "model.kinematics": "extensible"}
SOLID = {"section.law": "solid"}
#: the issue's seeds study (docs/explanation/weather.md, "Statistics over seeds")
STUDY = ["--vary", "wind.seed=1:6:6", "--vary", "wind.speed_m_s=5:9:3", "--quantity",
         "power_mean_W,tension_s0_max_N,tension_L0_max_N,member_force_min_N,moment_ratio_max,"
         "twist_max_rad_m,slack_time_fraction"]
ENV_REDUCED = "RAWEHELIX_BENCH_REDUCED"
#: the compiled steps' path (``--compiled``, issue 46; benchmarks/compiled_weather.py
#: measured its accuracy against TS): fixed steps of COMPILED_DT_S [s]
COMPILED_DT_S = 0.01
COMPILED_OPTIONS = {"ts_compiled": 1, "ts_adapt_type": "none"}


def path_arguments(compiled: bool) -> list[str]:
    """The command line's extra arguments of the path (none: PETSc TS, adaptive)."""
    if not compiled:
        return []
    return ["--set", f"time.dt_s={COMPILED_DT_S:g}",
            *[a for k, v in COMPILED_OPTIONS.items() for a in (f"-rawehelix_{k}", str(v))]]


def reduced_from_env() -> bool:
    return os.environ.get(ENV_REDUCED, "") not in ("", "0")


def real_time_factors(until_s: float, repeats: int, law: dict,
                      compiled: bool = False) -> list[float]:
    """simulated / solve time of ``repeats`` runs to ``until_s`` (after a warm-up)."""
    from rawehelix.studies import scene, simulate
    p = scene.load(SCENE, elements=ELEMENTS, overrides=law)
    options = {}
    if compiled:
        p, options = p.replace(time={"dt_s": COMPILED_DT_S}), COMPILED_OPTIONS
    simulate.compute(p, until_s=min(until_s, 0.2), options=options, progress=False)  # compile
    out = []
    for _ in range(repeats):
        s = simulate.compute(p, until_s=until_s, options=options, progress=False).summary
        out.append(s["simulated_s"] / s["solve_s"])
    return out


def _mpi_free_env() -> dict:
    """This environment without the variables an initialised MPI puts in it (mpirun
    refuses to start under them), root allowed."""
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMIX_"))}
    return {**env, "OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1"}


def study_command(until_s: float, outdir: str, compiled: bool = False) -> list[str]:
    exe = os.path.join(os.path.dirname(sys.executable), "rawehelix")
    return ["mpirun", "--oversubscribe", "-n", str(RANKS), exe, "study", SCENE, "--elements",
            str(ELEMENTS), "--set", f"time.until_s={until_s:g}", *path_arguments(compiled),
            *STUDY, "-o", outdir]


def shown(until_s: float, compiled: bool = False) -> str:
    """The study's command line as a user types it."""
    cmd = study_command(until_s, "DIR", compiled)
    return " ".join(["mpirun", "-n", str(RANKS), "rawehelix"] + cmd[5:])


def study_wall(until_s: float, compiled: bool = False, keep: str | None = None) -> tuple:
    """(wall time [s], failed points) of the whole study command on :data:`RANKS` ranks
    (``keep``: its output folder, kept; default a temporary one).  A study with failed
    points exits 3 with its results written: its time counts, and the failures too."""
    if shutil.which("mpirun") is None:
        raise RuntimeError("mpirun not found: make install puts Open MPI in place")
    with tempfile.TemporaryDirectory() as tmp:
        out = keep or os.path.join(tmp, "s")
        t0 = time.perf_counter()
        run = subprocess.run(study_command(until_s, out, compiled), capture_output=True,
                             text=True, env=_mpi_free_env())
        wall = time.perf_counter() - t0
        if run.returncode not in (0, 3):
            raise RuntimeError(f"the seeds study exited {run.returncode}: {run.stderr[-2000:]}")
        with open(os.path.join(out, "summary.json")) as f:
            failed = sorted((json.load(f).get("failed") or {}))
        return wall, failed


def _stats(x) -> dict:
    return {"median": float(np.median(x)), "min": float(min(x)), "max": float(max(x)),
            "runs": len(x), "values": [float(v) for v in x]}


def bench_weather(repeats: int = 3, reduced: bool = False, compiled: bool = False,
                  keep: str | None = None) -> dict:
    """Both parts (the study first: nothing MPI in this process yet); ``compiled``: on
    the compiled steps (fixed steps of COMPILED_DT_S) instead of PETSc TS."""
    until = REDUCED_S if reduced else FULL_S
    study_until = REDUCED_STUDY_S if reduced else FULL_S
    load0 = os.getloadavg()[0]
    wall, failed = study_wall(study_until, compiled, keep)
    solid = real_time_factors(until, repeats, SOLID, compiled)
    tens = real_time_factors(until, repeats, TENSEGRITY, compiled)
    return {"reduced": reduced, "compiled": compiled, "elements": ELEMENTS, "until_s": until,
            "solid_rtf": _stats(solid), "tensegrity_rtf": _stats(tens),
            "ratio": float(np.median(tens) / np.median(solid)),
            "study_until_s": study_until, "study_points": 18 + 3, "study_ranks": RANKS,
            "study_wall_s": wall, "study_failed": failed,
            "study_command": shown(study_until, compiled),
            "load_average_before": load0, "load_average_after": os.getloadavg()[0]}


def markdown(w: dict) -> list[str]:
    """The section's two rows of benchmarks/results.md."""
    f = lambda s: f"{s['median']:.2f} ({s['min']:.2f}-{s['max']:.2f}, {s['runs']} runs)"  # noqa: E731
    size = (f"reduced to {w['until_s']:g} s simulated (`--reduced`; the full size is "
            f"{FULL_S:g} s)" if w["reduced"] else f"{w['until_s']:g} s simulated")
    path = (f"compiled steps, dt = {COMPILED_DT_S * 1e3:g} ms" if w.get("compiled")
            else "PETSc TS, adaptive steps")
    load = (f"load average {w['load_average_before']:.1f} before, "
            f"{w['load_average_after']:.1f} after")
    study = (f"reduced to {w['study_until_s']:g} s a point (`--reduced`; the full size is "
             f"{FULL_S:g} s)" if w["reduced"] else f"{w['study_until_s']:g} s a point")
    return [f"| 17. turbulent_rated, N = {w['elements']}, {size}, {path}, real-time factor (simulated / "
            f"solve time), median of {w['solid_rtf']['runs']} | tensegrity {f(w['tensegrity_rtf'])} "
            f"against solid {f(w['solid_rtf'])}: tensegrity/solid {w['ratio']:.2f}; {load} "
            f"| measured (issue 44) |",
            f"| 17. seed study, the issue's 3 winds x 6 seeds (+ 3 sensitivity points), N = "
            f"{w['elements']}, {study}, whole `{w['study_command']}` command on "
            f"{w['study_ranks']} ranks, wall | {w['study_wall_s']:.0f} s"
            + (f"; {len(w['study_failed'])} points failed (their reasons in summary.json)"
               if w.get("study_failed") else "") + " | measured (issue 44) |"]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reduced", action="store_true", help="a trial: the runs shortened")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--compiled", action="store_true",
                    help="on the compiled steps (fixed 10 ms steps) instead of PETSc TS")
    ap.add_argument("--keep", help="keep the study's output folder here")
    ap.add_argument("--write", action="store_true",
                    help="store the result in benchmarks/results.json as run.py's section "
                         "weather (weather_compiled with --compiled); `run.py --only none` "
                         "then writes results.md")
    a = ap.parse_args(argv)
    w = bench_weather(a.repeats, a.reduced or reduced_from_env(), a.compiled, a.keep)
    print(json.dumps(w, indent=1))
    if a.write:
        path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results.json")
        with open(path) as f:
            results = json.load(f)
        results["weather_compiled" if a.compiled else "weather"] = w
        results.setdefault("dates", {})["weather_compiled" if a.compiled else "weather"] = \
            time.strftime("%Y-%m-%d %H:%M")
        with open(path, "w") as f:
            f.write(json.dumps(results, indent=2) + "\n")
    print("\n".join(markdown(w)))


if __name__ == "__main__":
    main()
