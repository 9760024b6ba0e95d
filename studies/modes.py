"""``rawehelix modes``: stationary state and its modes, printed like Table 3.

:func:`format_table` and :func:`write_summary` are scheme-independent: they
take the ``modes`` entries of the summary (keys ``family``, ``eigenvalue``,
``eigenvalue_per_s``, ``period_s``, ``dominant``).
"""

from __future__ import annotations

import json
import math
import pathlib
import time

from rawehelix.parameters import Parameters

FAMILY_LABELS = {
    "longitudinal": "Longitudinal",
    "lateral_in_plane": "Lateral (x-z)",
    "lateral_out_of_plane": "Lateral (y)",
    "torsional": "Torsional",
    "rigid": "Rigid rotation",
}


def mode_entry(eigenvalue: complex, family: str, dominant: list, t_scale: float,
               zero_tol: float = 1e-4) -> dict:
    """One summary entry; eigenvalue normalised, t_scale in s (Eq. 25)."""
    lam = complex(eigenvalue)
    oscillatory = family != "rigid" and abs(lam.imag) > zero_tol
    return {
        "family": family,
        "eigenvalue": [lam.real, lam.imag],
        "eigenvalue_per_s": [lam.real / t_scale, lam.imag / t_scale],
        "period_s": 2 * math.pi / abs(lam.imag) * t_scale if oscillatory else None,
        "dominant": list(dominant),
    }


def format_table(modes: list[dict]) -> str:
    """Table 3 layout: eigenvalue (normalised), dominant components, mode, period (s)."""
    head = f"{'Eigenvalue':>24}  {'Dominant components':<34} {'Mode':<15} {'Period (s)':>10}"
    lines = [head, "-" * len(head)]
    for m in modes:
        re, im = (round(v, 2) + 0.0 for v in m["eigenvalue"])  # + 0.0: no "-0.00"
        ev = f"{re:.2f} {'±' if im else '+'} {abs(im):.2f}i"
        dom = ", ".join(m["dominant"])  # state names as in Table 3: xdot_1, alphadot_0
        if len(dom) > 34:
            dom = dom[:31] + "..."
        period = "N/A" if m["period_s"] is None else f"{m['period_s']:.3f}"
        lines.append(f"{ev:>24}  {dom:<34} {FAMILY_LABELS.get(m['family'], m['family']):<15} "
                     f"{period:>10}")
    return "\n".join(lines)


def write_summary(outdir: pathlib.Path, summary: dict) -> pathlib.Path:
    """Write ``outdir/summary.json`` (creating outdir) and return its path."""
    outdir = pathlib.Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    path = outdir / "summary.json"
    path.write_text(json.dumps(summary, indent=2) + "\n")
    return path


def _select(modes: list, count: int | None) -> list:
    """The ``count`` slowest modes (smallest |lambda|), kept in Table 3 order."""
    if count is None or count >= len(modes):
        return modes
    keep = sorted(range(len(modes)), key=lambda k: abs(modes[k].eigenvalue))[:max(count, 0)]
    return [modes[k] for k in sorted(keep)]


def spline_modes(params: Parameters, count: int | None = None) -> list[dict]:
    """Stationary state (Newton from the shooting solution) and spectrum, spline scheme."""
    from rawehelix.solvers.spline_galerkin import spectrum, stationary
    from rawehelix.solvers.spline_galerkin.system import SplineGalerkin

    nd = params.normalised()
    system = SplineGalerkin(nd, params.discretisation.elements)
    state = stationary.solve(system)
    found = _select(spectrum.modes(system, state.x), count)
    return [mode_entry(m.eigenvalue, m.family, m.dominant, nd.t_scale) for m in found]


