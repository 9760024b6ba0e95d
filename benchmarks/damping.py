"""Table 3's decay rates with structural damping ([damping], forms/damping.py), and its cost.

For the Table 2 helix (``stationary_table2``, gravity and drag on, the paper's
kinematics) at N elements of degree 3: the modes without damping and with
one retardation time ``--tau`` switched on per mechanism.  For each family the
lowest three modes: the decay rate added by the damping (damped minus
undamped, SI) against the closed form tau x (the mechanism's share of
omega^2) / 2 at the mean tension T (normalised, k = n pi):

* torsional: all of omega^2;
* longitudinal, tau_a: sigma k^2 of sigma (1 + 2 eps0) k^2 + mu k^4 (the
  paper's axial stiffness, Eq. 23; 2 sigma eps0 = 2 T is the tension's);
  tau_b: mu k^4 of it (the paper bends the whole r);
* lateral, tau_b: mu k^4 of T k^2 + mu k^4 (the pinned string-beam).

The cost: CPU time (time.process_time) of stationary + modes
(``studies.modes.compute``) with all three on against none, and of a 1 s
run of ``nominal_operation`` at N = 4 (alpha2, adaptive), median of
``--repeats`` after one run that compiles the forms.

    .venv/bin/python benchmarks/damping.py [--elements 16] [--tau 1e-3] [--repeats 5]

Prints the markdown of docs/explanation/model.md (section 'structural damping').
Serial (COMM_SELF); a benchmark, not a test.
"""

from __future__ import annotations

import argparse
import math
import statistics
import time

from kinematics import lowest  # noqa: E402  (benchmarks/kinematics.py: petsc4py set up)
from mpi4py import MPI  # noqa: E402

from rawehelix.families import FAMILY_LABELS, VIBRATIONS  # noqa: E402
from rawehelix.solvers.dynamics import DynamicsSolver  # noqa: E402
from rawehelix.studies import scene  # noqa: E402
from rawehelix.studies.modes import compute  # noqa: E402

MECHANISMS = ("axial_s", "bending_s", "torsion_s")


def modes(N: int, **damping):
    params = scene.load("stationary_table2", elements=N, degree=3).replace(damping=damping)
    start = time.process_time()
    result = compute(params, comm=MPI.COMM_SELF, scene="stationary_table2")
    return result, time.process_time() - start


def spin_up(**damping):
    params = scene.load("nominal_operation", elements=4, degree=3).replace(damping=damping)
    start = time.process_time()
    solver = DynamicsSolver.from_stationary(params, MPI.COMM_SELF)
    solver.advance(1.0 / solver.q.t_scale)
    return time.process_time() - start


def shares(family, q, T, n):
    """{mechanism: its share of omega^2} of the n-th mode (module docstring)."""
    k = n * math.pi
    if family == "torsional":
        return {"torsion_s": 1.0}
    if family == "longitudinal":
        total = q.sigma * (1 + 2 * q.eps0) * k**2 + q.mu * k**4
        return {"axial_s": q.sigma * k**2 / total, "bending_s": q.mu * k**4 / total}
    return {"bending_s": q.mu * k**4 / (T * k**2 + q.mu * k**4)}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--elements", type=int, default=16)
    ap.add_argument("--tau", type=float, default=1e-3, help="retardation time [s]")
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    N, tau = args.elements, args.tau
    q = scene.load("stationary_table2", elements=N).normalised()
    base, _ = modes(N)
    T = base.info["mean_tension_N"] / q.force_scale
    print(f"Table 3 at N = {N}, p = 3, each retardation time {tau:g} s alone: the decay rate it "
          f"adds [1/s] (FE) and the closed form\n")
    print("| family | n | undamped decay [1/s] | tau_a: FE / closed | tau_b: FE / closed "
          "| tau_t: FE / closed |")
    print("|---|---|---|---|---|---|")
    damped = {m: modes(N, **{m: tau})[0] for m in MECHANISMS}
    for f in VIBRATIONS:
        for n, mode in enumerate(lowest(base, f), start=1):
            omega2 = (abs(mode.eigenvalue) / q.t_scale) ** 2
            share = shares(f, q, T, n)
            cells = []
            for m in MECHANISMS:
                added = lowest(damped[m], f)[n - 1].decay_per_s - mode.decay_per_s
                closed = tau * share.get(m, 0.0) * omega2 / 2
                cells.append(f"{added:.5g} / {closed:.5g}" + (
                    f" ({added / closed - 1:+.2%})" if closed else ""))
            print(f"| {FAMILY_LABELS[f] if n == 1 else ''} | {n} | {mode.decay_per_s:.5f} | "
                  + " | ".join(cells) + " |")
    on = {m: tau for m in MECHANISMS}
    cpu = {"off": [], "on": []}
    dyn = {"off": [], "on": []}
    for key, damping in (("off", {}), ("on", on)):  # compile
        modes(N, **damping)
        spin_up(**damping)
    for _ in range(args.repeats):
        for key, damping in (("off", {}), ("on", on)):
            cpu[key].append(modes(N, **damping)[1])
            dyn[key].append(spin_up(**damping))
    med = {k: statistics.median(v) for k, v in cpu.items()}
    dmed = {k: statistics.median(v) for k, v in dyn.items()}
    print(f"\nmean tension {base.info['mean_tension_N']:.3f} N")
    print(f"stationary + modes at N = {N}, CPU s (median of {args.repeats}): undamped "
          f"{med['off']:.3f}, all three on {med['on']:.3f}, ratio {med['on'] / med['off']:.2f}")
    print(f"nominal_operation 1 s at N = 4, CPU s: undamped {dmed['off']:.3f}, all three on "
          f"{dmed['on']:.3f}, ratio {dmed['on'] / dmed['off']:.2f}")


if __name__ == "__main__":
    main()
