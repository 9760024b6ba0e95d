"""`rawehelix operate`: the operating points from a wind speed to another, the power
curve up to the helix's first limit (issue 43, part 2).

1. The torque balance's branches (solvers/rigid_shaft_branch.py) are traced over the
   window of the wind along the rotor's axis V_n by the pseudo-arclength ``Branch``,
   through folds; each stretch between folds is a ``branch`` of summary.json, with the
   rigid torsional mode's stability (d(Q - tau_gen - L)/dOmega < 0).
2. At each wind speed of ``--wind`` (ascending), every branch that reaches it gives an
   operating point: the relative equilibrium on the FE rod (solvers/operating_point.py,
   at most 3 stationary solves), with its ``limits`` (studies/analysis/
   structure_limits.py) and its ``stable`` from the linearisation about it
   (solvers/spin_modes.py: the rotor's inertia, -dQ/dOmega, dtau/dOmega, Eq. 40's k1, k2;
   ``details[]`` keep the rigid shaft's verdict and max Re lambda).  The curve stops at the first wind speed where a point reaches
   a limit of the helix (slack, saturated moment, torsional collapse, breaking; a
   stationary solve that finds the helix slack is the slack limit), and says which;
   or where the rotor's table ends.

Computing writes nothing; :meth:`Operate.write` writes summary.json and power_curve.png.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from mpi4py import MPI

from rawehelix.errors import SceneError, SolverError
from rawehelix.operation.rotor import RPM  # rad/s per rpm
from rawehelix.parameters import Parameters
from rawehelix.solvers.operating_point import OperatingPointSolver
from rawehelix.solvers.stationary import SlackError
from rawehelix.solvers.rigid_shaft_branch import RigidShaftProblem, trace
from rawehelix.solvers.torque_balance import Drive, OutsideTable
from rawehelix.studies import schemes
from rawehelix.studies.analysis import structure_limits
from rawehelix.studies.store import writers

log = logging.getLogger("rawehelix")

#: the window of V_n traced, beyond the chord's share of --wind (the top tangent turns
#: from the chord by the sag's angle: a few degrees on the paper's helix)
WINDOW_MARGIN = 0.15
#: ... for a lifted top, whose end tangent turns from the lifter's pull with the thrust
LIFTED_WINDOW_MARGIN = 0.5
#: the most wind speeds a run takes (each a few stationary solves and a record)
MAX_WINDS = 2000
#: the keys of each point of summary.json (the issue's)
POINT_KEYS = ("wind_m_s", "rotor_rpm", "tsr", "power_W", "rotor_power_W", "torque_top_Nm",
              "torque_ground_Nm", "thrust_N", "tension_max_N", "tension_min_N", "twist_deg",
              "stable", "branch")


def parse_wind(text: str) -> list[float]:
    """``--wind LO:HI:STEP`` [m/s] -> the wind speeds, LO to HI inclusive; SceneError
    on --wind naming what is allowed."""
    try:
        lo, hi, step = (float(x) for x in text.split(":"))
    except ValueError:
        raise SceneError("--wind", text, "must be LO:HI:STEP in m/s, e.g. 4:16:0.5") from None
    if not (0 < lo <= hi and step > 0 and np.isfinite(lo + hi + step)):
        raise SceneError("--wind", text, "must be LO:HI:STEP with 0 < LO <= HI and STEP > 0 "
                         "(m/s)")
    count = float(np.floor((hi - lo) / step + 1e-9)) + 1
    if count > MAX_WINDS:
        raise SceneError("--wind", text, f"gives {count:.6g} wind speeds; at most {MAX_WINDS} "
                         "(a larger STEP)")
    return [float(lo + k * step) for k in range(int(count))]


def check_winds(winds) -> list[float]:
    """The API's ``wind_m_s``: finite, > 0, at most MAX_WINDS, ascending."""
    try:
        w = sorted(float(x) for x in np.atleast_1d(winds))
    except (TypeError, ValueError):
        w = []
    if not w or not all(np.isfinite(x) and x > 0 for x in w) or len(w) > MAX_WINDS:
        raise SceneError("wind_m_s", str(list(winds)),
                         f"must be 1 to {MAX_WINDS} finite wind speeds > 0 m/s")
    return w