def fe_modes(params: Parameters, outdir: pathlib.Path | None, count: int | None = None,
             comm=None, log=print, scene: str = "scene") -> dict:
    """Stationary state, its modes (SLEPc, :mod:`rawehelix.solvers.modal`) and the outputs.

    Writes on rank 0 only: ``summary.json``, ``modes.png`` (the first mode of
    each family) and ``modes.xdmf`` (the stationary centre line with those
    modes as point data, for ParaView).  Returns the summary on every rank."""
    import numpy as np
    from mpi4py import MPI

    from rawehelix.solvers.modal import FAMILIES, ModalSolver
    from rawehelix.studies import writers

    comm = comm or MPI.COMM_WORLD
    start = time.perf_counter()
    q = params.normalised()
    disc = params.discretisation
    solver = ModalSolver(params, comm, scene=scene)
    solver.linearise()
    nev = None if count is None else max(solver.default_nev(), 2 * count + 4)
    found = solver.solve(nev=nev, require_families=False)
    if count is None:
        missing = solver.missing
    else:
        missing = {}
    modes = _select(found, count)
    wall = time.perf_counter() - start
    firsts = {}
    for m in found:  # sorted by |lambda|: the first of each family
        if m.family != "rigid" and m.family not in firsts:
            firsts[m.family] = m
    firsts = {f: firsts[f] for f in FAMILIES if f in firsts}
    shapes = {f: solver.mode_shape(m) for f, m in firsts.items()}  # collective
    stationary = solver.stationary.gather()  # collective
    summary = None
    if comm.rank == 0:
        summary = {
            "scheme": "fe",
            "elements": disc.elements,
            "degree": disc.degree,
            "dofs": solver.rod.dof_count(),
            "ranks": comm.size,
            "gamma": params.model.gamma,
            "model": params.model.describe(),
            "mean_tension_N": float(q.tension_N(solver.mean_tension_value)),
            "missing_families": missing,
            "wall_s": wall,
            "modes": [mode_entry(m.eigenvalue, m.family, m.dominant, q.t_scale) for m in modes],
        }
        # per mode (same order): kinetic-energy fractions, twist with beta/delta (Eq. 27)
        summary["kinetic_energy_fractions"] = [
            {k: float(v) for k, v in m.fractions.items()} for m in modes]
        if outdir is not None:
            outdir = pathlib.Path(outdir)
            outdir.mkdir(parents=True, exist_ok=True)
            x = stationary.centre_line
            chord = q.top_position() / np.linalg.norm(q.top_position())
            normal = np.cross([0.0, 1.0, 0.0], chord)
            panels, point_data = {}, {"s_m": q.length_m(stationary.s)}
            for f, m in firsts.items():
                s, u, alpha = shapes[f]
                lam = m.eigenvalue
                u_max = np.linalg.norm(u, axis=1).max() or 1.0
                a_max = np.abs(alpha).max() or 1.0
                # a part below 1e-4 of the other one (normalised units) is round-off
                # or a weak slaved response: drawn as zero, not blown up to 1
                u_scale = u_max if u_max >= 1e-4 * a_max else math.inf
                a_scale = a_max if a_max >= 1e-4 * u_max else math.inf
                label = (f"{FAMILY_LABELS[f]}: lambda = {lam.real:.2f} + {lam.imag:.2f}i, "
                         f"{abs(lam.imag) / (2 * math.pi * q.t_scale):.2f} Hz\n"
                         f"max|alpha| / max|r~ displacement| = {a_max / u_max:.2g}")
                panels[label] = (u @ chord / u_scale, u @ normal / u_scale, u[:, 1] / u_scale,
                                 alpha / a_scale)
                point_data[f"{f}_displacement"] = u
                point_data[f"{f}_alpha"] = alpha
            writers.mode_shapes_png(outdir / "modes.png", q.length_m(stationary.s), panels,
                                    f"First modes of each family, FE N = {disc.elements}, "
                                    f"p = {disc.degree} (displacement and twist each scaled to 1)")
            writers.centre_line_xdmf(outdir / "modes.xdmf", q.length_m(x), point_data)
            writers.write_json(outdir / "summary.json", summary)
    return comm.bcast(summary, root=0)


def run(params: Parameters, outdir: pathlib.Path, count: int | None = None, log=print) -> dict:
    """Modes of the stationary state; prints the table and writes ``summary.json``.

    Parameters
    ----------
    params : the scene; ``params.discretisation.scheme`` picks the solver.
    outdir : created only after the computation succeeded.
    count : keep the ``count`` slowest modes (all when None).
    """
    scheme = params.discretisation.scheme
    if scheme == "fe":
        summary = fe_modes(params, outdir, count, log=log)
        log(f"Modes of the stationary state, scheme fe, N = {summary['elements']}, "
            f"p = {summary['degree']} ({summary['dofs']} dofs, {summary['wall_s']:.2f} s)")
        log(format_table(summary["modes"]))
        if summary["missing_families"]:
            log(f"note: fewer than 3 modes found for {summary['missing_families']}: "
                "try more elements (--elements) or -rawehelix_pep_nev")
        log(f"wrote {outdir}/summary.json, modes.png, modes.xdmf")
        return summary
    if scheme != "spline":
        raise ValueError(f"unknown scheme {scheme!r}")
    start = time.perf_counter()
    modes = spline_modes(params, count)
    summary = {
        "scheme": scheme,
        "elements": params.discretisation.elements,
        "wall_s": time.perf_counter() - start,
        "modes": modes,
    }
    log(f"Modes of the stationary state, scheme {scheme}, N = {summary['elements']}")
    log(format_table(modes))
    write_summary(outdir, summary)
    return summary
