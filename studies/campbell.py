"""`rawehelix campbell SCENE --wind LO:HI:STEP`: the Campbell diagram of the helix about
its operating points.

1. The operating points are ``operate``'s (studies/operate.py): at each wind speed, every
   relative equilibrium of the rotor and the generator on every branch of the torque
   balance, up to the helix's first limit (the curve stops there, as the power curve);
2. at each, the helix's shape is the stationary state under its end torque (solved again
   on a rod the modal solver shares: the same scene, torque and so the same state), and
   the modes about it (solvers/spin_modes.py): the rod's F linearised at U = that state,
   V = (0, Omega) in the twist, A = 0, with the rotor's spin inertia and aerodynamic
   damping -dQ/dOmega at the top's twist, the generator's dtau/dOmega (or Eq. 40's k1, k2)
   at the ground's; the lowest ``per_family`` modes of each family, their frequencies
   [Hz] and damping ratios, and the point's stability (max Re lambda);
3. along each branch, every crossing of the 1P, 2P and BP lines (B = rotor.blades) with
   a mode followed by its frequency (studies/campbell_lines.py).

The top end must be fixed (Eqs. 35-36): a lifted or circling top is refused.  Computing
writes nothing; :meth:`CampbellResult.write` writes summary.json and campbell.png.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

from mpi4py import MPI

from rawehelix.errors import SceneError
from rawehelix.parameters import Parameters, end_components
from rawehelix.solvers.operating_tops import FixedTop
from rawehelix.solvers.spin_modes import (EndLoads, RelativeEquilibrium, SpinModalSolver,
                                          damping_ratio, frequency_Hz)
from rawehelix.studies import campbell_lines, operate

PER_FAMILY = 2  # modes of each family followed across the operating points


def read_envelope(folder) -> dict:
    """The summary of an ``envelope`` run's output folder; SceneError on --envelope."""
    import json
    path = Path(folder) / "summary.json"
    try:
        summary = json.loads(path.read_text())
    except (OSError, ValueError):
        summary = None
    if not isinstance(summary, dict) or not isinstance(summary.get("ticks"), list):
        raise SceneError("--envelope", str(folder), "must be the output folder of a finished "
                         "'rawehelix envelope' run (its summary.json with 'ticks')")
    return summary


@dataclass
class CampbellPoint:
    """One operating point and its modes, in SI."""

    wind_m_s: float  # at the wind's reference height
    branch: int  # the k-th operating point at this wind, by rotor speed
    rotor_rpm: float
    wind_normal_m_s: float  # V_n along the rotor's axis
    torque_Nm: float  # the twist moment, constant along s: Q = tau
    loads: EndLoads
    stable: bool
    max_real_part_per_s: float
    modes: list = field(default_factory=list)  # dicts: family, index, frequency_Hz, ...

    def entry(self) -> dict:
        return {"wind_m_s": self.wind_m_s, "branch": self.branch, "rotor_rpm": self.rotor_rpm,
                "wind_normal_m_s": self.wind_normal_m_s, "torque_Nm": self.torque_Nm,
                "rotor_dtorque_domega_Nms": self.loads.rotor_dtorque_domega_Nms,
                "generator_dtorque_domega_Nms": self.loads.generator_dtorque_domega_Nms,
                "stable": self.stable, "max_real_part_per_s": self.max_real_part_per_s,
                "modes": self.modes}


