"""The linear frequency response of Sec. 5.3: ``rawehelix response``.

:func:`compute` linearises the scene about its stationary state with the
upper end at the centre of its circle (:func:`rawehelix.solvers.response.centre`),
solves the steady harmonic response to the circle of Eq. (70) at each f1
(:class:`~rawehelix.solvers.response.HarmonicResponse`) and returns a
:class:`ResponseResult`:

* ``points``: per f1 the midpoint's lateral amplitude (semi-major axis of its
  ellipse, and the in-plane and out-of-plane amplitudes) [m] and the tension
  amplitude at s = 0 [N];
* ``peaks``: the interior local maxima of the in-plane, the out-of-plane and
  the tension curves on the grid, each refined by a bounded Brent search
  (golden section with parabolic steps) on the log amplitude between its grid
  neighbours, and merged where two curves find the same one (relative 1e-6);
  without damping (no wind: drag (28) linearises to zero at rest) they are
  the poles of the response;
* ``natural``: the modes of the same linearisation (SLEPc, :mod:`.modal`) up
  to above the grid, and for each peak the nearest one.

Computing writes nothing; :meth:`ResponseResult.write` writes summary.json
and response.png.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from mpi4py import MPI

from rawehelix.families import FAMILY_LABELS
from rawehelix.parameters import Parameters
from rawehelix.studies import forcing, limits, schemes
from rawehelix.studies.store import writers
from rawehelix.studies.scene import SceneError

#: the curves whose local maxima are peaks (ResponsePoint attributes)
CURVES = {"lateral_in_plane": "in_plane_m", "lateral_out_of_plane": "out_of_plane_m",
          "tension": "tension_amplitude_N"}
MERGE = 1e-6  # peaks of two curves closer than this (relative) are one
XTOL = 1e-9  # relative f1 tolerance of the peak refinement
UNDAMPED = 1e-6  # a mode with decay / omega below this has no damping to speak of


@dataclass
class ResponseResult:
    """The linear frequency response in SI (the same on every rank)."""

    params: Parameters
    f1_Hz: np.ndarray
    lateral_mid_amplitude_m: np.ndarray  # semi-major axis of the midpoint's lateral ellipse
    lateral_mid_in_plane_m: np.ndarray
    lateral_mid_out_of_plane_m: np.ndarray
    tension_amplitude_N: np.ndarray  # |dT(0)|
    peaks: list  # dicts: f1_Hz, seen_in, amplitudes, nearest mode
    natural: list  # dicts: family, frequency_Hz, decay_per_s
    summary: dict = field(default_factory=dict)
    rank: int = 0

    @property
    def peaks_Hz(self) -> list[float]:
        return [p["f1_Hz"] for p in self.peaks]

    def write(self, outdir) -> Path:
        """summary.json and response.png (rank 0 writes)."""
        return writers.summary_and_figure(outdir, self.rank, self.summary,
                                          lambda d: response_png(d / "response.png", self))


def check(params: Parameters, command: str = "response"):
    """Refuse a scene the response cannot run (SceneError)."""
    if not schemes.of(params).fe_assembled:
        raise SceneError(params.name, "discretisation.scheme",
                         f"'{command}' linearises the FE scheme (--scheme fe)")
    forcing.require(params, command)
    if params.discretisation.elements < 2:
        raise SceneError(params.name, "discretisation.elements",
                         f"must be >= 2 for '{command}': the midpoint must be an interior node")
    limits.check_bending_resolution(params, command)


def compute(params: Parameters, f1_Hz=None, comm=MPI.COMM_WORLD) -> ResponseResult:
    """The linear response at each f1 [Hz] (default: the scene's [sweep] list).

    Raises SceneError for a bad scene or frequency list, SolverError if a
    solve fails (an f1 exactly on an undamped natural frequency)."""
    from rawehelix.solvers.response import HarmonicResponse
    from rawehelix.studies.sweep import validate_frequencies

    start = time.perf_counter()
    check(params)
    frequencies = validate_frequencies(params.sweep.frequencies() if f1_Hz is None else f1_Hz)
    solver = HarmonicResponse.from_stationary(params, comm, scene=params.name)
    points = [solver.at(f) for f in frequencies]
    peaks = find_peaks(solver, points)
    natural = natural_modes(solver, max(frequencies))
    for p in peaks:
        near = min(natural, key=lambda m: abs(m["frequency_Hz"] - p["f1_Hz"]), default=None)
        p["nearest_mode"] = None if near is None else {
            **near, "relative_difference": p["f1_Hz"] / near["frequency_Hz"] - 1}
    disc, q = params.discretisation, solver.q
    result = ResponseResult(
        params, np.array(frequencies),
        *(np.array([getattr(p, k) for p in points]) for k in
          ("lateral_mid_amplitude_m", "in_plane_m", "out_of_plane_m", "tension_amplitude_N")),
        peaks=peaks, natural=natural, rank=comm.rank)
    result.summary = {
        "scene": params.name, "scheme": "fe", "elements": disc.elements, "degree": disc.degree,
        "dofs": solver.rod.dof_count(), "ranks": comm.size,
        "circle_radius_m": params.ends.circle_radius_m,
        "linearised_about": "the stationary state with the upper end at the centre of its "
                            "circle (R1 = 0), torque-free ends, at rest (K, C, M of "
                            "solvers.linearise); the rotor torque (69) and the controller "
                            "(40) are not in it",
        "model": params.describe_model(),
        "mean_tension_N": float(q.tension_N(solver.modal.mean_tension_value)),
        "s_mid_m": float(q.length_m(solver.s_mid)),
        "points": [p.entry() for p in points],
        "peaks_Hz": result.peaks_Hz, "peaks": peaks, "natural_frequencies": natural,
        "wall_s": time.perf_counter() - start}
    return result


def _refine(solver, attr: str, a: float, b: float) -> float:
    """The f1 in [a, b] that maximises the amplitude ``attr`` (bounded Brent on its log)."""
    from scipy.optimize import minimize_scalar

    def cost(f):
        return -math.log(max(getattr(solver.at(f), attr), 1e-300))

    found = minimize_scalar(cost, bounds=(a, b), method="bounded",
                            options={"xatol": XTOL * b, "maxiter": 200})
    return float(found.x)


def find_peaks(solver, points: list) -> list[dict]:
    """The refined interior local maxima of each curve of :data:`CURVES`, merged
    across curves and sorted by f1 (collective)."""
    found = []
    f = [p.f1_Hz for p in points]
    for curve, attr in CURVES.items():
        y = np.array([getattr(p, attr) for p in points])
        scale = float(np.max(y)) if len(y) else 0.0
        for k in range(1, len(points) - 1):
            # an interior grid maximum, above round-off (a curve that the forcing does not reach)
            if y[k] > y[k - 1] and y[k] >= y[k + 1] and y[k] > 1e-9 * scale:
                found.append((_refine(solver, attr, f[k - 1], f[k + 1]), curve))
    found.sort()
    peaks = []
    for f1, curve in found:
        if peaks and abs(f1 - peaks[-1]["f1_Hz"]) <= MERGE * f1:
            peaks[-1]["seen_in"].append(curve)
            continue
        p = solver.at(f1)
        peaks.append({"f1_Hz": f1, "seen_in": [curve],
                      "lateral_mid_amplitude_m": p.lateral_mid_amplitude_m,
                      "tension_amplitude_N": p.tension_amplitude_N})
    return peaks


def natural_modes(solver, f_max_Hz: float, margin: float = 1.25) -> list[dict]:
    """The vibration modes of the linearisation up to ``margin`` f_max [Hz]:
    family, frequency_Hz, decay_per_s (collective; SLEPc, as ``rawehelix modes``)."""
    from rawehelix.solvers import analytic

    modal, q = solver.modal, solver.q
    omega = margin * 2 * math.pi * f_max_Hz * q.t_scale
    T = max(modal.mean_tension_value, 0.0)
    nev = max(modal.default_nev(), 2 * analytic.count_below(q, T, omega, modal.twist) + 8)
    modes = modal.solve(nev=nev, keep_vectors=False)
    out = []
    for m in modes:
        f = abs(m.eigenvalue.imag) / (2 * math.pi * q.t_scale)
        if m.family != "rigid" and f <= margin * f_max_Hz:
            out.append({"family": m.family, "frequency_Hz": f,
                        "decay_per_s": -m.eigenvalue.real / q.t_scale})
    return sorted(out, key=lambda m: m["frequency_Hz"])


def response_png(path: Path, result: ResponseResult):
    """Two panels against f1: the midpoint's lateral amplitudes and the tension
    amplitude at s = 0 (log scales), natural frequencies as vertical lines."""
    plt = writers._pyplot()
    f = result.f1_Hz
    fig, (ax0, ax1) = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
    ax0.semilogy(f, result.lateral_mid_amplitude_m, "-", color="k", lw=1.5,
                 label="semi-major axis of the lateral ellipse")
    ax0.semilogy(f, result.lateral_mid_in_plane_m, "--", color="C0", lw=1, label="in plane")
    ax0.semilogy(f, result.lateral_mid_out_of_plane_m, ":", color="C1", lw=1.5,
                 label="out of plane (y)")
    ax0.set_ylabel("midpoint amplitude [m]")
    ax1.semilogy(f, result.tension_amplitude_N, "-", color="C3")
    ax1.set_ylabel("tension amplitude at s = 0 [N]")
    ax1.set_xlabel("forcing frequency f1 [Hz]")
    colours = {"longitudinal": "C2", "lateral_in_plane": "C0", "lateral_out_of_plane": "C1",
               "torsional": "C4"}
    seen = set()
    for m in result.natural:
        if m["frequency_Hz"] > f.max():
            continue
        label = None if m["family"] in seen else f"mode: {FAMILY_LABELS[m['family']]}"
        seen.add(m["family"])
        for ax in (ax0, ax1):
            ax.axvline(m["frequency_Hz"], color=colours.get(m["family"], "0.5"), lw=0.8,
                       alpha=0.6, label=label if ax is ax0 else None)
    for ax in (ax0, ax1):
        ax.grid(True, which="both", alpha=0.3)
    ax0.legend(loc="upper left", fontsize=8)
    s = result.summary
    return writers._finish(fig, path, f"{result.params.title or result.params.name}: linear "
                                      f"response, R1 = {s['circle_radius_m']} m, FE N = "
                                      f"{s['elements']}, p = {s['degree']}", dpi=120)


def report(result: ResponseResult) -> str:
    """What ``rawehelix response`` prints: the grid, the peaks and the modes next to them."""
    s = result.summary
    f = result.f1_Hz
    lines = [f"{s['scene']}: linear response at {len(f)} f1 from {f.min():g} to {f.max():g} Hz, "
             f"R1 = {s['circle_radius_m']} m, FE N = {s['elements']}, p = {s['degree']} "
             f"({s['dofs']} dofs), {s['wall_s']:.2f} s",
             f"{'peak f1 (Hz)':>14}  {'lateral (m)':>11}  {'tension (N)':>11}  "
             f"{'nearest mode':<15} {'f (Hz)':>10}  {'rel. diff':>9}  seen in"]
    for p in result.peaks:
        m = p["nearest_mode"] or {}
        lines.append(f"{p['f1_Hz']:14.6f}  {p['lateral_mid_amplitude_m']:11.4g}  "
                     f"{p['tension_amplitude_N']:11.4g}  "
                     f"{FAMILY_LABELS.get(m.get('family'), '-'):<15} "
                     f"{m.get('frequency_Hz', math.nan):10.6f}  "
                     f"{m.get('relative_difference', math.nan):9.1e}  {', '.join(p['seen_in'])}")
    if not result.peaks:
        lines.append("  (no interior local maximum on this grid)")
    undamped = [p for p in result.peaks if p["nearest_mode"] and p["nearest_mode"]["decay_per_s"]
                < UNDAMPED * 2 * math.pi * p["nearest_mode"]["frequency_Hz"]]
    if undamped:
        lines.append("  undamped modes (no wind: the drag (28) vanishes at rest): those peaks are "
                     "poles, their heights only say how close the search came")
    return "\n".join(lines)
