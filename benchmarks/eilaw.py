"""The EI law of Eq. (64) (helix.EI_law, EI = 52.4 T + 2290): its effect and its cost.

For the Table 2 helix (``stationary_table2``) and the Sec. 5.3 helix
(``mobile_end`` with fixed ends: no circle, no torque, no controller) at N
elements of degree 3, three models:

* ``paper``: the default model (paper's kinematics, EI = EI_Nm2);
* ``extensible``: model.kinematics = "extensible", EI = EI_Nm2;
* ``law``: extensible with EI = a T + b at the local tension.

Prints the stationary tension (at s = 0, mean, at s = 1, N) and the lowest
three lateral frequencies (Hz) in and out of plane of each, and the CPU time
(time.process_time) of a stationary solve and of a modal solve (linearisation
+ SLEPc) about it, the median of ``--repeats`` runs after one that compiles
the forms, with the ratios to ``paper``.

    .venv/bin/python benchmarks/eilaw.py [--elements 16] [--repeats 5]

Serial (COMM_SELF); a benchmark, not a test.  docs/explanation/model.md (section
'tension-dependent bending') quotes its output.
"""

from __future__ import annotations

import argparse
import logging
import statistics
import time

import petsc4py

petsc4py.init([])
logging.disable(logging.INFO)

import numpy as np  # noqa: E402
from mpi4py import MPI  # noqa: E402

from rawehelix.solvers.modal import ModalSolver  # noqa: E402
from rawehelix.solvers.stationary import StationarySolver  # noqa: E402
from rawehelix.parameters import PAPER_EI_LAW  # noqa: E402
from rawehelix.studies import scene  # noqa: E402

MODELS = ("paper", "extensible", "law")
LATERAL = ("lateral_in_plane", "lateral_out_of_plane")


def params(name: str, model: str, N: int):
    p = scene.load(name, elements=N, degree=3)
    if name == "mobile_end":
        p = p.replace(ends={"circle_radius_m": 0.0, "circle_frequency_Hz": 0.0},
                      torque={"top_Nm": 0.0}, controller={"k1": 0.0, "k2": 0.0})
    if model == "paper":
        return p
    return p.replace(model={"kinematics": "extensible"},
                     helix={"EI_law": PAPER_EI_LAW if model == "law" else None})


def run(p):
    """(stationary result, modes, CPU s of the stationary solve, CPU s of the modal solve)."""
    start = time.process_time()
    stationary = StationarySolver(p, MPI.COMM_SELF)
    result = stationary.solve()
    middle = time.process_time()
    solver = ModalSolver(p, MPI.COMM_SELF, rod=stationary.rod)
    solver.linearise(result.state)
    modes = solver.solve()
    return result, modes, middle - start, time.process_time() - middle


def lateral_Hz(modes, q):
    out = {}
    for f in LATERAL:
        w = sorted(abs(m.eigenvalue) for m in modes if m.family == f)[:3]
        out[f] = np.array(w) / q.t_scale / (2 * np.pi)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--elements", type=int, default=16)
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    N = args.elements
    for name in ("stationary_table2", "mobile_end"):
        print(f"\n{name}, N = {N}, p = 3; EI_Nm2 = {params(name, 'paper', N).helix.EI_Nm2:g}")
        print("| model | T(0), mean, T(1) [N] | in-plane n = 1, 2, 3 [Hz] | out-of-plane [Hz] |")
        print("|---|---|---|---|")
        base = None
        for model in MODELS:
            p = params(name, model, N)
            q = p.normalised()
            result, modes, _, _ = run(p)
            T = q.tension_N(result.tension)
            EI = "" if model != "law" else f" (EI({np.mean(T):.1f} N) = {p.helix.EI_law.EI_Nm2(np.mean(T)):.0f})"
            f = lateral_Hz(modes, q)
            if model == "extensible":
                base = f
            cells = [f"{T[0]:.3f}, {np.mean(T):.3f}, {T[-1]:.3f}"]
            for fam in LATERAL:
                text = ", ".join(f"{x:.4f}" for x in f[fam])
                if model == "law":
                    text += " (" + ", ".join(f"{x / y - 1:+.2%}"
                                             for x, y in zip(f[fam], base[fam])) + ")"
                cells.append(text)
            print(f"| {model}{EI} | " + " | ".join(cells) + " |")
    # cost, Table 2
    cpu = {m: ([], []) for m in MODELS}
    for m in MODELS:
        run(params("stationary_table2", m, N))  # compiles the forms
    for _ in range(args.repeats):
        for m in MODELS:
            _, _, ts, tm = run(params("stationary_table2", m, N))
            cpu[m][0].append(ts)
            cpu[m][1].append(tm)
    med = {m: (statistics.median(cpu[m][0]), statistics.median(cpu[m][1])) for m in MODELS}
    print(f"\nCPU s, Table 2, N = {N}, median of {args.repeats} (ratio to paper):")
    for m in MODELS:
        print(f"  {m:10s} stationary {med[m][0]:.3f} ({med[m][0] / med['paper'][0]:.2f}), "
              f"modal {med[m][1]:.3f} ({med[m][1] / med['paper'][1]:.2f})")


if __name__ == "__main__":
    main()
