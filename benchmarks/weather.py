"""Issue 44's cost (not a test): the turbulent scene's real-time factor at N = 8 with the
tensegrity section against the solid one (median of 3 each), and a seed study's wall
time on 2 MPI ranks against 1.

    .venv/bin/python benchmarks/weather.py [--until S] [--repeats 3] [--seeds 2]

Each run is ``simulate turbulent_rated`` (the whole compute, in this process, after a
warm-up run that compiles the forms) to ``--until`` simulated seconds; the study is the
whole ``rawehelix study`` command under mpirun.  Prints the figures as JSON and the
rows for benchmarks/results.md."""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

TENSEGRITY = {"section.law": "tensegrity", "model.kinematics": "extensible"}


def real_time_factors(until_s: float, repeats: int, law: dict) -> list[float]:
    from rawehelix.studies import scene, simulate
    p = scene.load("turbulent_rated", elements=8, overrides=law)
    simulate.compute(p, until_s=min(until_s, 0.2), progress=False)  # compile
    out = []
    for _ in range(repeats):
        s = simulate.compute(p, until_s=until_s, progress=False).summary
        out.append(s["simulated_s"] / s["solve_s"])
    return out


def study_wall(ranks: int, seeds: int, until_s: float) -> float:
    exe = os.path.join(os.path.dirname(sys.executable), "rawehelix")
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [exe, "study", "turbulent_rated", "--elements", "2", "--set",
               f"time.until_s={until_s}", "--vary", f"wind.seed=1:{seeds}:{seeds}", "--vary",
               "wind.speed_m_s=6:8:2", "--quantity", "power_mean_W,member_force_min_N",
               "--fd-step", "0", "-o", os.path.join(tmp, "s")]
        if ranks > 1:
            cmd = ["mpirun", "--allow-run-as-root", "--oversubscribe", "-n", str(ranks)] + cmd
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, capture_output=True)
        return time.perf_counter() - t0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--until", type=float, default=600.0, help="simulated seconds a run")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--seeds", type=int, default=6, help="seeds of the study (x 2 winds)")
    ap.add_argument("--study-until", type=float, default=600.0)
    a = ap.parse_args(argv)
    load0 = os.getloadavg()[0]
    # the studies first: mpirun refuses to start under a process that has MPI running
    # (simulate's import initialises it)
    walls = {r: study_wall(r, a.seeds, a.study_until) for r in (1, 2)}
    print(json.dumps({"study_wall_s": walls}), flush=True)
    solid = real_time_factors(a.until, a.repeats, {})
    print(json.dumps({"solid_rtf": solid}), flush=True)
    tens = real_time_factors(a.until, a.repeats, TENSEGRITY)
    out = {"until_s": a.until, "repeats": a.repeats, "solid_rtf": solid, "tensegrity_rtf": tens,
           "study_seeds": a.seeds, "study_until_s": a.study_until, "study_wall_s": walls,
           "load_average_before": load0, "load_average_after": os.getloadavg()[0]}
    print(json.dumps(out, indent=1))
    med = lambda x: f"{np.median(x):.2f} ({min(x):.2f}-{max(x):.2f}, {len(x)} runs)"  # noqa: E731
    print(f"| 17. turbulent_rated, N = 8, {a.until:g} s simulated, real-time factor | tensegrity "
          f"{med(tens)} against solid {med(solid)}: ratio {np.median(tens) / np.median(solid):.2f} "
          f"| measured (issue 44) |")
    print(f"| 17. seed study ({a.seeds} seeds x 2 winds, N = 2, {a.study_until:g} s each), wall | "
          f"1 rank {walls[1]:.0f} s, 2 ranks {walls[2]:.0f} s: x{walls[1] / walls[2]:.2f} "
          f"| measured (issue 44) |")


if __name__ == "__main__":
    main()
