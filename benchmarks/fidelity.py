"""The fidelity table of issue 14: what each option beyond the paper changes.

For the paper's model and each option (``OPTIONS``: a dict of dotted scene
overrides, as ``--set`` takes them) it measures, through the public API only
(``rh.load_scene``, ``rh.modes``, ``rh.simulate``, ``rh.orbits``):

* ``modes``: Table 3 (``stationary_table2``, the scene ``rawehelix modes``
  reproduces Table 3 with), the first mode of each family: frequency and
  decay rate;
* ``simulate``: Sec. 5.2 (``nominal_operation``): the settling time into the
  2 % band (the summary's ``settling_time_s``, studies/analysis/metrics.py) and the
  peak |ground torque|;
* ``sweep``: the same resonance by the paper's brute-force sweep
  (``rh.sweep`` on SWEEP_F1, continued upward): where the upper branch
  ends (the largest drop of T max) and its largest T max; the only
  measurement of the options whose orbits fail;
* ``orbits``: the Fig. 8 resonance (``mobile_end``): the branch from
  ``F1_START`` upward without superharmonic sites (as docs/explanation/orbits.md "Issue
  test 4"), stopped at the first point after the first fold; the fold's f1
  and T max and the peak (the first local maximum of T max that the branch
  locates, the vertex of its parabola; else the largest T max on the branch);

and the cost of each as the CPU time (time.process_time) of the same part
for the paper's model in the same process (orbits: CPU time per point).

    .venv/bin/python benchmarks/fidelity.py run modes simulate orbits sweep [--only NAME ...]
    .venv/bin/python benchmarks/fidelity.py table

``run`` stores each (part, option) in benchmarks/fidelity/<part>.json as it
finishes (a rerun skips what is stored unless ``--again``); ``table`` prints
the markdown of docs/explanation/model.md ("fidelity table").  Serial; a benchmark.
"""

from __future__ import annotations

import argparse
import json
import logging
import shutil
import statistics
import sys
import time
from pathlib import Path

import rawehelix as rh
from rawehelix.families import FAMILY_LABELS, VIBRATIONS

HERE = Path(__file__).resolve().parent / "fidelity"

#: the intrinsic law identified by `rawehelix labtest bending --fit` (docs/explanation/labtest.md)
EI_LAW = {"a_Nm2_per_N": 34.88, "b_Nm2": 2303.0}
#: retardation times [s]: round values that give each family's first Table 3
#: mode a damping ratio of about 1 % (the paper measures no decay rate; see
#: docs/explanation/model.md "fidelity table" for the ratios they give)
DAMPING = {"damping.axial_s": 1e-4, "damping.bending_s": 1e-3, "damping.torsion_s": 1e-3}
EXTENSIBLE = {"model.kinematics": "extensible"}
LAW = {**EXTENSIBLE, "helix.EI_law": EI_LAW}

#: GA [N] of the tensegrity's members (members.py::Members.shear_stiffness): the layout
#: that `rawehelix labtest torsion --fit` fits to GJ = 140 N m^2 under the lab's dead load
#: (6 tethers at R = 0.19 m, no lay, P0 = 632.6 N, bars EA_b = EA / 2; docs/explanation/
#: section.md) at the operating tension 200 N (each tether 649.3 N); 3833 N at 75 N
GA_MEMBERS = 3896.0
SHEARABLE = {f"shearable, GA {label}": {"model.kinematics": "shearable", "helix.GA_N": factor * GA_MEMBERS}
             for label, factor in (("members", 1.0), ("0.5 x members", 0.5), ("2 x members", 2.0))}

OPTIONS = {
    "paper": {},
    "extensible": EXTENSIBLE,
    "extensible + EI law": LAW,
    "damping": DAMPING,
    "EI law + damping": {**LAW, **DAMPING},
    **SHEARABLE,
}
HYSTERESIS = "torsion hysteresis"


