"""Issue 46 for the weather's runs (not a test): the compiled steps
(``-rawehelix_ts_compiled 1 -rawehelix_ts_adapt_type none``) against PETSc TS (the
scene's adaptive steps) on ``turbulent_rated``, each the command as users run it, CPU
(user + system of the command and its children) and wall:

* ``simulate`` 60 s at N = 8, the tensegrity section and the solid one (``--no-gif``:
  the animation is the same work on both paths);
* the reduced seeds study (6 seeds x 3 winds x 60 s, N = 2, 2 MPI ranks).

    .venv/bin/python benchmarks/compiled_weather.py [--dt 0.01] [--skip-study] [--skip-simulate]

Writes its section ``compiled_weather`` into benchmarks/results.json (the other sections
kept); ``benchmarks/run.py --only none`` then regenerates results.md with its rows
(:func:`markdown`).  One run of each (the study takes minutes on the shared machine):
the load average before and after is recorded with the figures."""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).parent
RAWEHELIX = os.path.join(os.path.dirname(sys.executable), "rawehelix")
MPIRUN = ["mpirun", "--allow-run-as-root", "--oversubscribe", "-n", "2"]
WIND = ["--set", "time.until_s=60", "--set", "wind.duration_s=60"]  # 60 simulated s
TENSEGRITY = ["--set", 'section.law="tensegrity"', "--set", 'model.kinematics="extensible"']
FIXED = {"ts_adapt_type": "none"}
FIXED_COMPILED = {**FIXED, "ts_compiled": 1}
STUDY = ["--vary", "wind.seed=1:6:6", "--vary", "wind.speed_m_s=5:9:3", "--quantity",
         "power_mean_W,tension_s0_max_N,tension_L0_max_N,member_force_min_N,moment_ratio_max,"
         "twist_max_rad_m,slack_time_fraction"]


def compiled(dt_s: float) -> list[str]:
    """The options of the compiled path: fixed steps of ``dt_s`` [s]."""
    return ["--set", f"time.dt_s={dt_s}", "-rawehelix_ts_compiled", "1",
            "-rawehelix_ts_adapt_type", "none"]


def timed(cmd: list[str]) -> dict:
    """Wall and CPU [s] of a command (its children's CPU: mpirun's ranks included), the
    load average before and after; the command's stdout's last lines."""
    load = os.getloadavg()[0]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    done = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return {"command": " ".join(cmd[cmd.index(RAWEHELIX):]).replace(RAWEHELIX, "rawehelix"),
            "returncode": done.returncode, "wall_s": wall, "cpu_s": cpu, "load_before": load,
            "load_after": os.getloadavg()[0], "tail": done.stdout.strip().splitlines()[-6:]}


def paths(dt_s: float, which) -> list:
    """(key, extra options) of the paths ``which`` ("ts", "compiled")."""
    return [(k, e) for k, e in (("ts", []), ("compiled", compiled(dt_s))) if k in which]


def simulate_pair(law: list[str], dt_s: float, tmp: Path, which, out: dict) -> dict:
    """``simulate turbulent_rated`` 60 s at N = 8 on TS and on the compiled steps."""
    for key, extra in paths(dt_s, which):
        folder = tmp / f"sim_{key}"
        shutil.rmtree(folder, ignore_errors=True)
        row = timed([RAWEHELIX, "simulate", "turbulent_rated", "--elements", "8", *WIND, *law,
                     "--no-gif", *extra, "-o", str(folder)])
        summary = json.loads((folder / "summary.json").read_text()) if row["returncode"] == 0 \
            else {}
        stats = summary.get("statistics", {})
        row.update({k: summary.get(k) for k in ("steps", "newton_iterations", "solve_s",
                                               "real_time_factor")})
        row["statistics"] = stats
        row["energy_balance"] = summary.get("energy", {}).get("balance_of_work_in")
        out[key] = row
    return out


def study_pair(dt_s: float, tmp: Path, which, out: dict) -> dict:
    """The reduced seeds study on 2 ranks, TS and compiled."""
    for key, extra in paths(dt_s, which):
        folder = tmp / f"study_{key}"
        shutil.rmtree(folder, ignore_errors=True)
        out[key] = timed([*MPIRUN, RAWEHELIX, "study", "turbulent_rated", "--elements", "2",
                          *WIND, *STUDY, *extra, "-o", str(folder)])
    return out


