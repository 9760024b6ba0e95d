"""Issue 46: the Sec. 5.3 run (mobile_end, 10 Hz, N = 8, p = 3, dt = 0.5 ms) by
`simulate` with PETSc TS (the default) against -rawehelix_ts_compiled 1, taken in
turn in one process, ``--repeats`` times; CPU time (process_time) of the time
loop (DynamicsSolver.advance: steps and the outputs' callbacks; set-up, the
stationary solve and the JIT excluded), and the same loop's parts on the compiled
path (the compiled steps, the time data in Python, the outputs).  Not a test.

    .venv/bin/python benchmarks/compiled_step.py [--until 2] [--repeats 3] [--output-every 0.002]
"""

from __future__ import annotations

import argparse
import json
import logging
import time

import numpy as np


#: the compiled loop's parts (exclusive CPU: a part's own time, its sub-parts'
#: excluded), each by the function it is: (module path, attribute path, name)
PARTS = (
    ("rawehelix.solvers.compiled_step", "_steps", "compiled steps (nopython)"),
    ("rawehelix.solvers.compiled_step", "CompiledChordAlpha.time_data", "time data (fitted)"),
    ("rawehelix.solvers.compiled_step", "CompiledChordAlpha.run", "a compiled call's Python"),
    ("rawehelix.solvers.probes", "Probes.values", "point values"),
    ("rawehelix.solvers.probes", "Probes.section", "section state (limits)"),
    ("rawehelix.studies.analysis.structure_limits", "Tracker.add", "limits tracker"),
    ("rawehelix.studies.simulate", "_Recorder.frame", "frames (fields)"),
    ("rawehelix.solvers.dynamics", "DynamicsSolver._accepted", "an output's other Python"),
    ("rawehelix.solvers.compiled_step", "CompiledAdvance.__init__",
     "the compiled steps' set-up (once a run: forms, ordering)"),
    ("rawehelix.solvers.chord", "ChordAlpha.start", "the start (TSALPHA2's half steps, Python)"),
)
LOOP = "the loop's other Python"


def _loop_cpu(params, until, options, parts=None):
    """CPU seconds of simulate.compute's time loop (and ``parts``: exclusive seconds by
    part of :data:`PARTS`, the rest of the loop under :data:`LOOP`)."""
    import importlib
    from rawehelix.solvers.dynamics import DynamicsSolver
    from rawehelix.studies import simulate
    acc = {"loop": 0.0}
    saved = []
    stack = [0.0]  # the children's time of each open part

    def wrap(owner, name, key):
        f = getattr(owner, name)
        saved.append((owner, name, f))

        def timed(*a, **k):
            stack.append(0.0)
            t = time.process_time()
            try:
                return f(*a, **k)
            finally:
                spent = time.process_time() - t
                children = stack.pop()
                acc[key] = acc.get(key, 0.0) + spent - children
                stack[-1] += spent
        setattr(owner, name, timed)
    wrap(DynamicsSolver, "advance", LOOP)
    if parts is not None:
        for module, path, key in PARTS:
            owner = importlib.import_module(module)
            *outer, name = path.split(".")
            for o in outer:
                owner = getattr(owner, o)
            wrap(owner, name, key)
    try:
        result = simulate.compute(params, until_s=until, options=options, progress=False)
    finally:
        for owner, name, f in reversed(saved):
            setattr(owner, name, f)
    acc["loop"] = stack[0]
    if parts is not None:
        for k, v in acc.items():
            parts[k] = parts.get(k, 0.0) + v
        parts["steps"] = parts.get("steps", 0) + result.summary["steps"]
        parts["outputs"] = parts.get("outputs", 0) + len(result.rows) - 1
    return acc["loop"], result


def newton_variants(params, until: float = 2.0, variants=((1e-14, 0.03), (1e-14, 0.01),
                                                           (1e-13, 0.03), (1e-12, 0.03))):
    """Hairer's tol and the LU refresh rate of the compiled steps (issue 46, item c):
    Newton iterations and factorisations a step and the compiled steps' CPU, ``until``
    simulated at 50 ms output."""
    from rawehelix.solvers import compiled_step
    params = params.replace(time={"output_every_s": 0.05})
    out = {}
    init = compiled_step.CompiledChordAlpha.__init__
    for tol, rate in variants:
        made = []

        def variant(self, *a, **k):
            k.update(tol=tol, rate=rate)
            init(self, *a, **k)
            made.append(self)
        compiled_step.CompiledChordAlpha.__init__ = variant
        try:
            parts = {}
            _loop_cpu(params, until, {"ts_compiled": 1}, parts)
        finally:
            compiled_step.CompiledChordAlpha.__init__ = init
        c = made[-1]._counters
        out[f"tol {tol:g}, rate {rate:g}"] = {
            "iterations_per_step": c[0] / c[2], "factorisations_per_step": c[1] / c[2],
            "steps_us_per_step": parts["compiled steps (nopython)"] / c[2] * 1e6}
    return out