@dataclass
class Operate:
    """The operating points in SI (on rank 0) and the run's ``summary``."""

    params: Parameters
    points: list  # the OperatingPoint of each entry of summary["points"]
    summary: dict = field(default_factory=dict)
    rank: int = 0

    def write(self, outdir) -> Path:
        """summary.json and power_curve.png into ``outdir`` (rank 0 writes)."""
        from rawehelix.studies.present import operate_figure
        outdir = Path(outdir)
        if self.rank != 0:
            return outdir
        outdir.mkdir(parents=True, exist_ok=True)
        operate_figure.power_curve_png(outdir / "power_curve.png", self.summary,
                                       self.params.title or self.params.name)
        writers.write_json(outdir / "summary.json", self.summary)
        return outdir


def fe_scheme(params: Parameters) -> None:
    """SceneError for a scheme without the FE stationary solve (the spline reference)."""
    if not schemes.of(params).fe_assembled:
        raise SceneError(params.name, "discretisation.scheme",
                         f"{params.discretisation.scheme!r}: 'operate' solves the FE rod's "
                         "relative equilibria; run with --scheme fe")


def elastic_twist(params: Parameters) -> None:
    """SceneError for a hysteretic torsion: its static twist under a torque depends on
    how the torque was applied, so a relative equilibrium has no one state."""
    hysteresis = params.model.torsion_hysteresis
    if hysteresis.active:
        raise SceneError(params.name, "torsion_hysteresis.rho",
                         f"{hysteresis.rho:g} < 1 (hysteretic torsion): the twist under the "
                         "rotor's torque depends on how the torque was applied, so 'operate' "
                         "has no one relative equilibrium to give; run with "
                         "--set torsion_hysteresis.rho=1")


def still_top(params: Parameters) -> None:
    """SceneError where the top end circles: a relative equilibrium needs the top still
    (Eq. 70's circle moves it).  A fixed or lifted top is solved
    (solvers/operating_tops.py)."""
    if params.ends.circle_radius_m > 0:
        raise SceneError(params.name, "ends.circle_radius_m",
                         f"{params.ends.circle_radius_m:g} > 0: the circle of Eq. (70) moves "
                         "the top end, so the helix has no relative equilibrium for 'operate': "
                         "run with --set ends.circle_radius_m=0")


def drive_of(params: Parameters) -> Drive:
    """The rotor's and the generator's laws of the scene (operation/) and the helix's
    spin-drag loss (``[spin_drag]``, parameters/spin_drag.py; None when off); SceneError
    where the scene has no rotor or generator."""
    from rawehelix.operation import generator, rotor, wind
    from rawehelix.parameters.spin_drag import loss_of
    r, g = rotor.from_params(params), generator.from_params(params)
    if r is None:
        raise SceneError(params.name, "rotor", "'operate' needs a [rotor] section (radius_m, "
                         "table or cp/ct/tsr, ...; see studies/scenes/example.toml)")
    if g is None:
        raise SceneError(params.name, "generator", "'operate' needs a [generator] section "
                         "(law = \"paper\", \"mppt\" or \"torque\")")
    return Drive(r, g, wind.air_density(params), loss=loss_of(params))


def at_wind(params: Parameters, V: float) -> Parameters:
    """The scene at the wind V [m/s] at the reference height: ``[wind]``'s speed where the
    scene has that section (with environment.wind_speed_m_s where it gives the same),
    else environment.wind_speed_m_s (the paper's uniform wind; the helix's drag, Eq. 14).
    The ends keep the scene's elongation (for ``ends.tension_N``, the one found at the
    scene's own wind): the helix is anchored once, whatever the wind does."""
    held = {"ends": {"elongation": params.ends.elongation}} if params.ends.resolved else {}
    if not params.wind.active:
        return params.replace(environment={"wind_speed_m_s": float(V)}, **held)
    changes = {"wind": {"speed_m_s": float(V)}, **held}
    if params.environment.wind_speed_m_s != 0:
        changes["environment"] = {"wind_speed_m_s": float(V)}
    return params.replace(**changes)


