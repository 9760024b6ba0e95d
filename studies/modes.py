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

from rawehelix.forms.parameters import Parameters

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
        raise NotImplementedError("FE modal analysis is issue 4")
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