@dataclass
class CampbellResult:
    """The Campbell diagram: ``points`` (:class:`CampbellPoint`: each operating point's
    modes and stability), ``crossings`` (dicts: family, mode, branch, line,
    frequency_Hz, rotor_rpm, wind_m_s), ``summary`` (what summary.json holds) and
    ``write(outdir)`` (summary.json, campbell.png)."""

    scene: str
    title: str
    blades: int
    points: list
    crossings: list
    elements: int
    wall_s: float
    envelope: dict | None = None  # an envelope summary: the forced helix's slack band
    envelope_value: float | None = None  # the scene's value of the envelope's key
    stopped: str = ""  # why the operating points stop (operate: the first limit, ...)
    first_limit: dict | None = None  # operate's first limit of the helix, or None

    @property
    def summary(self) -> dict:
        bands = (campbell_lines.slack_bands_Hz(self.envelope, self.envelope_value)
                 if self.envelope else [])
        crossings = [{**c, "in_slack_band": any(lo <= c["frequency_Hz"] <= hi
                                                for lo, hi in bands)} if self.envelope else c
                     for c in self.crossings]
        return {"scene": self.scene, "elements": self.elements, "blades": self.blades,
                "lines": [campbell_lines.line_name(n) for n in campbell_lines.orders(self.blades)],
                "points": [p.entry() for p in self.points],
                "tracks": [{"branch": b, "family": f, "points": [list(x) for x in sorted(t)]}
                           for (b, f, _), t in tracks(self.points).items()],
                "crossings": crossings, "slack_bands_Hz": bands,
                "slack_bands_of": ({"key": self.envelope.get("key"), "value": self.envelope_value}
                                   if self.envelope else None),
                "stopped": self.stopped,
                "first_limit": self.first_limit, "wall_s": self.wall_s}

    def write(self, outdir) -> Path:
        from rawehelix.studies.present.campbell_figure import campbell_png
        from rawehelix.studies.store import writers
        outdir = Path(outdir)
        outdir.mkdir(parents=True, exist_ok=True)
        summary = self.summary
        writers.write_json(outdir / "summary.json", summary)
        campbell_png(outdir / "campbell.png", summary, self.title)
        return outdir


def mode_entries(solver: SpinModalSolver, modes, per_family: int) -> list[dict]:
    """The lowest ``per_family`` oscillating modes of each family, by frequency."""
    out, seen = [], {}
    for m in sorted(modes, key=lambda m: abs(m.eigenvalue.imag)):
        if m.family not in solver.families or m.eigenvalue.imag == 0:
            continue
        k = seen.get(m.family, 0)
        if k >= per_family:
            continue
        seen[m.family] = k + 1
        lam = m.eigenvalue / solver.q.t_scale
        out.append({"family": m.family, "index": k, "frequency_Hz": frequency_Hz(m, solver.q),
                    "damping_ratio": damping_ratio(m),
                    "eigenvalue_per_s": [lam.real, lam.imag]})
    return out


class PointSolvers:
    """One stationary and one modal solver on one rod for a run's operating points
    (solvers/operating_tops.py's FixedTop, as operate's): the scene at another wind speed
    differs only in the helix's drag, a constant of the forms (RodDiscretisation.set_wind),
    so the forms are built once (they were 85 % of a point's cost, measured at N = 8); a
    scene that changes more gets new solvers."""

    def __init__(self, comm, scene: str, per_family: int = PER_FAMILY):
        self.scene, self.per_family = scene, per_family
        self.top = FixedTop(comm)

    @property
    def stationary(self):
        return self.top.stationary

    def modes(self, params: Parameters, omega_rad_s: float, torque_Nm: float, loads: EndLoads):
        """(solver, modes) about the relative equilibrium of spin ``omega_rad_s`` [rad/s]
        under the end torque ``torque_Nm`` [N m] (both ends, Eqs. 38-39; the spin drag's
        loss along s, if any) with the end ``loads``."""
        state = self.top.state(params, omega_rad_s, torque_Nm, thrust_N=0.0)
        modal = self.top.modal
        modal.linearise_at(RelativeEquilibrium(state.result.state, omega_rad_s, loads))
        return modal, modal.solve(per_family=self.per_family, keep_vectors=False,
                                  require_families=False)


def scene_value(params: Parameters, envelope: dict | None):
    """The scene's value of the envelope's key (``helix.EI_Nm2``), or None."""
    if not envelope or "." not in str(envelope.get("key", "")):
        return None
    section, name = envelope["key"].split(".", 1)
    try:
        return float(getattr(getattr(params, section), name))
    except (AttributeError, TypeError, ValueError):
        return None


def refuse_moving_top(params: Parameters):
    """The linearisation holds both ends' positions (Eqs. 35-36): a top moved by a
    position or force component (the circle, the lifter) is refused, naming it."""
    moving = [c for c in end_components.active(params) if c.end == "top" and c.load != "torque"]
    if moving:
        c = moving[0]
        raise SceneError(params.name, c.KEY, f"'campbell' linearises about a fixed top end "
                         f"(Eqs. 35-36), and the scene's top is moved by its {c.name} "
                         f"({c.equation}): switch it off in the scene ({c.off})")