def hub_speed(params: Parameters):
    """V -> the rotor's wind [m/s] at the hub: the scene's profile (operation/wind.py) at
    the top end's height."""
    from rawehelix.operation import wind
    profile = wind.from_params(params)
    return lambda V: profile.at_reference(float(V)).hub_speed


class _Limits:
    """The limits of every point: the run's block over the whole curve (one tracker) and
    each point's own first limit."""

    def __init__(self, params):
        self.run = structure_limits.of_params(params)

    def __call__(self, params, solver):
        from rawehelix.solvers.probes import SectionProbe
        section = SectionProbe.of_rod(solver.rod).section()  # collective
        if section is None:
            return None
        q = params.normalised()
        own = structure_limits.of_params(params)
        structure_limits.add_normalised(own, q, section)
        structure_limits.add_normalised(self.run, q, section)
        return own.block()


@dataclass
class Plan:
    """What a run knows before any FE work: the laws, the traced branches of the torque
    balance (numpy only), the chord's axis factor a0 = V_n / V_hub and V -> V_hub."""

    drive: Drive
    traced: object  # solvers/rigid_shaft_branch.py::Traced
    a0: float
    hub: object  # V [m/s] -> V_hub [m/s]

    def uncovered(self, winds) -> list[float]:
        """The wind speeds without a root of the balance in the rotor's table (at the
        chord's axis factor)."""
        return [V for V in winds if not self.drive.roots(self.a0 * self.hub(V))]

    def span_m_s(self) -> str:
        """The wind speeds [m/s] the branches reach, in words."""
        scale = self.a0 * self.hub(1.0)  # V_hub is proportional to V (operation/wind.py)
        return ", ".join(f"{seg.v_n[0] / scale:.3g} to {seg.v_n[-1] / scale:.3g}"
                         for seg in self.traced.segments) or "none"


def plan(params: Parameters, winds, key: str = "wind_m_s", text: str | None = None) -> Plan:
    """The run's :class:`Plan`; SceneError on ``key`` (``text``: the value as given) where
    a wind speed has no operating point inside the rotor's table.  Numpy only."""
    from rawehelix.solvers.operating_point import chord_axis_factor
    fe_scheme(params)
    elastic_twist(params)
    still_top(params)
    drive = drive_of(params)
    if params.lifter.active:  # a lifter that cannot hold the helix up at rest
        from rawehelix.solvers import lifted
        lifted.check_holds(params, lifted.top_load(params))
    q = params.normalised()
    hub = hub_speed(params)
    a0 = chord_axis_factor(drive, params)
    # a lifted top's tangent turns with the thrust, by more than a sag's angle
    margin = LIFTED_WINDOW_MARGIN if params.lifter.active else WINDOW_MARGIN
    problem = RigidShaftProblem(drive, q.t_scale, q.torque_scale)
    traced = trace(problem, a0 * hub(winds[0]) * (1 - margin),
                   min(1.0, a0 * (1 + margin)) * hub(winds[-1]))
    out = Plan(drive, traced, a0, hub)
    missing = out.uncovered(winds)
    if missing:
        lo, hi = drive.rotor.tsr_range
        raise SceneError(key, text or f"{winds[0]:g} .. {winds[-1]:g} m/s",
                         f"no operating point of the rotor and generator inside the rotor's "
                         f"table (tip-speed ratios {lo:g} to {hi:g}) at {_listed(missing)} m/s; "
                         f"they have operating points from {out.span_m_s()} m/s: choose wind "
                         f"speeds there, or extend the rotor's table")
    return out