def _hysteresis_law():
    """The Bouc-Wen law FIG5 of benchmarks/hysteresis.py as overrides, or None
    where the [torsion_hysteresis] switch is not in this tree."""
    import importlib.util
    path = Path(__file__).resolve().parent / "hysteresis.py"
    if not path.exists():
        return None
    spec = importlib.util.spec_from_file_location("hysteresis_benchmark", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return {f"torsion_hysteresis.{k}": v for k, v in module.FIG5.items()}


#: options whose row stays "pending" until measured (the hysteresis: until its branch is in)
PENDING = (HYSTERESIS,)

PARTS = ("modes", "simulate", "orbits", "sweep")
ELEMENTS = {"modes": 16, "simulate": 16, "orbits": 4, "sweep": 4}
SWEEP_F1 = [round(11.5 + 0.1 * k, 1) for k in range(15)]  # Hz, the sweep's grid
REPEATS = 3  # modes, simulate: the median CPU time of REPEATS runs after one that compiles
F1_START = 11.5  # Hz, the start of docs/explanation/orbits.md's fold window
#: the shearable rod's first lateral mode of mobile_end is 5-14 % below the paper's
#: (9.40, 9.08, 8.52 Hz at GA = 2x, 1x, 0.5x the members' against 9.86 Hz): its fold too
F1_START_OF = {name: 9.5 for name in SHEARABLE}
F1_START_OF["shearable, GA 0.5 x members"] = 6.0  # from rest its shooting fails at 9.5 and 8 Hz
F1_STOP = {"paper": 12.9, "extensible": 12.9, "damping": 12.9}  # else F1_STOP_WIDE
F1_STOP_WIDE = 14.5  # the EI law stiffens the Sec. 5.3 helix (+10 % EI at 73 N)
MAX_POINTS = 120  # the shearable rod at 0.5x the members' GA needs more than 60 from 6 Hz to its fold


#: why the shearable rows have no brute-force sweep (docs/explanation/shearable.md)
SWEEP_NOT_RUN = ("its shear modes are damped only by alpha2 (multiplier 0.9992 a period at "
                 "0.5 ms), so the sweep's points run to the 500-period cap; the orbits give "
                 "the fold")


class _NotRun(Exception):
    """An option a part does not run, with the reason."""


class _FoldPassed(Exception):
    """The branch turned back in f1: the first fold is behind the last point."""


def modes_row(name: str, overrides: dict, N: int) -> dict:
    scene = rh.load_scene("stationary_table2", elements=N, degree=3, overrides=overrides)
    rh.modes(scene)  # compiles the forms
    cpus = []
    for _ in range(REPEATS):
        start = time.process_time()
        result = rh.modes(scene)
        cpus.append(time.process_time() - start)
    cpu = statistics.median(cpus)
    first = {}
    for m in sorted(result, key=lambda m: m.frequency_Hz):
        if m.family in VIBRATIONS:
            first.setdefault(m.family, {"frequency_Hz": m.frequency_Hz,
                                        "decay_per_s": m.decay_per_s})
    return {"elements": N, "cpu_s": cpu, "first": first}


def simulate_row(name: str, overrides: dict, N: int) -> dict:
    scene = rh.load_scene("nominal_operation", elements=N, degree=3, overrides=overrides)
    rh.simulate(scene, until_s=0.1, progress=False)  # compiles the forms
    cpus = []
    for _ in range(REPEATS):
        start = time.process_time()
        ts = rh.simulate(scene, progress=False)
        cpus.append(time.process_time() - start)
    cpu = statistics.median(cpus)
    return {"elements": N, "cpu_s": cpu, "until_s": float(ts.t_s[-1]),
            "settling_time_s": ts.summary["settling_time_s"],
            "peak_ground_torque_Nm": float(abs(ts.ground_torque_Nm).max()),
            "tension_range_N": ts.summary["tension_range_N"],
            "max_spin_lag_rpm": float((ts.spin_rpm[:, 2] - ts.spin_rpm[:, 0]).max()),
            "steps": ts.summary["steps"]}


def orbits_row(name: str, overrides: dict, N: int) -> dict:
    scene = rh.load_scene("mobile_end", elements=N, degree=3, overrides=overrides)
    stop = F1_STOP.get(name, F1_STOP_WIDE)
    store = HERE / "orbits" / name.replace(" ", "_").replace("+", "and")
    shutil.rmtree(store, ignore_errors=True)
    seen = []

    def progress(orbit):
        seen.append(orbit.f1_Hz)
        if len(seen) > 2 and seen[-1] < seen[-2]:
            raise _FoldPassed()

    start = time.process_time()
    f1_start = F1_START_OF.get(name, F1_START)
    try:
        result = rh.orbits(scene, f1_start, stop, progress=progress, outdir=store,
                           superharmonics=(), max_points=MAX_POINTS)
    except _FoldPassed:  # the stored branch up to here, with its events
        result = rh.orbits(scene, f1_start, stop, outdir=store, superharmonics=(),
                           max_points=len(seen))
    cpu = time.process_time() - start
    f1 = [b["f1_Hz"] for b in result.branch]
    tmax = [b["tension_max_N"] for b in result.branch]
    k = max(range(len(tmax)), key=lambda i: tmax[i])
    located = [x for x in result.peaks if x["kind"] == "peak"]  # the branch's parabola vertex
    peak = ({"f1_Hz": located[0]["f1_Hz"], "tension_max_N": located[0]["tension_max_N"],
             "at_end": False} if located else
            {"f1_Hz": f1[k], "tension_max_N": tmax[k], "at_end": k == len(f1) - 1})
    fold = result.folds[0] if result.folds else None
    return {"elements": N, "cpu_s": cpu, "points": len(f1), "window_Hz": [f1_start, stop],
            "cpu_per_point_s": cpu / max(1, len(f1)),
            "fold": None if fold is None else {"f1_Hz": fold["f1_Hz"],
                                               "tension_max_N": fold["tension_max_N"],
                                               "f1_error_Hz": fold.get("f1_error_Hz")},
            "peak": peak, "f1_last_Hz": f1[-1], "folds": result.folds, "peaks": result.peaks,
            "branch": result.branch}


def sweep_row(name: str, overrides: dict, N: int) -> dict:
    """The paper's own Fig. 8 method: ``rh.sweep`` continued from one f1 of
    SWEEP_F1 to the next (time integration to the periodic state); the upper
    branch ends at the largest drop of T max."""
    scene = rh.load_scene("mobile_end", elements=N, degree=3, overrides=overrides)
    start = time.process_time()
    result = rh.sweep(scene, SWEEP_F1)
    cpu = time.process_time() - start
    f1 = [p["f1_Hz"] for p in result.points]
    tmax = [p["tension_max_N"] for p in result.points]
    drop = min(range(len(f1) - 1), key=lambda i: tmax[i + 1] - tmax[i])
    k = max(range(len(f1)), key=lambda i: tmax[i])
    return {"elements": N, "cpu_s": cpu, "f1_Hz": f1, "tension_max_N": tmax,
            "periodic": [bool(p["periodic"]) for p in result.points],
            "jump_Hz": [f1[drop], f1[drop + 1]], "jump_N": [tmax[drop], tmax[drop + 1]],
            "peak": {"f1_Hz": f1[k], "tension_max_N": tmax[k]}}


ROWS = {"modes": modes_row, "simulate": simulate_row, "orbits": orbits_row, "sweep": sweep_row}


def load(part: str) -> dict:
    path = HERE / f"{part}.json"
    return json.loads(path.read_text()) if path.exists() else {}


def run(parts, only, again: bool):
    HERE.mkdir(parents=True, exist_ok=True)
    options = dict(OPTIONS)
    law = _hysteresis_law()
    if law is not None:
        options[HYSTERESIS] = law
    for part in parts:
        stored = load(part)
        for name, overrides in options.items():
            if (only and name not in only and name != "paper") or (name in stored and not again
                                                                    and name != "paper"):
                continue
            print(f"[{time.strftime('%H:%M:%S')}] {part}: {name} ...", flush=True)
            try:
                if part == "sweep" and name in SHEARABLE:
                    raise _NotRun(SWEEP_NOT_RUN)
                row = ROWS[part](name, overrides, ELEMENTS[part])
            except _NotRun as why:
                row = {"not run": str(why)}
            except (rh.SceneError, rh.SolverError) as err:  # refused, or failed to solve
                if name == "paper":
                    raise
                kind = "refused" if isinstance(err, rh.SceneError) else "failed"
                row = {kind: str(err).splitlines()[0]}
            row["overrides"] = overrides
            if name == "paper":
                paper = row
            else:  # the paper's CPU time in this process: the cost's reference
                row.update({f"paper_{k}": paper[k] for k in ("cpu_s", "cpu_per_point_s")
                            if k in row})
            stored[name] = row
            (HERE / f"{part}.json").write_text(json.dumps(stored, indent=1))
            print(f"  {json.dumps(row)}", flush=True)


def _pct(x, ref):
    if x is None or ref is None:
        return "n/a"
    return f"{100 * (x / ref - 1):+.2f} %"


def _missing(name, row, columns: int) -> str:
    """The row of an option not measured ("pending"), refused or failed in the part."""
    if row is None:
        cells = ["pending"] * columns
    else:
        kind = next(k for k in ("refused", "failed", "not run") if k in row)
        cells = [f"{kind}: {row[kind]}"] + ["-"] * (columns - 1)
    return f"| {name} | " + " | ".join(cells) + " |"


def _n(ref):
    return f", N = {ref['elements']}, p = 3" if ref and "elements" in ref else ""


def _cost(row, ref, key="cpu_s"):
    """The CPU time against the paper's in the same process (``paper_<key>``)."""
    if not row or not ref:
        return "pending"
    return f"x{row[key] / row.get('paper_' + key, ref[key]):.2f}"


def _lines(rows: dict, columns: int, cells) -> list[str]:
    """A table's body: per option, ``cells(name, row, ref)`` (ref: the paper's
    row), or the missing row."""
    out, ref = [], rows.get("paper")
    for name in dict.fromkeys([*OPTIONS, *PENDING]):
        row = rows.get(name)
        if row is None or any(k in row for k in ("refused", "failed", "not run")):
            out.append(_missing(name, row, columns))
        else:
            out.append(f"| {name} | " + " | ".join(cells(name, row, ref)) + " |")
    return out


def _modes_cells(fams):
    def cells(name, row, ref):
        out = []
        for f in fams:
            m, r = row["first"][f], ref["first"][f]
            c = f"{m['frequency_Hz']:.4f}, {m['decay_per_s']:.4f}"
            if name != "paper":
                c += f" ({_pct(m['frequency_Hz'], r['frequency_Hz'])}, " \
                     f"{m['decay_per_s'] - r['decay_per_s']:+.4f})"
            out.append(c)
        return out + [_cost(row, ref)]
    return cells


def _simulate_cells(name, row, ref):
    st, tq = row["settling_time_s"], row["peak_ground_torque_Nm"]
    lag, (t_lo, t_hi) = row["max_spin_lag_rpm"], row["tension_range_N"]
    cells = [("not settled" if st is None else f"{st:.4f}"), f"{tq:.3f}"]
    if name != "paper":
        cells = [f"{cells[0]} ({_pct(st, ref['settling_time_s'])})",
                 f"{cells[1]} ({_pct(tq, ref['peak_ground_torque_Nm'])})"]
    return cells + [f"{lag:.3f}", f"{t_lo:.2f}-{t_hi:.2f}", _cost(row, ref)]


def _orbits_cells(name, row, ref):
    fold, peak = row["fold"], row["peak"]
    if fold is None:
        fc = f"none to {row['f1_last_Hz']:.2f} Hz"
    else:
        fc = f"{fold['f1_Hz']:.4f} ({fold['tension_max_N']:.1f})"
    pc = f"{peak['f1_Hz']:.4f}" + (" (window end)" if peak["at_end"] else "")
    tc = f"{peak['tension_max_N']:.1f}"
    if name != "paper" and ref is not None:
        if fold is not None and ref["fold"] is not None:
            fc += f" {fold['f1_Hz'] - ref['fold']['f1_Hz']:+.3f} Hz"
        pc += f" {peak['f1_Hz'] - ref['peak']['f1_Hz']:+.3f} Hz"
        tc += f" ({_pct(peak['tension_max_N'], ref['peak']['tension_max_N'])})"
    return [fc, pc, tc, str(row["points"]),
            f"{row['cpu_per_point_s']:.2f} s ({_cost(row, ref, 'cpu_per_point_s')})"]


def _sweep_cells(name, row, ref):
    (a, b), (ta, tb), peak = row["jump_Hz"], row["jump_N"], row["peak"]
    tc = f"{peak['tension_max_N']:.1f} ({peak['f1_Hz']:.1f})"
    if name != "paper":
        tc += f" {_pct(peak['tension_max_N'], ref['peak']['tension_max_N'])}"
    return [f"{a:.1f}-{b:.1f} ({ta:.0f} -> {tb:.0f})", tc, _cost(row, ref)]


def build_table(results: dict) -> str:
    """The markdown fidelity table from ``{part: {option: row}}`` (rows as
    :func:`run` stores them); options without a row say "pending"."""
    modes, sim, orb, swp = (results.get(part, {}) for part in PARTS)
    ref = modes.get("paper")
    fams = [f for f in VIBRATIONS if ref and f in ref["first"]]
    head = ["option"] + [f"{FAMILY_LABELS[f]} 1: f [Hz], decay [1/s]" for f in fams] + ["CPU"]
    out = [f"**Table 3** (`stationary_table2`{_n(ref)}, first mode of each family; change "
           "against the paper's model)", "", "| " + " | ".join(head) + " |",
           "|" + "---|" * len(head), *_lines(modes, len(head) - 1, _modes_cells(fams))]
    out += ["", f"**Sec. 5.2** (`nominal_operation`{_n(sim.get('paper'))}, 30 s)", "",
            "| option | settling time (2 %) [s] | peak ground torque [Nm] | max spin(L0) - "
            "spin(0) [rpm] | tension range [N] | CPU |", "|---|---|---|---|---|---|",
            *_lines(sim, 5, _simulate_cells)]
    out += ["", f"**Fig. 8 resonance** (`mobile_end`{_n(orb.get('paper'))}, `rh.orbits` from "
            f"{F1_START} Hz, to the first point after the first fold)", "",
            "| option | fold f1 [Hz] (T max [N]) | peak f1 [Hz] | peak T max [N] | points | "
            "CPU per point |", "|---|---|---|---|---|---|", *_lines(orb, 5, _orbits_cells)]
    out += ["", f"**Fig. 8 by the paper's sweep** (`mobile_end`{_n(swp.get('paper'))}, "
            f"`rh.sweep` at f1 = {SWEEP_F1[0]}, {SWEEP_F1[1]} .. {SWEEP_F1[-1]} Hz, continued "
            "upward)", "", "| option | upper branch ends between [Hz] (T max [N]) | "
            "largest T max [N] (at f1 [Hz]) | CPU |", "|---|---|---|---|",
            *_lines(swp, 3, _sweep_cells)]
    return "\n".join(out)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = p.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run")
    r.add_argument("parts", nargs="+", choices=PARTS)
    r.add_argument("--only", nargs="*", default=None, choices=[*OPTIONS, HYSTERESIS])
    r.add_argument("--again", action="store_true", help="recompute stored options")
    for part in PARTS:
        r.add_argument(f"--{part}-elements", type=int, default=ELEMENTS[part])
    sub.add_parser("table")
    a = p.parse_args(argv)
    if a.cmd == "run":
        import petsc4py
        petsc4py.init([])
        logging.disable(logging.INFO)
        for part in PARTS:
            ELEMENTS[part] = getattr(a, f"{part}_elements")
        run(a.parts, a.only, a.again)
    print(build_table({part: load(part) for part in PARTS}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
