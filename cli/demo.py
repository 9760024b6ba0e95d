"""A helix designer's first three minutes: ``python -m rawehelix.cli.demo [OUTDIR]``.

Runs the paper's Sec. 5 with the public API, at small N, and writes
OUTDIR/report.html with every figure and the key tables:

    stationary/   Sec. 5.1: stationary state, checked against shooting (N = 16)
    modes/        Table 3: its modes (FE N = 16), mode GIFs
    modes_spline/ Table 3 with the paper's scheme (spline-Galerkin N = 2)
    spin_up/      Sec. 5.2 / Fig. 6: 10 s of the torque ramp and controller (N = 8)
    sweep/        Sec. 5.3 / Fig. 8: T max(f1) around the resonance (N = 8)

:func:`build_report` (summaries and image paths in, report.html out) is the
part that does not solve; ``tests/test_report.py`` runs it on synthetic data.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

from rawehelix.studies.present import paper
from rawehelix.studies.present.report import (TABLE3_HEADER, Figure, Section, Table, cell, table3_rows,
                                      write_report)

# Around the FE N = 8 resonance (12.5 Hz, then the drop at 13 Hz: docs/sweep/fe_N8):
# the rise, the peak and the fall in six points, ~30 s wall after the 10 s lead-in.
SWEEP_F1_HZ = (9.0, 10.0, 11.0, 12.0, 12.5, 13.0)
SPIN_UP_S = 10.0
STEPS = ("stationary", "modes", "modes_spline", "spin_up", "sweep")
PICTURES = ("*.png", "*.gif")


def images_in(folder: Path) -> list[Path]:
    """The pictures a result wrote into ``folder``, PNGs first."""
    folder = Path(folder)
    return [p for pattern in PICTURES for p in sorted(folder.glob(pattern))]


def main(outdir="results", log=print) -> Path:
    """Run the five studies into ``outdir`` and write ``outdir/report.html``."""
    import rawehelix as rh

    # Absolute from here on: the pictures are listed from the working directory and
    # the page resolves them against its own folder, so a relative outdir would count twice.
    outdir = Path(os.path.abspath(outdir))
    summaries, wall = {}, {}

    def step(name, compute):
        start = time.perf_counter()
        result = compute()
        result.write(outdir / name)
        wall[name] = time.perf_counter() - start
        summaries[name] = result.summary
        log(f"demo: {name} in {wall[name]:.1f} s -> {outdir / name}")

    scene = rh.load_scene("stationary_table2", elements=16)
    step("stationary", lambda: rh.stationary(scene))
    step("modes", lambda: rh.modes(scene))
    step("modes_spline", lambda: rh.modes(rh.load_scene("stationary_table2", scheme="spline",
                                                         elements=paper.TABLE3_ELEMENTS)))
    step("spin_up", lambda: rh.simulate(rh.load_scene("nominal_operation", elements=8),
                                        until_s=SPIN_UP_S))
    step("sweep", lambda: rh.sweep(rh.load_scene("mobile_end", elements=8),
                                   f1_Hz=list(SWEEP_F1_HZ)))
    images = {name: images_in(outdir / name) for name in STEPS}
    path = build_report(outdir, summaries, images, wall)
    log(f"demo: {sum(wall.values()):.0f} s in all; open {path}")
    return path


# -- the report ------------------------------------------------------------------------------
def _get(d: dict, *keys):
    """d[k1][k2]...; None where a key is missing."""
    for k in keys:
        if not isinstance(d, dict) or k not in d:
            return None
        d = d[k]
    return d


def _figures(paths, captions: dict) -> list[Figure]:
    return [Figure(p, captions.get(Path(p).name, Path(p).name)) for p in paths]


def stationary_section(s: dict, images) -> Section:
    rows = [["T(0) (N)", _get(s, "tension_N", "s0"), _get(s, "shooting_tension_s0_N"),
             paper.SEC52_TENSION_N],
            ["T(L0) (N)", _get(s, "tension_N", "s1"), None, None],
            ["sag (m)", _get(s, "sag_m"), None, None],
            ["max |r_FE - r_shooting| (m)", _get(s, "shooting_max_diff_m"), 0.0, None],
            ["Newton iterations", _get(s, "newton_iterations"), None, None]]
    return Section(
        "Sec. 5.1: the stationary state",
        [f"Table 2 helix with fixed ends, FE N = {_get(s, 'elements')}, p = {_get(s, 'degree')}: "
         "the stationary centre line found by Newton, against the independent shooting "
         "solution of Eqs. (67)-(68). The paper sets the elongation for a nominal tension "
         "of about 200 N."],
        [Table(["quantity", "FE", "shooting", "paper"], rows)],
        _figures(images, {"stationary.png": "The stationary centre line, its deflection from "
                          "the chord and the tension along s."}))


def modes_section(fe: dict, spline: dict, images) -> Section:
    tables = []
    for label, m in (("FE", fe), ("spline-Galerkin (the paper's scheme)", spline)):
        if m:
            tables.append(Table(TABLE3_HEADER, table3_rows(m),
                                f"Table 3 beside {label}, N = {_get(m, 'elements')}; "
                                "eigenvalues normalised by sqrt(L0/g) (Eq. 25)"))
    return Section(
        "Table 3: modes of the stationary state",
        ["Eigenvalues of the linearisation about the stationary state. Every family has "
         "negative or zero real part: the stationary state is stable. The paper's N = 2 is "
         "reproduced by the spline-Galerkin scheme; the FE column shows what more elements "
         "change. The animations show the first mode of each family oscillating about the "
         "stationary centre line (magnifications stated in each)."],
        tables, _figures(images, {"modes.png": "First mode of each family: displacement "
                                  "and twist along s, each scaled to 1."}))


def spin_up_section(s: dict, images) -> Section:
    target = _get(s, "target_rpm") or paper.SEC52_TARGET_RPM
    rows = [["spin at s = 0 (rpm)", _get(s, "final", "spin_rpm", "s0"), target],
            ["spin at mid-span (rpm)", _get(s, "final", "spin_rpm", "mid"), target],
            ["spin at s = L0 (rpm)", _get(s, "final", "spin_rpm", "L0"), target],
            ["tension T(0) (N)", _get(s, "final", "tension_s0_N"), paper.SEC52_TENSION_N],
            ["tension T(L0) (N)", _get(s, "final", "tension_L0_N"), paper.SEC52_TENSION_N],
            ["ground torque (N m)", _get(s, "final", "ground_torque_Nm"), None],
            ["settling time (s)", _get(s, "settling_time_s"), None]]
    t_range = _get(s, "tension_range_N")
    perf = [["simulated (s)", _get(s, "simulated_s")], ["wall (s)", _get(s, "wall_s")],
            ["real-time factor", _get(s, "real_time_factor")], ["time steps", _get(s, "steps")],
            ["Newton iterations", _get(s, "newton_iterations")]]
    return Section(
        "Sec. 5.2: spin-up in nominal operation (Fig. 6)",
        [f"The rotor torque ramps up as Eq. (69) and the ground-torque controller (40) drives "
         f"the helix to {target:g} rpm, FE N = {_get(s, 'elements')}. Values at the end of the "
         f"run (t = {_get(s, 'simulated_s') or 0:.1f} s), beside the paper's outcome (Fig. 6: "
         "every node at the target spin, tension almost constant, about 200 N)."
         + (f" Tension range over the run: {t_range[0]:.1f} to {t_range[1]:.1f} N."
            if t_range else "")],
        [Table(["at the end", "computed", "paper (Sec. 5.2)"], rows),
         Table(["cost", "value"], perf)],
        _figures(images, {"dynamics.png": "Fig. 6: spin at the nodes, ground torque and "
                          "tension against time."}))


def sweep_section(s: dict, images) -> Section:
    points = sorted(_get(s, "points") or [], key=lambda p: p["f1_Hz"])
    rows = [[p["f1_Hz"], p.get("tension_max_N"), p.get("tension_min_N"), p.get("tension_mean_N"),
             p.get("periodic"), p.get("wall_s")] for p in points]
    above = [p["f1_Hz"] for p in points if (p.get("tension_max_N") or 0) > paper.SEC52_TENSION_N]
    text = (f"The upper end circles with f1 (Eq. 70); for each f1 the tension at s = 0 is "
            f"integrated until periodic, continuing from the previous f1 (FE N = "
            f"{_get(s, 'elements')}). Largest T max at f1 = {cell(_get(s, 'resonance_Hz'))} Hz"
            f" ({cell(_get(s, 'peak_tension_N'))} N). The paper (N = 2) sees T max rise above "
            f"about {paper.FIG8_RISE_HZ:g} Hz and reach about 200 N near "
            f"{paper.FIG8_200N_HZ:g} Hz; here T max first exceeds 200 N at "
            f"{cell(above[0] if above else None)} Hz.")
    return Section(
        "Sec. 5.3: resonance with a mobile end (Fig. 8)", [text],
        [Table(["f1 (Hz)", "T max (N)", "T min (N)", "T mean (N)", "periodic", "wall (s)"], rows)],
        _figures(images, {"sweep.png": "Fig. 8: maximum tension at s = 0 against f1."}))


def build_report(outdir, summaries: dict, images: dict, wall_s: dict | None = None) -> Path:
    """Write ``outdir/report.html`` from the studies' summaries and pictures.

    summaries / images: keyed by STEPS (stationary, modes, modes_spline,
    spin_up, sweep); a missing key leaves its section out.  Image paths are
    absolute or relative to outdir; a missing image raises MissingImage."""
    outdir = Path(outdir)
    overview = Section(
        "What was computed",
        ["The helix of Tables 1-2 (and 4 for the mobile end) as an unshearable Cosserat rod "
         "(Sanchez-Arriaga et al.), solved with rawehelix at small N so that the whole page "
         "takes a few minutes. Every number is in SI unless marked normalised."],
        [Table(["study", "wall (s)"], [[k, v] for k, v in (wall_s or {}).items()])]
        if wall_s else [])
    sections = [overview]
    if "stationary" in summaries:
        sections.append(stationary_section(summaries["stationary"], images.get("stationary", [])))
    if "modes" in summaries or "modes_spline" in summaries:
        sections.append(modes_section(summaries.get("modes"), summaries.get("modes_spline"),
                                      images.get("modes", []) + images.get("modes_spline", [])))
    if "spin_up" in summaries:
        sections.append(spin_up_section(summaries["spin_up"], images.get("spin_up", [])))
    if "sweep" in summaries:
        sections.append(sweep_section(summaries["sweep"], images.get("sweep", [])))
    return write_report(outdir / "report.html", sections, "rawehelix: the helix of Sec. 5",
                        meta=f"written {time.strftime('%Y-%m-%d %H:%M')}")


def cli(argv=None):
    parser = argparse.ArgumentParser(prog="python -m rawehelix.cli.demo",
                                     description=__doc__.split("\n")[0])
    parser.add_argument("outdir", nargs="?", default="results")
    parser.add_argument("-v", "--verbose", action="count", default=0, help="more messages")
    args = parser.parse_args(argv)
    from rawehelix.studies import logs
    logs.configure(args.verbose)  # no JIT-compiler chatter on a cold cache
    main(args.outdir)


if __name__ == "__main__":
    cli()
