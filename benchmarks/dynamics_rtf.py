"""Real-time factor of the Sec. 5.2 scene (30 s) and where the time goes.

    .venv/bin/python benchmarks/dynamics_rtf.py [--elements 8] [--degree 3] [PETSc options]

Reports, for the default (alpha2, adaptive) and a few hot-path variants:
simulated s per wall s of the time loop (set-up, the stationary solve and the
JIT excluded; sampling the outputs every 0.05 s included), and the shares of
residual assembly, Jacobian assembly (Python timers around the dolfinx calls)
and linear solves (PETSc's KSPSolve + PCSetUp events: LU factorisation and
triangular solves).  Not a test.
"""

from __future__ import annotations

import argparse
import sys
import time

import petsc4py


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--elements", type=int, default=8)
    parser.add_argument("--degree", type=int, default=3)
    parser.add_argument("--until", type=float, default=30.0)
    args, petsc_args = parser.parse_known_args()
    petsc4py.init([sys.argv[0], *petsc_args])
    import logging
    logging.getLogger().setLevel(logging.WARNING)
    from petsc4py import PETSc
    from rawehelix.solvers.dynamics import DynamicsSolver
    from rawehelix.studies import scene

    PETSc.Log.begin()
    params = scene.load("nominal_operation", elements=args.elements, degree=args.degree)
    variants = {
        "alpha2, adaptive (default)": {},
        "+ Jacobian lagged 2": {"ts_snes_lag_jacobian": 2, "ts_snes_lag_jacobian_persists": 1},
        "+ lagged 2, LU reused in a step": {"ts_snes_lag_jacobian": 2,
                                            "ts_snes_lag_preconditioner": 2},
        "alpha2, fixed dt = 0.01 s": {"ts_adapt_type": "none"},
        "cn (first-order form), adaptive": {"ts_type": "cn"},
    }
    print(f"Sec. 5.2, {args.until:g} s, N = {args.elements}, p = {args.degree}")
    print(f"{'variant':36s} {'RTF':>6s} {'steps':>6s} {'Newton':>7s} {'wall s':>7s} "
          f"{'resid%':>7s} {'jac%':>6s} {'linear%':>8s} {'final spin rpm':>15s}")
    for name, opts in variants.items():
        p = params.replace(time={"dt_s": 0.01}) if "fixed" in name else params
        solver = DynamicsSolver.from_stationary(p, options=opts)
        timers = {"residual": 0.0, "jacobian": 0.0}

        def timed(fn, key):
            def wrapper(*a, **k):
                t0 = time.perf_counter()
                out = fn(*a, **k)
                timers[key] += time.perf_counter() - t0
                return out
            return wrapper
        solver.form.assemble_residual = timed(solver.form.assemble_residual, "residual")
        solver.form.assemble_jacobian = timed(solver.form.assemble_jacobian, "jacobian")
        ksp0 = _event("KSPSolve") + _event("PCSetUp")
        last = {}

        def sample(sv):
            last.update(sv.probes.values())
        q = solver.q
        t0 = time.perf_counter()
        solver.advance(args.until / q.t_scale, on_output=sample, output_every=0.05 / q.t_scale)
        wall = time.perf_counter() - t0
        linear = _event("KSPSolve") + _event("PCSetUp") - ksp0
        share = lambda x: 100 * x / wall  # noqa: E731
        print(f"{name:36s} {args.until / wall:6.1f} {solver.steps:6d} {solver.newton_iterations:7d} "
              f"{wall:7.2f} {share(timers['residual']):7.1f} {share(timers['jacobian']):6.1f} "
              f"{share(linear):8.1f} {q.spin_rpm(last['spin0']):15.4f}")


def _event(name: str) -> float:
    from petsc4py import PETSc
    return PETSc.Log.Event(name).getPerfInfo()["time"]


if __name__ == "__main__":
    main()
