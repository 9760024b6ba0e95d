"""The bending operator at large N: interior penalty (IP) against the mixed form.

For the Table 2 helix (``stationary_table2``, gamma off as in the scene):

1. the stationary state against the shooting reference (Sys. 67):
   max |r_FE - r_shooting| at the nodes [m] and |T(0) / T_shooting(0) - 1|,
   with the Newton iterations and the test that accepted the state
   (``rtol``, ``stol``, or the round-off ``floor`` of solvers.snes);
2. the lowest eigenvalue |lambda| of each family, relative deviation from
   the mixed form at N = 256, p = 4.

    .venv/bin/python benchmarks/large_n.py [-o docs/explanation/large_n.md]

Serial (COMM_SELF); a benchmark, not a test (a few minutes).
"""

from __future__ import annotations

import argparse
import logging
import math
import time
from pathlib import Path

import petsc4py

petsc4py.init([])
logging.disable(logging.INFO)

import numpy as np  # noqa: E402
from mpi4py import MPI  # noqa: E402

from rawehelix.families import VIBRATIONS as FAMILIES  # noqa: E402
from rawehelix.references import shooting  # noqa: E402
from rawehelix.solvers.modal import ModalSolver  # noqa: E402
from rawehelix.solvers.snes import SolverError  # noqa: E402
from rawehelix.solvers.stationary import StationarySolver  # noqa: E402
from rawehelix.studies import scene  # noqa: E402

STATIONARY_N = (2, 4, 8, 16, 32, 64, 128, 256, 512, 1000, 2000, 4000, 10000)
MODAL_N = (8, 16, 64, 256, 1000, 2000, 4000, 10000)
MODAL_IP_N = (8, 16, 64, 256, 1000, 2000)  # IP's Newton fails from N = 4000 on
REFERENCE = (256, 4, "mixed")


def params(N, p, bending):
    return scene.load("stationary_table2", elements=N, degree=p,
                      overrides={"discretisation.bending": bending})


def stationary(N, p, bending, reference):
    """(|dr| [m], |dT0| rel, its, accepted by, |dx|/|x| of the last step, wall) or None."""
    prm = params(N, p, bending)
    q = prm.normalised()
    solver = StationarySolver(prm, MPI.COMM_SELF)
    conv = solver.newton.convergence
    history = []

    def test(snes, it, norms):
        history.append(norms)
        return conv(snes, it, norms)
    solver.newton.snes.setConvergenceTest(test)
    start = time.perf_counter()
    try:
        res = solver.solve()
    except SolverError:
        return None
    wall = time.perf_counter() - start
    dr = float(np.max(np.linalg.norm(res.centre_line - reference.centre_line(res.s), axis=1)) * q.L0)
    T0 = float(np.ravel(reference.tension(0.0))[0])
    dT = abs(res.tension[0] - T0) / abs(T0)
    xnorm, ynorm, fnorm = history[-1]
    f0 = history[0][2]
    rtol, atol, stol, _ = solver.newton.snes.getTolerances()
    by = ("floor" if conv.on_floor else "atol" if fnorm <= atol else
          "rtol" if fnorm <= rtol * f0 else "stol")
    return dr, dT, res.newton_iterations, by, ynorm / max(xnorm, 1e-300), wall


def lowest(N, p, bending):
    prm = params(N, p, bending)
    start = time.perf_counter()
    try:
        solver = ModalSolver.from_stationary(prm, MPI.COMM_SELF, scene="stationary_table2")
    except SolverError:
        return None, math.nan
    modes = solver.solve(per_family=1, keep_vectors=False, require_families=False)
    found = {}
    for m in modes:
        found.setdefault(m.family, abs(m.eigenvalue))
    return found, time.perf_counter() - start


def rate(e0, e1):
    return "" if not (e0 and e1 and e0 > 0 and e1 > 0) else f"{math.log2(e0 / e1):.2f}"


def stationary_table(p, reference, log):
    lines = [f"### p = {p}", "",
             "| N | mixed: max dr [m] | rate | T(0) rel. error | rate | Newton | accepted by | last step | wall [s] "
             "| IP: max dr [m] | T(0) rel. error | accepted by |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    prev = None
    for N in STATIONARY_N:
        m = stationary(N, p, "mixed", reference)
        ip = stationary(N, p, "ip", reference) if N <= 4000 else None  # 10^4: 50 failing iterations
        ip_cells = (f"{ip[0]:.2e} | {ip[1]:.2e} | {ip[3]}" if ip else
                    "Newton fails | | " if N <= 4000 else "(not run: fails from 4000) | |")
        if m is None:
            lines.append(f"| {N} | Newton fails | | | | | | | | {ip_cells} |")
            continue
        r_rate = rate(prev[0], m[0]) if prev and N == 2 * prev[2] else ""
        t_rate = rate(prev[1], m[1]) if prev and N == 2 * prev[2] else ""
        lines.append(f"| {N} | {m[0]:.2e} | {r_rate} | {m[1]:.2e} | {t_rate} | {m[2]} | {m[3]} | "
                     f"{m[4]:.1e} | {m[5]:.2f} | {ip_cells} |")
        log(lines[-1])
        prev = (m[0], m[1], N)
    return lines


def modal_table(log):
    ref, wall = lowest(*REFERENCE)
    lines = [f"Reference: mixed form, N = {REFERENCE[0]}, p = {REFERENCE[1]} ({wall:.1f} s): "
             + ", ".join(f"{f} {ref[f]:.10f}" for f in FAMILIES), "",
             "| N | form | " + " | ".join(FAMILIES) + " | wall [s] |",
             "|---|---|" + "---|" * len(FAMILIES) + "---|"]
    for N in MODAL_N:
        for bending in ("mixed", "ip"):
            if bending == "ip" and N not in MODAL_IP_N:
                continue
            found, wall = lowest(N, 3, bending)
            if found is None:
                cells = ["Newton fails"] * len(FAMILIES)
            else:
                cells = [f"{found[f] / ref[f] - 1:+.1e}" if f in found else "—" for f in FAMILIES]
            lines.append(f"| {N} | {bending} | " + " | ".join(cells) + f" | {wall:.2f} |")
            log(lines[-1])
    return lines


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("-o", "--output", type=Path, default=None)
    args = ap.parse_args()
    q = params(2, 3, "mixed").normalised()
    reference = shooting.solve(q)
    T0 = float(np.ravel(reference.tension(0.0))[0])
    lines = ["# Large N: the bending operator (generated by benchmarks/large_n.py)", "",
             f"Table 2 helix, gamma off; shooting T(0) = {float(q.tension_N(T0)):.6f} N.", "",
             "## Stationary state against shooting", ""]
    for p in (3, 2):
        lines += stationary_table(p, reference, print) + [""]
    lines += ["## Lowest eigenvalue of each family, p = 3 (relative deviation)", ""]
    lines += modal_table(print) + [""]
    text = "\n".join(lines)
    if args.output:
        args.output.write_text(text)
    print(text)


if __name__ == "__main__":
    main()