def _listed(values, most: int = 4) -> str:
    shown = ", ".join(f"{v:g}" for v in values[:most])
    return shown + (f" and {len(values) - most} more" if len(values) > most else "")


def compute(params: Parameters, winds, comm=MPI.COMM_WORLD, planned: Plan | None = None
            ) -> Operate:
    """The operating points at the wind speeds ``winds`` [m/s] (module docstring);
    ``planned``: the run's :func:`plan` if already made."""
    start = time.perf_counter()
    winds = check_winds(winds)
    p_ = planned or plan(params, winds)
    drive, traced, hub = p_.drive, p_.traced, p_.hub
    limits = _Limits(params)
    solver = OperatingPointSolver(lambda V: at_wind(params, V), drive, hub, comm,
                                  limits=limits)
    points, entries, details, stop, first = [], [], [], None, None
    solves = 0
    notes = list(traced.notes)
    for V in winds:
        reached = []
        a = solver.a if solver.a is not None else p_.a0
        for branch, root in traced.at(drive, a * hub(V)):  # every root at V, each once
            if branch >= len(traced.segments) and not any("not reached" in n for n in notes):
                notes.append(f"branch {branch} (from {V:g} m/s) was not reached by the "
                             "continuation: its points are the balance's roots at each wind")
            try:
                p = solver.solve(V, root)
            except OutsideTable:
                continue  # the branch leaves the table between a's guess and its value
            except SlackError as err:  # the whole helix slack: the slack limit, reached
                reached.append((branch, {"kind": "slack", "s_m": None, "t_s": None,
                                         "why": str(err)}))
                continue
            except SolverError as err:
                stop = (f"at {V:g} m/s the relative equilibrium on branch {branch} failed "
                        f"({err}); the points before it are kept: a run with more --elements, "
                        f"or --wind below {V:g}, avoids it")
                break
            solves += p.stationary_solves
            points.append(p)
            entries.append(_entry(p, branch))
            details.append(_detail(p, branch))
            if comm.rank == 0:  # every rank solves the point; one says so
                log.info("operate: %g m/s (branch %d): %.1f rpm, P %.1f W, T %.1f .. %.1f N, "
                         "%d solves", V, branch, p.omega_rad_s / RPM, p.power_W,
                         entries[-1]["tension_min_N"] or 0.0,
                         entries[-1]["tension_max_N"] or 0.0, p.stationary_solves)
            if p.limits and p.limits.get("first_limit"):
                reached.append((branch, p.limits["first_limit"]))
        if stop:
            break
        if reached:
            branch, hit = reached[0]
            first = {**hit, "wind_m_s": V, "branch": branch}
            where = "" if hit["s_m"] is None else f", s = {hit['s_m']:.3f} m"
            stop = (f"the helix reaches its first limit, {hit['kind']}, at {V:g} m/s "
                    f"(branch {branch}{where})")
            break
    if not points:
        raise SolverError(f"no operating point was solved at {_listed(winds)} m/s: {stop}")
    # V_n = a V_hub with a the solved points' mean axis factor, V_hub proportional to V
    scale = float(np.mean([p.v_n_m_s / p.hub_wind_m_s for p in points])) * hub(1.0)
    block = limits.run.block()
    block["first_limit"] = first
    summary = {
        "scene": params.name, "elements": params.discretisation.elements,
        "degree": params.discretisation.degree, "ranks": comm.size,
        "wind_m_s": winds, "rotor_axis": drive.rotor.axis,
        "points": entries, "details": details,
        "folds": [{"v_n_m_s": float(v), "wind_m_s": float(v / scale)} for v in traced.folds],
        "branches": [{"branch": s.index, "stable": s.stable,
                      "v_n_m_s": [float(s.v_n[0]), float(s.v_n[-1])]} for s in traced.segments],
        "limits": block, "first_limit": first,
        "stopped": stop or "the last wind speed of --wind",
        "notes": notes,
        "stationary_solves": {"total": solves, "max_per_point": max(
            p.stationary_solves for p in points)},
        "branch_points_traced": traced.points,
        "wall_s": time.perf_counter() - start,
    }
    return Operate(params, points, comm.bcast(summary if comm.rank == 0 else None, root=0),
                   rank=comm.rank)