def accuracy(dt_s: float, until_s: float = 20.0) -> list[dict]:
    """The figures of the fixed step: turbulent_rated at N = 2 for ``until_s`` (in this
    process, CPU of each compute) on the compiled steps at dt, dt/2 and dt/4 and on TS
    (adaptive and at dt): the mean power and the largest tension at each end, each
    against the dt/4 run."""
    from rawehelix.studies import scene, simulate
    p = scene.load("turbulent_rated", elements=2).replace(
        wind={"duration_s": until_s}, time={"until_s": until_s})
    runs = {f"compiled dt = {dt_s / k * 1e3:g} ms": ({**FIXED_COMPILED}, dt_s / k) for k in (1, 2, 4)}
    runs.update({"TS adaptive": ({}, None), f"TS dt = {dt_s * 1e3:g} ms": (FIXED, dt_s)})
    out = {}
    for name, (options, dt) in runs.items():
        params = p if dt is None else p.replace(time={"dt_s": dt})
        cpu = time.process_time()
        series = simulate.compute(params, until_s=until_s, options=options, progress=False)
        cpu = time.process_time() - cpu
        cols = list(series.columns)
        out[name] = {"cpu_s": cpu, "steps": series.summary["steps"],
                     **{k: float(f(series.rows[:, cols.index(c)])) for k, f, c in (
                         ("power_mean_W", np.mean, "power_W"),
                         ("tension_s0_max_N", np.max, "tension_s0_N"),
                         ("tension_L0_max_N", np.max, "tension_L0_N"))}}
    ref = out[f"compiled dt = {dt_s / 4 * 1e3:g} ms"]
    rows = []
    for name, v in out.items():
        err = {k: (v[k] - ref[k]) / abs(ref[k]) for k in ("power_mean_W", "tension_s0_max_N",
                                                          "tension_L0_max_N")}
        rows.append({"what": f"turbulent_rated N = 2, {until_s:g} s, {name} ({v['steps']} steps, "
                             f"CPU {v['cpu_s']:.1f} s)",
                     "measured": f"power mean {v['power_mean_W']:.4f} W, T(0) max "
                                 f"{v['tension_s0_max_N']:.3f} N, T(L0) max "
                                 f"{v['tension_L0_max_N']:.3f} N; against the dt/4 run "
                                 f"{err['power_mean_W']:+.1e}, {err['tension_s0_max_N']:+.1e}, "
                                 f"{err['tension_L0_max_N']:+.1e}",
                     **v})
    return rows


