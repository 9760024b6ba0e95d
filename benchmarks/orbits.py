"""The cost of a continuation point of the FE periodic orbits (solvers/orbits.py), before
and after the chord steps and the sparse tangent, in CPU time in one process.

For N elements (degree 3) of ``mobile_end``: the orbit at ``F1`` Hz (shot once), then
for each of ``AlphaMap(newton="full")`` (the former map: full Newton, dense F_U, F_V,
F_A and LU in every iteration, dense tangent) and the default chord map, a branch
traced from it (``Branch.trace``, the same start), ``points`` points: CPU time
(time.process_time) of each point, median and spread.  Also one plain period and
one tangent (Floquet) period at F1, and where a point's CPU time goes (cProfile
with the process-time clock, one point each, by part).

    .venv/bin/python benchmarks/orbits.py [--elements 4,8] [--points 4]
    .venv/bin/python benchmarks/run.py --only orbits

Prints the markdown of docs/explanation/orbits.md ("Cost of a point").  A benchmark, not a test.
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import statistics
import time

F1 = 11.5  # Hz: the upper branch below the peak, T max changing fast (short steps)
#: parts of a point's CPU time: (label, substrings of the profiled function names)
PARTS = (("matrix assembly", ("assemble_matrix", "pack_coefficients", "pack_constants",
                              "getValuesCSR", "zeroEntries")),
         ("residual assembly", ("assemble_vector",)),
         ("dense conversion", ("_dense",)),
         ("LU factorisation", ("lu_factor", "gstrf", "getrf")),
         ("LU solves", ("lu_solve", "getrs", "'solve' of 'SuperLU'")),
         ("tangent products and newmark", ("csr_matvecs", "_combine", "axpy", "newmark")),
         ("eigenvalues, dense solves", ("eigvals", "linalg.py:solve", "lstsq")))


def _params(elements):
    import rawehelix as rh
    return rh.load_scene("mobile_end", elements=elements, degree=3)


def _parts(stats: pstats.Stats) -> dict:
    """tottime [s] by part of PARTS; the rest is Python (step loop, numpy glue)."""
    out = {label: 0.0 for label, _ in PARTS}
    out["Python and the rest"] = 0.0
    for (path, line, name), (_, _, tottime, _, _) in stats.stats.items():
        where = f"{path}:{name}"
        for label, keys in PARTS:
            if any(k in where for k in keys):
                out[label] += tottime
                break
        else:
            out["Python and the rest"] += tottime
    return out


def bench_point_cost(elements: int, points: int = 4) -> dict:
    """CPU time per continuation point, the former map against the chord one."""
    from rawehelix.studies.orbits import branch as Branch  # the study's observable and guards
    from rawehelix.solvers.orbits import AlphaMap
    from rawehelix.studies.orbits import LEAD_IN_PERIODS

    params = _params(elements)
    chord = AlphaMap(params)
    full = AlphaMap(params, newton="full", solver=chord.solver)
    first = chord.orbit(chord.X_stationary, F1, lead_in=LEAD_IN_PERIODS)
    X = first.X
    out = {"elements": elements, "state": 3 * chord.n, "f1_Hz": F1,
           "steps_per_period": chord.steps_per_period(F1)}
    for name, m in (("full", full), ("chord", chord)):
        row = {}
        t = time.process_time()
        m.period(X, F1)
        row["plain_period_s"] = time.process_time() - t
        m._kept = None
        t = time.process_time()
        m.period(X, F1, tangent=True)
        row["tangent_period_s"] = time.process_time() - t
        branch = Branch(m)
        times, marks = [], [time.process_time()]

        def tick(orbit):
            marks.append(time.process_time())
            times.append(marks[-1] - marks[-2])

        branch.start(first, 1.0)
        marks[0] = time.process_time()
        for _ in range(points):
            branch.trace(None, 15.0, max_points=len(branch.points) + 1, progress=tick)
        profile = cProfile.Profile(time.process_time)  # one more point, not timed
        profile.enable()
        branch.trace(None, 15.0, max_points=len(branch.points) + 1)
        profile.disable()
        row["point_s"] = {"median": statistics.median(times), "min": min(times),
                          "max": max(times), "points": len(times)}
        row["tension_max_N"] = [p.tension_max_N for p in branch.points[1:points + 1]]
        row["f1_Hz"] = [p.f1_Hz for p in branch.points[1:points + 1]]
        row["parts_profiled_point_s"] = _parts(pstats.Stats(profile))
        out[name] = row
    f, c = out["full"], out["chord"]
    out["speedup_point"] = f["point_s"]["median"] / c["point_s"]["median"]
    out["speedup_plain_period"] = f["plain_period_s"] / c["plain_period_s"]
    out["speedup_tangent_period"] = f["tangent_period_s"] / c["tangent_period_s"]
    out["tension_max_rel_difference"] = max(
        abs(a / b - 1) for a, b in zip(c["tension_max_N"], f["tension_max_N"]))
    out["f1_difference_Hz"] = max(abs(a - b) for a, b in zip(c["f1_Hz"], f["f1_Hz"]))
    return out


def bench_orbits(elements=(4, 8), points: int = 4) -> dict:
    return {f"N{n}": bench_point_cost(n, points) for n in elements}


def markdown(r: dict) -> str:
    lines = ["| N (3n) | map | plain period | tangent period | point: median (min-max) | "
             "speed-up of a point |", "| --- | --- | --- | --- | --- | --- |"]
    for v in r.values():
        for name in ("full", "chord"):
            row = v[name]
            p = row["point_s"]
            lines.append(f"| {v['elements']} ({v['state']}) | {name} | {row['plain_period_s']:.2f} s "
                         f"| {row['tangent_period_s']:.2f} s | {p['median']:.2f} s "
                         f"({p['min']:.2f}-{p['max']:.2f}, {p['points']} points) | "
                         + (f"x{v['speedup_point']:.2f} (periods: plain x{v['speedup_plain_period']:.1f}, "
                            f"tangent x{v['speedup_tangent_period']:.1f}); T max of the points "
                            f"within {v['tension_max_rel_difference']:.1e}, f1 within "
                            f"{v['f1_difference_Hz']:.1e} Hz |" if name == "chord" else "|"))
    lines += ["", "Where a point's CPU time goes (one more point under cProfile with the process-time clock, which inflates the many small calls, in the Python column):", "",
              "| N | map | " + " | ".join(next(iter(r.values()))["full"]["parts_profiled_point_s"]) + " |",
              "| --- | --- |" + " --- |" * len(next(iter(r.values()))["full"]["parts_profiled_point_s"])]
    for v in r.values():
        for name in ("full", "chord"):
            parts = v[name]["parts_profiled_point_s"]
            lines.append(f"| {v['elements']} | {name} | "
                         + " | ".join(f"{s:.2f}" for s in parts.values()) + " |")
    return "\n".join(lines) + "\n"


def main():
    import json
    import logging

    import petsc4py
    petsc4py.init([])
    logging.getLogger().setLevel(logging.WARNING)
    parser = argparse.ArgumentParser()
    parser.add_argument("--elements", default="4,8")
    parser.add_argument("--points", type=int, default=4)
    args = parser.parse_args()
    r = bench_orbits(tuple(int(n) for n in args.elements.split(",")), args.points)
    print(json.dumps(r, indent=1))
    print(markdown(r))


if __name__ == "__main__":
    main()
