"""`make bench` section ``hb`` (issue 31): harmonic balance's cost, as ratios in one
session.  Not tests.

* the whole Fig. 8 curve (``rawehelix orbits mobile_end --f1 15:0.5 --method hb``) at
  N = 8 against the brute-force sweep (``rawehelix sweep --f1 0.5:15:0.5``) at the same
  N, CPU time of each whole command, run in turn (target: 1/20);
* the same curve at N = 32, against N = 8's;
* a fold curve over a factor of 4 in EI at N = 8 (``rawehelix envelope``, EI 2500 to
  10000 N m^2, 2 branches, 9-16 Hz), its CPU time against that of the one-parameter branches it
  replaces (one a fold-curve point);
* where a point's time goes at N = 8 and 32 (the AFT residual, the Jacobian's assembly,
  the PETSc LU, Hill's method), in CPU time.
"""

from __future__ import annotations

import json
import shutil
import time
from pathlib import Path

HERE = Path(__file__).parent


def curves(rawehelix: str, stats, cpu_of, repeats: int = 1) -> dict:
    out = HERE / "hb_runs"
    cases = {"hb_N8": ["orbits", "mobile_end", "--elements", "8", "--f1", "15:0.5",
                       "--method", "hb"],
             "sweep_N8": ["sweep", "mobile_end", "--elements", "8", "--f1", "0.5:15:0.5"],
             "hb_N32": ["orbits", "mobile_end", "--elements", "32", "--f1", "15:0.5",
                        "--method", "hb"]}
    cpu = {k: [] for k in cases}
    for _ in range(repeats):
        for key, args in cases.items():
            shutil.rmtree(out / key, ignore_errors=True)
            cpu[key].append(cpu_of([rawehelix, *args, "-o", str(out / key)]))
    got = {k: json.loads((out / k / "summary.json").read_text()) for k in ("hb_N8", "hb_N32")}
    shutil.rmtree(out, ignore_errors=True)
    result = {f"{k}_cpu_s": stats(v) for k, v in cpu.items()}
    for k, s in got.items():
        result[f"{k}_points"] = len(s["branch"])
        result[f"{k}_folds_Hz"] = [f["f1_Hz"] for f in s["folds"]]
        result[f"{k}_H"] = sorted({p["accuracy"]["H"] for p in s["branch"]})
    med = {k: result[f"{k}_cpu_s"]["median"] for k in cases}
    result["ratio_hb_over_sweep_N8"] = med["hb_N8"] / med["sweep_N8"]
    result["ratio_N32_over_N8"] = med["hb_N32"] / med["hb_N8"]
    return result


def fold_curve(stats) -> dict:
    """The envelope's fold curves over EI x 4 against its branches, CPU time in-process."""
    import rawehelix as rh
    params = rh.load_scene("mobile_end", elements=8, degree=3)
    t0 = time.process_time()
    result = rh.envelope(params, "helix.EI_Nm2=2500:10000:2", 9.0, 16.0)
    total = time.process_time() - t0
    s = result.summary
    branches = sum(t["wall_s"] for t in s["ticks"])  # one process, one core: wall ~ CPU
    points = sum(len(c["points"]) for c in s["fold_curves"])
    folds = s["fold_curves_wall_s"]
    per_branch = branches / len(s["ticks"])
    return {"fold_curve_points": points, "fold_curves_cpu_s": folds,
            "branches": len(s["ticks"]), "branch_cpu_s": per_branch,
            "replaced_cpu_s": points * per_branch,
            "ratio_fold_curve_over_replaced": folds / (points * per_branch),
            "fold_check_max_Hz": s["fold_check_max_Hz"], "envelope_cpu_s": total,
            "ends": [c["end"] for c in s["fold_curves"]]}


def parts(stats, elements=(8, 32), f1: float = 10.0, repeats: int = 3) -> dict:
    """CPU time of a point's parts at 10 Hz."""
    import rawehelix as rh
    from rawehelix.solvers.harmonic_balance.problem import HarmonicBalance
    from rawehelix.solvers.harmonic_balance.sparse_lu import LU
    out = {}
    for N in elements:
        m = HarmonicBalance(rh.load_scene("mobile_end", elements=N, degree=3))
        o = m.orbit(m.X_stationary, f1)
        t = {"residual": [], "jacobian": [], "lu": [], "hill": []}
        for _ in range(repeats):
            c = time.process_time()
            m.residual(o.X, f1, resolution=o.steps)
            t["residual"].append(time.process_time() - c)
            c = time.process_time()
            _, _, J = m.residual(o.X, f1, jacobian=True, resolution=o.steps)
            t["jacobian"].append(time.process_time() - c)
            c = time.process_time()
            LU(J).solve(o.G)
            t["lu"].append(time.process_time() - c)
            tangents = m.sampled(o.X, f1, resolution=o.steps)[2]
            c = time.process_time()
            m.hill(f1, o.steps, tangents)
            t["hill"].append(time.process_time() - c)
        out[str(N)] = {"H": o.steps, "unknowns": int(o.X.size),
                       **{k: stats(v) for k, v in t.items()}}
    return out


def bench_hb(rawehelix: str, stats, cpu_of, repeats: int = 1) -> dict:
    """``stats`` and ``cpu_of``: run.py's (a figure's median and spread, a command's CPU time)."""
    return {"curves": curves(rawehelix, stats, cpu_of, repeats), "fold_curve": fold_curve(stats),
            "parts": parts(stats)}


def markdown(r: dict) -> list[str]:
    c, f, p = r["curves"], r["fold_curve"], r["parts"]
    med = lambda v: f"{v['median']:.0f} s"  # noqa: E731
    lines = [
        f"| 14. the whole Fig. 8 curve by harmonic balance (`orbits --f1 15:0.5 --method hb`, "
        f"{c['hb_N8_points']} points, H {c['hb_N8_H']}) against the brute-force sweep, N = 8, "
        f"CPU of each command | {med(c['hb_N8_cpu_s'])} against {med(c['sweep_N8_cpu_s'])}: "
        f"ratio {c['ratio_hb_over_sweep_N8']:.2f} (shooting: 0.50, item 11) | <= 1/20 "
        f"(issue 31): not met, Hill's method is about 90 % of a point |",
        f"| 14. the same curve at N = 32 ({c['hb_N32_points']} points) | "
        f"{med(c['hb_N32_cpu_s'])}: x{c['ratio_N32_over_N8']:.1f} N = 8's | measured |",
        f"| 14. fold curves over EI x 4 (2500-10000 N m^2) at N = 8, {f['fold_curve_points']} "
        f"points | {f['fold_curves_cpu_s']:.0f} s against {f['replaced_cpu_s']:.0f} s for the "
        f"one-parameter branches they replace (one {f['branch_cpu_s']:.0f} s a point): ratio "
        f"{f['ratio_fold_curve_over_replaced']:.3f} | measured |"]
    for N, v in p.items():
        lines.append(
            f"| 14. a point's parts at N = {N}, H = {v['H']} ({v['unknowns']} unknowns), CPU | "
            + ", ".join(f"{k} {v[k]['median'] * 1e3:.1f} ms" for k in ("residual", "jacobian",
                                                                        "lu", "hill"))
            + " | measured |")
    return lines
