"""`make bench`: the speed figures of rawehelix, as ratios and medians.  Not tests.

    .venv/bin/python benchmarks/run.py [--quick]

Writes ``benchmarks/results.json`` and ``benchmarks/results.md`` (the README
shows the table).  Each figure is the median of ``repeats`` runs with its
spread (min-max); the sweeps run once (minutes each), which the table says.

1. Sec. 5.3 sweep: FE at the converged resolution against the spline
   reference at N = 2 (the paper's method), same points, same process.
2. Cost of one time step against N (10 to 10^4) and the fitted exponent.
3. Sweep speed-up on 2 MPI ranks against 1 (mpirun, same command).
4. The modal solve (20 eigenpairs) at N = 2000, p = 3.
5. Real-time factor of the Sec. 5.2 and 5.3 scenes at converged resolution.
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

HERE = Path(__file__).parent
ROOT = HERE.parent
FE_SWEEP = {"elements": 8, "degree": 3}  # converged within 1 % (README, Sec. 5.3)
SWEEP_F1 = [float(f) for f in range(1, 16)]  # 15 points, 1-15 Hz


def stats(values):
    v = np.asarray(values, dtype=float)
    return {"median": float(np.median(v)), "min": float(v.min()), "max": float(v.max()),
            "runs": len(v)}


def quiet():
    import logging
    import petsc4py
    petsc4py.init([sys.argv[0]])
    logging.getLogger().setLevel(logging.WARNING)


def sweep_wall(scheme: str, f1: list[float], extra: dict | None = None) -> float:
    from mpi4py import MPI
    from rawehelix.studies import scene, sweep
    params = scene.load("mobile_end", scheme=scheme, **(extra or {}))
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        summary = sweep.run(params, Path(tmp) / "s", f1, comm=MPI.COMM_SELF, log=lambda *a: None)
        wall = time.perf_counter() - t0
    return wall, summary


def bench_sweep(f1):
    fe_wall, fe = sweep_wall("fe", f1, FE_SWEEP)
    sp_wall, sp = sweep_wall("spline", f1, {"elements": 2})
    return {"points": len(f1), "fe": {**FE_SWEEP, "wall_s": fe_wall, "resonance_Hz": fe["resonance_Hz"],
                                      "peak_tension_N": fe["peak_tension_N"]},
            "spline_N2": {"wall_s": sp_wall, "resonance_Hz": sp["resonance_Hz"],
                          "peak_tension_N": sp["peak_tension_N"]},
            "ratio_fe_over_spline": fe_wall / sp_wall}


def newton_iteration_cost(N: int, repeats: int) -> float:
    """One Newton iteration of a time step (residual, Jacobian, LU solve with the
    solvers' own choice, ``lu_options``) at the chord state; a step costs ~1-2 of these."""
    from petsc4py import PETSc
    from mpi4py import MPI
    from rawehelix import compat
    from rawehelix.solvers.discrete import RodDiscretisation
    from rawehelix.solvers.snes import lu_options
    from rawehelix.solvers.ts_forms import SecondOrder
    from rawehelix.studies import scene
    params = scene.load("nominal_operation", elements=N, degree=3)
    rod = RodDiscretisation(params, MPI.COMM_SELF, pin_twist=False)
    rod.set_chord()
    form = SecondOrder(rod, rod.bcs[:2])
    x = compat.petsc_vec(form.u).copy()
    b, A = form.b, form.A
    ksp = PETSc.KSP().create(MPI.COMM_SELF)
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    lu = lu_options(MPI.COMM_SELF)
    ksp.getPC().setFactorSolverType(lu["pc_factor_mat_solver_type"])
    if "pc_factor_mat_ordering_type" in lu:
        ksp.getPC().setFactorOrdering(lu["pc_factor_mat_ordering_type"])
    y = x.duplicate()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        form.shift_a.value, form.shift_v.value = 1e4, 1e2
        form.assemble_residual(x, b)
        form.assemble_jacobian(A)
        ksp.setOperators(A)
        ksp.solve(b, y)
        times.append(time.perf_counter() - t0)
    return stats(times)


def bench_step_cost(repeats: int, ladder):
    rows = {N: newton_iteration_cost(N, repeats) for N in ladder}
    Ns = np.array(ladder, dtype=float)
    t = np.array([rows[N]["median"] for N in ladder])
    big = Ns >= 100
    slope = float(np.polyfit(np.log(Ns[big]), np.log(t[big]), 1)[0])
    return {"per_N": {str(N): rows[N] for N in ladder}, "fitted_exponent_N>=100": slope}


def bench_mpi_speedup(f1):
    env = {**os.environ, "OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1"}
    exe = str(Path(sys.executable).with_name("rawehelix"))
    out = {}
    spec = f"{f1[0]}:{f1[-1]}:{f1[1] - f1[0]}"
    for n in (1, 2):
        with tempfile.TemporaryDirectory() as tmp:
            cmd = ["mpirun", "-n", str(n), "--oversubscribe", exe, "sweep", "mobile_end",
                   "--elements", str(FE_SWEEP["elements"]), "--f1", spec, "-o", f"{tmp}/s"]
            t0 = time.perf_counter()
            subprocess.run(cmd, check=True, env=env, stdout=subprocess.DEVNULL)
            out[f"{n}_ranks_s"] = time.perf_counter() - t0
    out["speedup"] = out["1_ranks_s"] / out["2_ranks_s"]
    out["f1"] = spec
    return out


def bench_modal(repeats: int):
    from mpi4py import MPI
    from rawehelix.solvers.modal import ModalSolver
    from rawehelix.studies import scene
    walls = []
    for _ in range(repeats):
        params = scene.load("stationary_table2", elements=2000, degree=3)
        solver = ModalSolver(params, MPI.COMM_SELF)
        solver.linearise()
        t0 = time.perf_counter()
        solver.solve(nev=20, keep_vectors=False, require_families=False)
        walls.append(time.perf_counter() - t0)
    return {"elements": 2000, "degree": 3, "nev": 20, "pep_solve_s": stats(walls)}


def bench_rtf(repeats: int):
    from mpi4py import MPI
    from rawehelix.solvers.dynamics import DynamicsSolver
    from rawehelix.solvers.forced import FEBackend
    from rawehelix.studies import scene
    out = {}
    rtf = []
    for _ in range(repeats):
        params = scene.load("nominal_operation", elements=8, degree=3)
        solver = DynamicsSolver(params, MPI.COMM_SELF)
        t0 = time.perf_counter()
        solver.advance(30.0 / solver.q.t_scale)
        rtf.append(30.0 / (time.perf_counter() - t0))
    out["sec5.2_N8_p3_alpha2_adaptive"] = stats(rtf)
    rtf = []
    for _ in range(repeats):
        params = scene.load("mobile_end", elements=8, degree=3)
        backend = FEBackend(params)
        q = params.normalised().at_frequency(10.0)
        t_end = 2.0 / q.t_scale
        t0 = time.perf_counter()
        backend.advance(backend.stationary(), q, 0.0, t_end, np.linspace(t_end / 200, t_end, 200))
        rtf.append(2.0 / (time.perf_counter() - t0))
    out["sec5.3_10Hz_N8_p3_alpha2_dt0.5ms"] = stats(rtf)
    return out


TARGETS = {
    "sweep": "FE at converged N: as fast as or faster than the paper's N = 2 reference (ratio <= 1)",
    "step_cost": "linear in N (exponent 1)",
    "mpi": "2 ranks: speed-up near 2 (2 cores)",
    "modal": "seconds (the paper: N = 2 only)",
    "rtf": "real-time factor >= 5 (Sec. 5.2)",
}


def markdown(r: dict) -> str:
    s, st, m, md, rt = (r.get(k) for k in ("sweep", "step_cost", "mpi", "modal", "rtf"))
    lines = [f"Measured {r['date']} on {r['machine']['cores']} cores.", "",
             "| benchmark | measured | target |", "| --- | --- | --- |"]
    if s:
        lines.append(f"| 1. Sec. 5.3 sweep, {s['points']} points (1 run each) | FE N = "
                     f"{FE_SWEEP['elements']}, p = 3: {s['fe']['wall_s']:.0f} s; spline N = 2: "
                     f"{s['spline_N2']['wall_s']:.0f} s; ratio FE/spline = "
                     f"{s['ratio_fe_over_spline']:.2f} | {TARGETS['sweep']} |")
    if st:
        per = ", ".join(f"N={k}: {v['median'] * 1e3:.2f} ms" for k, v in st["per_N"].items())
        lines.append(
            f"| 2. one Newton iteration of a step against N (median of "
            f"{next(iter(st['per_N'].values()))['runs']}) | {per}; fitted exponent "
            f"{st['fitted_exponent_N>=100']:.2f} (N >= 100) | {TARGETS['step_cost']} |")
    if m:
        lines.append(f"| 3. sweep f1 = {m['f1']} Hz on 2 ranks vs 1 (1 run each) | "
                     f"{m['1_ranks_s']:.0f} s vs {m['2_ranks_s']:.0f} s: speed-up {m['speedup']:.2f} "
                     f"| {TARGETS['mpi']} |")
    if md:
        p = md["pep_solve_s"]
        lines.append(f"| 4. modal solve, 20 eigenpairs, N = 2000, p = 3 | {p['median']:.2f} s "
                     f"({p['min']:.2f}-{p['max']:.2f}, {p['runs']} runs) | {TARGETS['modal']} |")
    for key, v in (rt or {}).items():
        lines.append(f"| 5. real-time factor, {key} | {v['median']:.1f} ({v['min']:.1f}-{v['max']:.1f}, "
                     f"{v['runs']} runs) | {TARGETS['rtf']} |")
    return "\n".join(lines) + "\n"


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--quick", action="store_true", help="fewer points and repeats")
    parser.add_argument("--only", default="step_cost,modal,rtf,sweep,mpi",
                        help="comma-separated sections to run")
    args = parser.parse_args()
    quiet()
    repeats = 2 if args.quick else 3
    f1 = SWEEP_F1[8::3] if args.quick else SWEEP_F1
    results = {"machine": {"cores": os.cpu_count()}, "date": time.strftime("%Y-%m-%d %H:%M")}
    only = set(args.only.split(","))
    steps = (10, 30, 100, 300, 1000, 3000, 10000)
    for name, fn in (("step_cost", lambda: bench_step_cost(repeats, steps)),
                     ("modal", lambda: bench_modal(repeats)),
                     ("rtf", lambda: bench_rtf(repeats)),
                     ("sweep", lambda: bench_sweep(f1)),
                     ("mpi", lambda: bench_mpi_speedup(f1[len(f1) // 2:]) if shutil.which("mpirun") else None)):
        if name not in only:
            continue
        t0 = time.perf_counter()
        results[name] = fn()
        print(f"{name}: done in {time.perf_counter() - t0:.0f} s", flush=True)
        (HERE / "results.json").write_text(json.dumps(results, indent=2) + "\n")
    (HERE / "results.md").write_text(markdown(results))
    print(markdown(results))


if __name__ == "__main__":
    main()