def markdown(r: dict) -> list[str]:
    """The section's rows of benchmarks/results.md."""
    lines = []
    dt = r.get("dt_s")
    for law, v in (r.get("simulate") or {}).items():
        if not {"ts", "compiled"} <= set(v):
            continue
        t, c = v["ts"], v["compiled"]
        what = (f"| 18. `simulate turbulent_rated --elements 8` 60 s, {law} section, compiled "
                f"steps (`-rawehelix_ts_compiled 1 -rawehelix_ts_adapt_type none`, dt = "
                f"{dt * 1e3:g} ms) against TS (adaptive), whole command, one run each | ")
        if c.get("returncode"):  # the compiled path did not run it
            lines.append(what + f"TS CPU {t['cpu_s']:.0f} s, wall {t['wall_s']:.0f} s, "
                         f"{t['steps']} steps (real-time factor {t['real_time_factor']:.2f}); "
                         f"compiled: not run ({c.get('refused', 'failed')}) | issue 46: the same "
                         f"path for the weather runs |")
            continue
        lines.append(
            what + f"CPU {t['cpu_s']:.0f} s -> {c['cpu_s']:.0f} s (x{t['cpu_s'] / c['cpu_s']:.2f}), "
            f"wall {t['wall_s']:.0f} s -> {c['wall_s']:.0f} s; {t['steps']} -> {c['steps']} steps; "
            f"the summary's real-time factor {t['real_time_factor']:.2f} -> "
            f"{c['real_time_factor']:.2f}; mean power {t['statistics']['power_mean_W']:.3f} -> "
            f"{c['statistics']['power_mean_W']:.3f} W, T(0) max "
            f"{t['statistics']['tension_s0_max_N']:.3f} -> {c['statistics']['tension_s0_max_N']:.3f}"
            f" N; load {t['load_before']:.1f}-{c['load_after']:.1f} | issue 46: the same path for "
            f"the weather runs |")
    s = r.get("study")
    if s and {"ts", "compiled"} <= set(s):
        t, c = s["ts"], s["compiled"]
        lines.append(
            f"| 18. seeds study on the compiled steps: `rawehelix study turbulent_rated` 6 seeds x "
            f"3 winds x 60 s, N = 2, 2 ranks (mpirun), dt = {dt * 1e3:g} ms against TS "
            f"(adaptive), whole command, one run each | wall {t['wall_s']:.0f} s -> "
            f"{c['wall_s']:.0f} s (x{t['wall_s'] / c['wall_s']:.2f}), CPU {t['cpu_s']:.0f} s -> "
            f"{c['cpu_s']:.0f} s; load {t['load_before']:.1f}-{c['load_after']:.1f}"
            + (f"; point by point: mean power within {p['power_mean_W_max_rel']:.1e}, the largest "
               f"tensions within {max(p['tension_s0_max_N_max_rel'], p['tension_L0_max_N_max_rel']):.1e}, "
               f"the smallest member force within {p['member_force_min_N_max_abs']:.2f} N"
               if (p := s.get("points_compared")) else "")
            + " | issue 46: the seeds study before and after |")
    for law, h in (r.get("dt_half_N8") or {}).items():
        e = h["against_dt_half"]
        lines.append(
            f"| 18. the same 60 s at N = 8, {law} section, against the compiled run at dt/2 = "
            f"{dt / 2 * 1e3:g} ms (mean power {h['statistics']['power_mean_W']:.3f} W, T(0) max "
            f"{h['statistics']['tension_s0_max_N']:.3f} N, T(L0) max "
            f"{h['statistics']['tension_L0_max_N']:.3f} N) | compiled at {dt * 1e3:g} ms "
            + ", ".join(f"{e['compiled'][k]:+.1e}" for k in ("power_mean_W", "tension_s0_max_N",
                                                            "tension_L0_max_N"))
            + "; TS adaptive " + ", ".join(f"{e['ts'][k]:+.1e}" for k in (
                "power_mean_W", "tension_s0_max_N", "tension_L0_max_N"))
            + " (mean power, T(0) max, T(L0) max) | the dt of the rows above |")
    for row in r.get("accuracy") or []:
        lines.append(f"| 18. {row['what']} | {row['measured']} | the dt of the rows above |")
    return lines


def bench(dt_s: float = 0.01, which=("ts", "compiled"), study: bool = True,
          simulate: bool = True, section: dict | None = None) -> dict:
    """The section's figures (``section``: the last ones, kept where not run now)."""
    section = dict(section or {})
    section["dt_s"] = dt_s
    with tempfile.TemporaryDirectory() as tmp:
        if study:
            section["study"] = study_pair(dt_s, Path(tmp), which, section.get("study", {}))
        if simulate:
            sims = section.setdefault("simulate", {})
            for law, options in (("tensegrity", TENSEGRITY), ("solid", [])):
                sims[law] = simulate_pair(options, dt_s, Path(tmp), which, sims.get(law, {}))
    return section


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dt", type=float, default=0.01, help="the compiled path's fixed step [s]")
    ap.add_argument("--skip-study", action="store_true")
    ap.add_argument("--skip-simulate", action="store_true")
    ap.add_argument("--accuracy", action="store_true", help="only the fixed step's accuracy "
                    "(N = 2, 20 s, in this process)")
    ap.add_argument("--paths", default="ts,compiled", help="the paths to run (the others' "
                    "last figures kept)")
    a = ap.parse_args(argv)
    which = a.paths.split(",")
    path = HERE / "results.json"
    results = json.loads(path.read_text())
    if a.accuracy:
        import rawehelix.solvers.compiled_step  # noqa: F401  (registers the compiled steps)
        section = {**(results.get("compiled_weather") or {}), "accuracy": accuracy(a.dt)}
    else:
        section = bench(a.dt, which, not a.skip_study, not a.skip_simulate,
                        results.get("compiled_weather") or {})
    results["compiled_weather"] = section
    results.setdefault("dates", {})["compiled_weather"] = time.strftime("%Y-%m-%d %H:%M")
    path.write_text(json.dumps(results, indent=2) + "\n")
    print("\n".join(markdown(section)))


if __name__ == "__main__":
    main()
