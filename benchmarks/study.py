"""`rawehelix study` on MPI ranks, and what one point costs per kind of quantity.

1. A 16-point modal study (``lateral_frequency_Hz`` over ``helix.EI_Nm2``,
   mobile_end, N elements, no sensitivity points) as the whole command under
   ``mpirun -n 1`` and ``-n 2``, after one run that compiles the forms.  The
   speed-up is that of the point loop (``summary.json``: each rank's loop wall
   and CPU time, start-up and the gathering excluded) and of the whole
   command; the 1-minute load average before each run says how busy the
   shared machine was.  The two CSVs must be the same bytes.
2. The CPU time (time.process_time) and wall time of one point per stage, in
   this process on COMM_SELF (quantities.evaluate): a stationary quantity
   (``tension_s0_N``), a modal one (``lateral_frequency_Hz``), a sweep one
   (``tension_max_N@10``) and an orbit one (``fold_Hz``: the orbits traced
   from 11.5 Hz to past the Sec. 5.3 fold at 12.70 Hz, docs/explanation/orbits.md; a
   trace from 12.4 Hz fails, the shooting from the stationary state does
   not converge there).

    .venv/bin/python benchmarks/study.py [--elements 8] [--points 16] [--repeats 3]
    .venv/bin/python benchmarks/run.py --only study      (the same, into results.json)
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
from pathlib import Path

import numpy as np

ELEMENTS = 8
POINTS = 16
EI_RANGE = "3000:6000"
FOLD_WINDOW = {"sweep.f1_start_Hz": 11.5, "sweep.f1_stop_Hz": 12.75}  # past the fold at 12.70 Hz


def _busy_cpu_s() -> float:
    """CPU seconds spent by the whole machine (every process) since boot, from /proc/stat."""
    fields = Path("/proc/stat").read_text().split("\n", 1)[0].split()[1:]
    user, nice, system, _idle, _iowait, irq, softirq, steal = (int(x) for x in fields[:8])
    return (user + nice + system + irq + softirq + steal) / os.sysconf("SC_CLK_TCK")


def _children_cpu_s() -> float:
    import resource
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def _study_command(ranks: int, points: int, elements: int, outdir: Path) -> dict:
    env = {**os.environ, "OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1"}
    exe = str(Path(sys.executable).with_name("rawehelix"))
    cmd = ["mpirun", "-n", str(ranks), "--oversubscribe", exe, "study", "mobile_end",
           "--elements", str(elements), "--vary", f"helix.EI_Nm2={EI_RANGE}:{points}",
           "--quantity", "lateral_frequency_Hz", "--fd-step", "0", "-o", str(outdir)]
    shutil.rmtree(outdir, ignore_errors=True)
    load = os.getloadavg()[0]
    busy0, ours0 = _busy_cpu_s(), _children_cpu_s()
    t0, u0 = time.perf_counter(), time.time()
    subprocess.run(cmd, check=True, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall, u1 = time.perf_counter() - t0, time.time()
    # the cores that other processes (not this command's) kept busy during the run
    others = max(0.0, (_busy_cpu_s() - busy0) - (_children_cpu_s() - ours0)) / wall
    s = json.loads((outdir / "summary.json").read_text())
    points = [json.loads(p.read_text()) for p in sorted((outdir / "points").glob("*.json"))]
    return {"command_wall_s": wall, "load_1min_before": load, "others_cores": others,
            # before the last rank's loop starts (mpirun, imports, the scenes checked) and
            # after the last rank's loop ends (gathering, sensitivities, CSV, figures)
            "startup_s": max(x["loop_start_unix"] for x in s["loops"]) - u0,
            "tail_s": u1 - max(x["loop_end_unix"] for x in s["loops"]),
            "point_cpu_s": float(np.median([p["point_cpu_s"] for p in points])),
            "point_wall_s": float(np.median([p["point_wall_s"] for p in points])),
            "loop_wall_s": max(x["loop_wall_s"] for x in s["loops"]),
            "loop_cpu_s": sum(x["loop_cpu_s"] for x in s["loops"]),
            "loop_cpu_s_max_rank": max(x["loop_cpu_s"] for x in s["loops"]),
            "per_rank": s["loops"], "failed": len(s["failed"]),
            "csv": (outdir / "study.csv").read_text()}


def bench_speedup(points: int = POINTS, elements: int = ELEMENTS, repeats: int = 1) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        _study_command(1, 2, elements, tmp / "warm")  # compiles the forms
        runs = {1: [], 2: []}
        for _ in range(repeats):
            for ranks in (1, 2):
                runs[ranks].append(_study_command(ranks, points, elements, tmp / f"r{ranks}"))
    same = all(r["csv"] == runs[1][0]["csv"] for r in runs[1] + runs[2])
    for rows in runs.values():
        for r in rows:
            r.pop("csv")
    metrics = ("command_wall_s", "loop_wall_s", "loop_cpu_s", "loop_cpu_s_max_rank",
               "startup_s", "tail_s", "point_cpu_s", "point_wall_s", "load_1min_before",
               "others_cores")
    med = {k: {m: float(np.median([r[m] for r in rows])) for m in metrics}
           for k, rows in runs.items()}
    spread = {str(k): {m: [float(min(r[m] for r in rows)), float(max(r[m] for r in rows))]
                       for m in metrics} for k, rows in runs.items()}
    # the ratios of each repeat (a 1-rank run and the 2-rank run after it)
    pairs = list(zip(runs[1], runs[2]))
    ratio = {m: [a[m] / b[m] for a, b in pairs] for m in ("loop_wall_s", "command_wall_s")}
    # the pairs during which other processes kept less than 0.1 core busy (the machine is shared)
    idle = [i for i, (a, b) in enumerate(pairs) if max(a["others_cores"], b["others_cores"]) < 0.1]
    fixed1 = med[1]["startup_s"] + med[1]["tail_s"]
    return {"points": points, "elements": elements, "quantity": "lateral_frequency_Hz",
            "runs": {str(k): v for k, v in runs.items()}, "median": {str(k): v for k, v in med.items()},
            "spread": spread, "repeats": repeats,
            "speedup_loop": med[1]["loop_wall_s"] / med[2]["loop_wall_s"],
            "speedup_command": med[1]["command_wall_s"] / med[2]["command_wall_s"],
            "speedup_loop_per_repeat": ratio["loop_wall_s"],
            "speedup_command_per_repeat": ratio["command_wall_s"],
            "idle_pairs": idle,
            "speedup_loop_idle": [ratio["loop_wall_s"][i] for i in idle],
            "speedup_command_idle": [ratio["command_wall_s"][i] for i in idle],
            # Amdahl: the 1-rank command with the same start-up and tail and the loop halved
            "speedup_command_bound": med[1]["command_wall_s"]
            / (fixed1 + med[1]["loop_wall_s"] / 2),
            "cpu_ratio_2_over_1": med[2]["loop_cpu_s"] / med[1]["loop_cpu_s"],
            # on dedicated cores: the 1-rank loop's CPU over the busier rank's of 2
            "speedup_cpu": med[1]["loop_cpu_s"] / med[2]["loop_cpu_s_max_rank"],
            "csv_1_equals_2_ranks": same, "cores": os.cpu_count()}


def bench_cost(elements: int = ELEMENTS, repeats: int = 3) -> dict:
    """CPU and wall time of one point per stage (the cheap ones: median of
    ``repeats`` after one that compiles; the sweep and orbit ones: one run)."""
    import petsc4py
    petsc4py.init([sys.argv[0]])
    from rawehelix.studies import quantities, scene

    cases = {"stationary": ("tension_s0_N", {}, elements, repeats),
             "modes": ("lateral_frequency_Hz", {}, elements, repeats),
             "sweep": ("tension_max_N@10", {}, elements, 1),
             "orbits": ("fold_Hz", FOLD_WINDOW, 4, 1)}
    out = {}
    for stage, (name, over, n, k) in cases.items():
        params = scene.load("mobile_end", elements=n, overrides=over)
        if k > 1:
            quantities.evaluate(params, [name])
        cpu, wall, value = [], [], None
        for _ in range(k):
            c0, w0 = time.process_time(), time.perf_counter()
            got = quantities.evaluate(params, [name])
            cpu.append(time.process_time() - c0)
            wall.append(time.perf_counter() - w0)
            value = got["values"][name] if got["values"][name] is not None else got["errors"][name]
        out[stage] = {"quantity": name, "elements": n, "overrides": over, "value": value,
                      "cpu_s": float(np.median(cpu)), "wall_s": float(np.median(wall)), "runs": k}
        print(f"  {stage}: {name} = {value} ({out[stage]['cpu_s']:.2f} s CPU)", flush=True)
    return out


def bench_study(repeats: int = 1) -> dict:
    return {"speedup": bench_speedup(repeats=repeats), "cost_per_point": bench_cost()}


def markdown(r: dict) -> str:
    sp, cost = r["speedup"], r.get("cost_per_point")
    m1, m2 = sp["median"]["1"], sp["median"]["2"]
    s1, s2 = sp["spread"]["1"], sp["spread"]["2"]

    def rng(x):
        return f"{min(x):.2f}-{max(x):.2f}"
    idle = ""
    if sp["speedup_loop_idle"]:
        li, ci = sp["speedup_loop_idle"], sp["speedup_command_idle"]
        idle = (f"**on the {len(li)} pairs of runs with the other processes below 0.1 core: "
                f"point loop x{np.median(li):.2f} ({rng(li)}), whole command x{np.median(ci):.2f} "
                f"({rng(ci)})**; all {sp['repeats']} pairs: ")
    lines = [f"| {sp['points']}-point modal study (mobile_end, N = {sp['elements']}), "
             f"2 ranks vs 1 (medians of {sp['repeats']}) | {idle}"
             f"point loop {m1['loop_wall_s']:.2f} s -> {m2['loop_wall_s']:.2f} s wall: x"
             f"{sp['speedup_loop']:.2f} (pairs {rng(sp['speedup_loop_per_repeat'])}); CPU "
             f"{m1['loop_cpu_s']:.2f} s -> busier rank {m2['loop_cpu_s_max_rank']:.2f} s: x"
             f"{sp['speedup_cpu']:.2f}; whole command {m1['command_wall_s']:.2f} s -> "
             f"{m2['command_wall_s']:.2f} s: x{sp['speedup_command']:.2f} (pairs "
             f"{rng(sp['speedup_command_per_repeat'])}; start-up {m1['startup_s']:.2f} / "
             f"{m2['startup_s']:.2f} s and tail {m1['tail_s']:.2f} / {m2['tail_s']:.2f} s "
             f"not split: "
             f"at most x{sp['speedup_command_bound']:.2f}); other processes kept "
             f"{min(s1['others_cores'][0], s2['others_cores'][0]):.2f}-"
             f"{max(s1['others_cores'][1], s2['others_cores'][1]):.2f} of the {sp['cores']} cores "
             f"busy during the runs; CSVs equal: {sp['csv_1_equals_2_ranks']} "
             f"| >= 1.9 (issue 15) |"]
    if cost is None:
        return lines[0]
    per = "; ".join(f"{v['quantity']} (N = {v['elements']}) {v['cpu_s']:.2f} s CPU / "
                    f"{v['wall_s']:.2f} s wall" for v in cost.values())
    lines.append(f"| cost of one study point by stage | {per} | modal: no time loop |")
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--elements", type=int, default=ELEMENTS)
    parser.add_argument("--points", type=int, default=POINTS)
    parser.add_argument("--repeats", type=int, default=1)
    parser.add_argument("--skip-cost", action="store_true")
    parser.add_argument("--json", type=Path, default=None,
                        help="also write the result there (the 'study' section of results.json)")
    args = parser.parse_args()
    r = {"speedup": bench_speedup(args.points, args.elements, args.repeats)}
    sp = r["speedup"]
    print(json.dumps({k: sp[k] for k in ("median", "spread")}, indent=1), flush=True)
    print(json.dumps({k: v for k, v in sp.items() if k.startswith("speedup")}), flush=True)
    if not args.skip_cost:
        r["cost_per_point"] = bench_cost(args.elements)
    print(markdown(r))
    if args.json:
        args.json.write_text(json.dumps(r, indent=1) + "\n")


if __name__ == "__main__":
    main()
