"""`make bench` section ``hb_stability`` (issue 46): the whole Fig. 8 curve by harmonic
balance (``rawehelix orbits mobile_end --f1 15:0.5 --method hb``) with the guarded
stability step (solvers/harmonic_balance/stability.py) against Hill's method at every
point, in one session, in turn, CPU time in-process; the folds of both and each
guarded point's verdict against a full Hill solve at that point.  Not tests.

    .venv/bin/python benchmarks/hb_stability.py 8 [repeats]
"""

from __future__ import annotations

import json
import sys
import time

import numpy as np


def _curve(N: int, step) -> tuple[float, dict, list]:
    """(CPU [s], summary, the branch's orbits) of the curve with stability step ``step``."""
    import rawehelix as rh
    from rawehelix.solvers.harmonic_balance import problem as hb
    from rawehelix.studies import orbit_method
    seen = []
    finish = hb.HarmonicBalance.finish

    def kept(self, *a, **k):  # the orbits, for the check against a full Hill solve
        orbit = finish(self, *a, **k)
        seen.append(orbit)
        return orbit
    was = orbit_method.HB.stability
    hb.HarmonicBalance.finish, orbit_method.HB.stability = kept, step
    try:
        params = rh.load_scene("mobile_end", elements=N, degree=3)
        c0 = time.process_time()
        result = rh.orbits(params, 15.0, 0.5, method="hb")
        cpu = time.process_time() - c0
    finally:
        hb.HarmonicBalance.finish, orbit_method.HB.stability = finish, was
    by_f1 = {o.f1_Hz: o for o in seen}
    return cpu, result.summary, [by_f1[p["f1_Hz"]] for p in result.summary["branch"]]


def _stats(v):
    return {"median": float(np.median(v)), "min": float(min(v)), "max": float(max(v)),
            "runs": len(v)}


def bench(N: int = 8, repeats: int = 3, check: bool = True) -> dict:
    from rawehelix.solvers.harmonic_balance.problem import HarmonicBalance
    from rawehelix.solvers.harmonic_balance.stability import EVERY_POINT, GUARDED
    import rawehelix as rh
    cpu = {"every_point": [], "guarded": []}
    out = {}
    for _ in range(repeats):
        for step in (EVERY_POINT, GUARDED):
            c, summary, orbits = _curve(N, step)
            cpu[step.name].append(c)
            out[step.name] = (summary, orbits)
    (ref, _), (got, orbits) = out["every_point"], out["guarded"]
    carried = [o for o in orbits if "hill_f1_Hz" in o.accuracy]
    result = {"N": N, **{f"{k}_cpu_s": _stats(v) for k, v in cpu.items()},
              "points": {k: len(s["branch"]) for k, (s, _) in out.items()},
              "hill_solves": len(orbits) - len(carried),
              "folds_Hz": {k: [f["f1_Hz"] for f in s["folds"]] for k, (s, _) in out.items()},
              "bifurcations": {k: len(s["bifurcations"]) for k, (s, _) in out.items()}}
    result["ratio"] = result["guarded_cpu_s"]["median"] / result["every_point_cpu_s"]["median"]
    ref_f, got_f = result["folds_Hz"]["every_point"], result["folds_Hz"]["guarded"]
    result["fold_max_diff_Hz"] = (float(np.max(np.abs(np.subtract(ref_f, got_f))))
                                  if len(ref_f) == len(got_f) else None)
    if check:  # each guarded point's verdict against a full Hill solve at that point
        m = HarmonicBalance(rh.load_scene("mobile_end", elements=N, degree=3))
        differ = [o.f1_Hz for o in carried
                  if (np.abs(m.multipliers(o.X, o.f1_Hz, o.steps)[0]) < 1.0) != o.stable]
        result["carried_points"], result["verdicts_differing_Hz"] = len(carried), differ
    return result


if __name__ == "__main__":
    N = int(sys.argv[1]) if len(sys.argv) > 1 else 8
    repeats = int(sys.argv[2]) if len(sys.argv) > 2 else 1
    print(json.dumps(bench(N, repeats), indent=1))
