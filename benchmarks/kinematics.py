"""Table 3 with model.kinematics = "paper" and "extensible", and the cost of the switch.

For the Table 2 helix (``stationary_table2``) at N elements of degree 3: the
stationary state and its modes (``studies.modes.compute``) with both
kinematics, the lowest three modes of each family side by side (|lambda|
normalised, frequency, decay rate) and the CPU time (time.process_time, so
that other processes on the machine do not count) of stationary + modes,
the median of ``--repeats`` runs after one that compiles the forms.

    .venv/bin/python benchmarks/kinematics.py [--elements 16] [--repeats 5]

Prints the markdown table of docs/explanation/model.md (section 'kinematics').
Serial (COMM_SELF); a benchmark, not a test.
"""

from __future__ import annotations

import argparse
import logging
import statistics
import time

import petsc4py

petsc4py.init([])
logging.disable(logging.INFO)

from mpi4py import MPI  # noqa: E402

from rawehelix.families import FAMILY_LABELS, VIBRATIONS  # noqa: E402
from rawehelix.studies import scene  # noqa: E402
from rawehelix.studies.modes import compute  # noqa: E402

KINEMATICS = ("paper", "extensible")


def run(kinematics: str, N: int):
    params = scene.load("stationary_table2", elements=N, degree=3).replace(
        model={"kinematics": kinematics})
    start = time.process_time()
    result = compute(params, comm=MPI.COMM_SELF, scene="stationary_table2")
    return result, time.process_time() - start


def lowest(result, family, count=3):
    return sorted((m for m in result if m.family == family), key=lambda m: abs(m.eigenvalue))[:count]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--elements", type=int, default=16)
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    results, cpu = {}, {k: [] for k in KINEMATICS}
    for k in KINEMATICS:
        run(k, args.elements)  # compiles the forms
    for _ in range(args.repeats):
        for k in KINEMATICS:
            results[k], t = run(k, args.elements)
            cpu[k].append(t)
    print(f"Table 3 at N = {args.elements}, p = 3 (|lambda| normalised, frequency in Hz)\n")
    print("| family | n | paper | extensible | change | decay paper / extensible [1/s] |")
    print("|---|---|---|---|---|---|")
    for f in VIBRATIONS:
        pairs = zip(lowest(results["paper"], f), lowest(results["extensible"], f))
        for n, (a, b) in enumerate(pairs, start=1):
            la, lb = abs(a.eigenvalue), abs(b.eigenvalue)
            print(f"| {FAMILY_LABELS[f] if n == 1 else ''} | {n} | {la:.4f} ({a.frequency_Hz:.4f}) "
                  f"| {lb:.4f} ({b.frequency_Hz:.4f}) | {lb / la - 1:+.3%} "
                  f"| {a.decay_per_s:.5f} / {b.decay_per_s:.5f} |")
    tension = {k: results[k].info["mean_tension_N"] for k in KINEMATICS}
    median = {k: statistics.median(cpu[k]) for k in KINEMATICS}
    print(f"\nmean tension [N]: paper {tension['paper']:.3f}, extensible {tension['extensible']:.3f}")
    print(f"stationary + modes, CPU s (median of {args.repeats}): paper {median['paper']:.3f}, "
          f"extensible {median['extensible']:.3f}, ratio "
          f"{median['extensible'] / median['paper']:.2f}")


if __name__ == "__main__":
    main()