def floor_us(params, repeats: int = 2000) -> dict:
    """CPU microseconds of a compiled step's parts at the stationary state (a loop of
    ``repeats`` calls from Python; the call's dispatch, ~1-2 us, included); the
    band is J's renumbered (solvers/banded_lu.py)."""
    from rawehelix.solvers import banded_lu, compiled_forms
    from rawehelix.solvers.compiled_step import CompiledChordAlpha
    s = CompiledChordAlpha(params)
    op, forms = s.op, s.forms
    n, kl = op.n, s.bandwidth
    X, c = op.X_stationary.copy(), forms.constants()
    h = params.time.dt_s / params.normalised().t_scale
    cj = forms.jacobian_constants(c, *s.alpha.shifts(h))
    Fp, Jp = forms.pieces()
    R, J, piv, x = np.zeros(n), np.zeros((n, n)), np.zeros(n, np.int64), np.zeros(n)
    A, LT, UT = np.zeros((n, n)), np.zeros((n, kl)), np.zeros((n, 2 * kl))
    compiled_forms.jacobian(J, X, cj, Jp, s._bc)
    banded_lu.permute(J, s._perm, A)
    LU = A.copy()
    banded_lu.factor(LU, piv, kl, LT, UT)
    t0 = 0.1
    parts = {"residual F": lambda: compiled_forms.residual(R, X, c, Fp),
             "banded LU solve": lambda: banded_lu.solve(LU, LT, UT, piv, kl, R, x),
             "Jacobian J": lambda: compiled_forms.jacobian(J, X, cj, Jp, s._bc),
             "banded LU factor": lambda: banded_lu.factor(A.copy(), piv, kl, LT, UT),
             "time data (a 4-step stretch, fitted)": lambda: s.time_data(
                 t0 + np.arange(4) * h, t0 + 4 * h),
             "time data (a 4-step stretch, set_time a step)": lambda: s.time_data(
                 t0 + np.arange(4) * h)}
    parts.update(_output_floor(params))
    out = {}
    for name, f in parts.items():
        m = repeats // 10 if "J" in name or "factor" in name else repeats
        f()
        t0 = time.process_time()
        for _ in range(m):
            f()
        out[name] = (time.process_time() - t0) / m * 1e6
    out["bandwidth"], out["unknowns"] = kl, n
    return out


def _output_floor(params) -> dict:
    """An output's probes, each the way it is and the way it was (issue 46): the point
    values by one Expression against the 10 forms' assembly, the section state by the
    C++ interpolation against Function.interpolate and an MPI gather."""
    import dolfinx.fem
    from mpi4py import MPI
    from rawehelix.solvers import fields
    from rawehelix.solvers.dynamics import DynamicsSolver
    solver = DynamicsSolver.from_stationary(params, MPI.COMM_SELF)
    probes, sp = solver.probes, solver.probes.section_probe

    def section_before():
        sp._u.interpolate(sp._expr)
        s = sp._u.function_space.tabulate_dof_coordinates()[:, 0]
        MPI.COMM_SELF.gather(s, root=0), MPI.COMM_SELF.gather(sp._u.x.array, root=0)
        return fields.gather(sp._u)
    return {"point values (one Expression)": probes.values,
            "point values (10 forms, before)": lambda: [
                dolfinx.fem.assemble_scalar(f) for f in probes.forms.values()],
            "section state (C++ interpolation)": probes.section,
            "section state (Function.interpolate, MPI gather, before)": section_before}


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--until", type=float, default=2.0)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--output-every", type=float, default=None,
                        help="time.output_every_s (default: the scene's, 2 ms)")
    parser.add_argument("--json", default=None)
    args = parser.parse_args()
    logging.getLogger().setLevel(logging.WARNING)
    from rawehelix.studies import scene
    params = scene.load("mobile_end", elements=8, degree=3).replace(
        ends={"circle_frequency_Hz": 10.0})
    if args.output_every:
        params = params.replace(time={"output_every_s": args.output_every})
    variants = {"ts": {}, "compiled": {"ts_compiled": 1}}
    _loop_cpu(params, 0.01, variants["compiled"])  # the JIT (cached to disk after the first)
    cpu = {k: [] for k in variants}
    rows, parts = {}, {}
    for _ in range(args.repeats):
        for key, options in variants.items():
            c, result = _loop_cpu(params, args.until, options, parts if key == "compiled" else None)
            cpu[key].append(c)
            rows[key] = result.rows
    out = {"until_s": args.until, "output_every_s": params.time.output_every_s}
    for key in variants:
        rtf = args.until / np.array(cpu[key])
        out[key] = {"rtf_median": float(np.median(rtf)), "rtf_min": float(rtf.min()),
                    "rtf_max": float(rtf.max()), "loop_cpu_s": cpu[key]}
    out["ratio"] = out["compiled"]["rtf_median"] / out["ts"]["rtf_median"]
    out["compiled_parts_s"] = {k: v / args.repeats for k, v in parts.items()}  # each run's
    T = {k: r[:, 5] for k, r in rows.items()}
    out["tension_s0_max_N"] = {k: float(v.max()) for k, v in T.items()}
    out["tension_s0_rel_diff"] = float(np.abs(T["compiled"] - T["ts"]).max() / np.abs(T["ts"]).max())
    out["floor_us"] = floor_us(params)
    print(json.dumps(out, indent=1))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(out, f, indent=1)


if __name__ == "__main__":
    main()