def compute(params: Parameters, winds, comm=MPI.COMM_SELF, per_family: int = PER_FAMILY,
            envelope: dict | None = None, progress=None) -> CampbellResult:
    """The Campbell diagram over ``winds`` [m/s] (module docstring): ``operate``'s
    operating points, each linearised."""
    start = time.perf_counter()
    refuse_moving_top(params)
    winds = operate.check_winds(winds)
    planned = operate.plan(params, winds)  # refuses a scene without a rotor, a wind off its table
    drive = planned.drive
    operating = operate.compute(params, winds, comm=comm, planned=planned)
    points, solvers = [], PointSolvers(comm, params.name, per_family)
    for op, entry in zip(operating.points, operating.summary["points"]):
        p = operate.at_wind(params, op.wind_m_s)
        loads = EndLoads.of_laws(drive.rotor, drive.generator, op.omega_rad_s, op.v_n_m_s,
                                 drive.rho_kg_m3, p.controller)
        solver, modes = solvers.modes(p, op.omega_rad_s, op.torque_top_Nm, loads)
        points.append(CampbellPoint(
            wind_m_s=op.wind_m_s, branch=entry["branch"], rotor_rpm=entry["rotor_rpm"],
            wind_normal_m_s=op.v_n_m_s, torque_Nm=op.torque_top_Nm, loads=loads,
            stable=solver.stable(modes), max_real_part_per_s=solver.max_real_part(modes),
            modes=mode_entries(solver, modes, per_family)))
        if progress is not None:
            progress(points[-1])
    return CampbellResult(scene=params.name, title=params.title or params.name,
                          blades=drive.rotor.blades, points=points,
                          crossings=campbell_lines.crossings(tracks(points), drive.rotor.blades),
                          elements=params.discretisation.elements,
                          wall_s=time.perf_counter() - start, envelope=envelope,
                          envelope_value=scene_value(params, envelope),
                          stopped=operating.summary["stopped"],
                          first_limit=operating.summary["first_limit"])


def tracks(points: list[CampbellPoint]) -> dict:
    """{(branch, family, track): [(rotor_rpm, frequency_Hz, wind_m_s, index,
    damping_ratio)]}: each mode followed along its branch by its frequency
    (campbell_lines.follow)."""
    by, zeta = {}, {}
    for p in points:
        for family in {m["family"] for m in p.modes}:
            mine = [m for m in p.modes if m["family"] == family]
            by.setdefault((p.branch, family), []).append(
                (p.rotor_rpm, p.wind_m_s, [m["frequency_Hz"] for m in mine]))
            zeta[p.branch, family, p.rotor_rpm] = [m["damping_ratio"] for m in mine]
    return {(branch, family, k): [(*x, zeta[branch, family, x[0]][x[3]]) for x in track]
            for (branch, family), pts in by.items()
            for k, track in enumerate(campbell_lines.follow(pts))}


def report(result: CampbellResult) -> str:
    """The table ``rawehelix campbell`` prints."""
    lines = [f"{result.title}: {len(result.points)} operating points, "
             f"{len(result.crossings)} crossings of the {', '.join(result.summary['lines'])} lines"]
    for p in result.points:
        lowest = {}
        for m in p.modes:
            lowest.setdefault(m["family"], m["frequency_Hz"])
        modes = ", ".join(f"{k} {v:.3g} Hz" for k, v in lowest.items())
        lines.append(f"  V = {p.wind_m_s:6.2f} m/s  branch {p.branch}  {p.rotor_rpm:8.2f} rpm  "
                     f"{'stable  ' if p.stable else 'UNSTABLE'}  max Re {p.max_real_part_per_s:+.3g}"
                     f" /s  {modes}")
    summary = result.summary
    for c in summary["crossings"]:
        lines.append(f"  crossing {c['line']:>3} x {c['family']} {c['mode']}: "
                     f"{c['frequency_Hz']:.4g} Hz at {c['rotor_rpm']:.2f} rpm, "
                     f"V = {c['wind_m_s']:.3g} m/s"
                     + ("  (in the forced helix's slack band)" if c.get("in_slack_band") else ""))
    if summary["slack_bands_Hz"]:
        lines.append("  the forced helix slackens at f1 in " + ", ".join(
            f"{lo:.3g}-{hi:.3g} Hz" for lo, hi in summary["slack_bands_Hz"]))
    lines.append(f"  stopped: {result.stopped}")
    return "\n".join(lines)