def _entry(p, branch: int) -> dict:
    """A point of summary.json: exactly :data:`POINT_KEYS`."""
    T = p.tension_N
    return {"wind_m_s": p.wind_m_s, "rotor_rpm": p.omega_rad_s / RPM, "tsr": p.tsr,
            "power_W": p.power_W, "rotor_power_W": p.rotor_power_W,
            "torque_top_Nm": p.torque_top_Nm, "torque_ground_Nm": p.torque_ground_Nm,
            "thrust_N": p.thrust_N,
            "tension_max_N": None if T is None else float(T.max()),
            "tension_min_N": None if T is None else float(T.min()),
            "twist_deg": None if p.twist_rad is None else float(np.degrees(p.twist_rad)),
            "stable": p.stable, "branch": branch}


def _detail(p, branch: int) -> dict:
    """What a point has besides the issue's keys (the figure's smallest member force)."""
    lim = p.limits or {}
    fmin = (lim.get("min_member_force_N") or {}).get("value")
    return {"wind_m_s": p.wind_m_s, "branch": branch, "hub_wind_m_s": p.hub_wind_m_s,
            "v_n_m_s": p.v_n_m_s, "loss_Nm": p.loss_Nm, "slope_Nm_s": p.slope_Nm_s,
            "member_force_min_N": fmin, "first_limit": lim.get("first_limit"),
            "stationary_solves": p.stationary_solves, "axis_defect": p.axis_defect,
            "max_real_part_per_s": p.max_real_part_per_s,
            "rigid_shaft_stable": p.rigid_shaft_stable, "stability_from": p.stability_from,
            "top_m": None if p.top_m is None else [float(x) for x in p.top_m],
            "tension_ground_N": None if p.tension_N is None else float(
                p.tension_N[int(np.argmin(p.s_tension_m))]),
            "wall_s": p.wall_s}


def report(result: Operate) -> str:
    """The lines a user reads: the power curve up to the first limit, that limit and its
    wind speed, and why the curve stopped."""
    s = result.summary
    lines = [f"{s['scene']}: N = {s['elements']}, p = {s['degree']}: {len(s['points'])} "
             f"operating points, {s['stationary_solves']['total']} stationary solves "
             f"(at most {s['stationary_solves']['max_per_point']} a point), {s['wall_s']:.1f} s",
             "  wind [m/s]  branch  rotor [rpm]   tsr   power [W]  T min..max [N]  twist [deg]"]
    for e in s["points"]:
        lines.append(f"  {e['wind_m_s']:9.3g}  {e['branch']:6d}  {e['rotor_rpm']:11.2f}  "
                     f"{e['tsr']:5.2f}  {e['power_W']:9.1f}  {e['tension_min_N']:6.1f}..."
                     f"{e['tension_max_N']:<6.1f}  {e['twist_deg']:10.2f}"
                     + ("" if e["stable"] else "  unstable"))
    first = s["first_limit"]
    lines.append("  first limit: " + (f"{first['kind']} at {first['wind_m_s']:g} m/s (branch "
                                      f"{first['branch']}"
                                      + ("" if first["s_m"] is None else f", s = {first['s_m']:.3f} m")
                                      + ")" if first else "none in the wind speeds run"))
    lines.append(f"  stopped: {s['stopped']}")
    for note in s["notes"]:
        lines.append(f"  note: {note}")
    for fold in s["folds"]:
        lines.append(f"  fold at V = {fold['wind_m_s']:.4g} m/s (V_n = {fold['v_n_m_s']:.4g} m/s "
                     "along the rotor's axis): a branch turns back in the wind there")
    return "\n".join(lines)
