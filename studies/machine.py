"""simulate with the machine (issue 43): the rotor at the top, the generator at the
ground, at a constant wind (solvers/end_torques.py).  A run with a rotor starts at the
rigid-shaft operating point (operation/rigid_shaft.py: the stable root of Q = tau at
the hub's mean wind at t = 0 (:func:`start_wind`: a turbulent record's fluctuation
left out), or the paper's law's target spin), on the stationary state twisted by
its torque and spinning uniformly: the relative equilibrium the run then keeps, or
settles back to after a gust.  Its time series gains :data:`COLUMNS`, its summary the
``machine`` (the start) and the ``energy`` block (solvers/energy_account.py)."""

from __future__ import annotations

import numpy as np

from rawehelix.operation import generator
from rawehelix.operation.rigid_shaft import operating_points
from rawehelix.operation.rotor import RPM, OutOfTable  # RPM: rad/s per rpm
from rawehelix.solvers.end_torques import Machine, WindBelowRotor, machine_of
from rawehelix.solvers.snes import SolverError
from rawehelix.studies.scene import SceneError

#: the machine's columns of time_series.csv, after the helix's
COLUMNS = ("rotor_rpm", "power_W", "thrust_N", "wind_hub_m_s")
#: a start-up has reached the operating point once the rotor stays within this fraction
#: of the point's speed to the end of the run [-]
REACHED = 0.01


def of(params) -> Machine:
    """The scene's machine (off: the paper's ends)."""
    return machine_of(params)


def start_wind(machine: Machine) -> Machine:
    """The machine in the wind a run starts in: the history's at t = 0 without the
    turbulence's fluctuation (V_ref f(z_hub) + G(0), operation/wind_series.py), so a
    turbulent run starts at its mean wind's operating point, the one ``rawehelix operate``
    gives at that wind, whatever gust of the record happens to blow at t = 0.  A steady,
    step, gust or file wind is unchanged (no fluctuation)."""
    if machine.history is None:
        return machine
    return machine.in_wind(machine.history.mean_hub(0.0))


def start_point(params, machine: Machine):
    """The rigid-shaft operating point the run starts at, in :func:`start_wind`, against
    the scene's ground law (the paper's Eq. 40 holds its target spin): the stable one of
    the fastest rotor; SceneError (exit 2) when the wind has none, naming the keys to
    change."""
    machine = start_wind(machine)
    ground = generator.from_params(params)  # every law, the paper's too (None: no torque)
    points = [p for p in operating_points(machine.rotor, ground, machine.wind_n_m_s,
                                          machine.air_density_kg_m3) if p.stable]
    if not points:
        raise SceneError(params.name, "wind.speed_m_s",
                         f"{machine.wind_hub_m_s:g} m/s (V_n = {machine.wind_n_m_s:.4g} m/s along "
                         f"the rotor's axis) gives the rotor no stable operating point against the "
                         f"generator inside its table (tsr {machine.rotor.tsr_range[0]:g} to "
                         f"{machine.rotor.tsr_range[1]:g}): change wind.speed_m_s or the "
                         f"generator's law (rawehelix operate SCENE --wind LO:HI:STEP lists them)")
    return max(points, key=lambda p: p.omega_rad_s)


def solver(params, machine: Machine, comm, options):
    """(DynamicsSolver, the summary's ``machine`` block): started at the operating
    point with a rotor; from the stationary state at rest without one."""
    from rawehelix.solvers.dynamics import DynamicsSolver
    rest = machine.rotor is None or starts_from_rest(params, machine)
    if rest and params.lifter.active:  # the lifted top starts at the operating point only
        raise SceneError(params.name, "lifter.top",
                         "'lifted' in simulate starts from the lifted state at the rotor's "
                         "operating point: give [rotor] a table and no generator.release_rpm, "
                         "or set lifter.top = 'fixed' (--set 'lifter.top=\"fixed\"')")
    if rest:
        return DynamicsSolver.from_stationary(params, comm, options=options, scene=params.name), \
            ({"start": "rest", "wind_hub_m_s": machine.wind_hub_m_s} if machine.rotor else {})
    point = start_point(params, machine)
    q = params.normalised()
    sv = DynamicsSolver.spinning(params, machine, point.omega_rad_s * q.t_scale,
                                 point.rotor_torque_Nm / q.torque_scale, comm, options,
                                 scene=params.name)
    start = start_wind(machine)
    return sv, {"start_rotor_rpm": point.rotor_rpm, "start_torque_Nm": point.rotor_torque_Nm,
                "start_power_W": point.power_W, "wind_hub_m_s": start.wind_hub_m_s,
                "wind_n_m_s": start.wind_n_m_s, "tsr": point.tsr}


def starts_from_rest(params, machine: Machine) -> bool:
    """A start-up (generator.release_rpm given): from the untwisted helix at rest.  The
    rotor at rest needs Q(0) finite, its table from tip-speed ratio 0 with Cp = 0 there
    (Q = 1/2 rho pi R^3 V_n^2 Cp / lambda); SceneError (exit 2) otherwise."""
    if machine.generator is None or machine.generator.release_rad_s is None:
        return False
    rotor = machine.rotor
    if rotor is not None and not (rotor.table_tsr[0] == 0 and rotor.table_cp[0] == 0):
        raise SceneError(params.name, "rotor.table",
                         f"starts at tsr {rotor.table_tsr[0]:g} with cp {rotor.table_cp[0]:g}: a "
                         f"start-up from rest (generator.release_rpm) needs its first row at "
                         f"tsr 0 with cp 0 (the rotor's torque at rest is then 1/2 rho pi R^3 "
                         f"V^2 dCp/dtsr(0)); add that row or remove generator.release_rpm")
    return True


def startup(machine: Machine, release, rows) -> dict:
    """The summary's ``startup`` block: the release (solvers/release.py) and whether the
    rotor reached the operating point of the last output's wind (:data:`REACHED`): the
    first output time from which it stays there, else None.  ``rows`` the run's (its
    machine columns after the helix's 8)."""
    block = release.summary()
    block["operating_rpm"] = block["reached_at_s"] = None
    if not len(rows) or machine.rotor is None:
        return block
    now = at(machine, float(rows[-1, 0]))
    points = [p for p in operating_points(now.rotor, now.generator, now.wind_n_m_s,
                                          now.air_density_kg_m3) if p.stable]
    if not points:
        return block
    rpm = max(points, key=lambda p: p.omega_rad_s).rotor_rpm
    near = np.abs(rows[:, -len(COLUMNS)] / rpm - 1) < REACHED
    away = np.flatnonzero(~near)
    first = 0 if not len(away) else away[-1] + 1
    block.update(operating_rpm=float(rpm),
                 reached_at_s=float(rows[first, 0]) if first < len(rows) else None)
    return block


def startup_line(block: dict | None, simulated_s: float) -> str:
    """The start-up's answer: released when, and the operating point reached when or
    not by the run's end ('' without a start-up)."""
    if not block:
        return ""
    at = block["released_at_s"]
    released = (f"released at {block['release_rpm']:g} rpm at t = {at:.3f} s" if at is not None
                else f"not released (the ground never reached {block['release_rpm']:g} rpm)")
    point = block["operating_rpm"]
    if point is None:
        reached = "no stable operating point at the last wind"
    elif block["reached_at_s"] is not None:
        reached = (f"reached the operating point {point:.2f} rpm (within {REACHED:.0%}) at "
                   f"t = {block['reached_at_s']:.3f} s")
    else:
        reached = (f"did not reach the operating point {point:.2f} rpm by t = {simulated_s:.3f} s "
                   f"(a longer run: --until; the members' first limit below says what else "
                   f"stopped it)")
    return f"\n  start-up: generator {released}; {reached}"


def top_position(params, solver) -> list | None:
    """The lifted top's position r(L0) [m] (x, y, z down) in the solver's state, on every
    rank (collective); None with the top held at [ends]' position."""
    if not params.lifter.active:
        return None
    _, r = solver.rod.gather_centre_line()
    top = None if r is None else [float(x) for x in solver.q.length_m(r[-1])]
    return solver.comm.bcast(top, root=0)


def lifter_block(start_m, now_m) -> dict:
    """summary.json's ``lifter`` of a run: the top at the start and at the end [m] and
    the distance between them."""
    return {"top": "lifted", "start_top_position_m": start_m, "top_position_m": now_m,
            "moved_m": float(np.linalg.norm(np.subtract(now_m, start_m)))}


def lifter_line(block: dict | None) -> str:
    """The report's line of a lifted top ('' with the top fixed)."""
    if not block:
        return ""
    x, y, z = block["top_position_m"]
    return (f"\n  lifted top at ({x:.4f}, {y:.4f}, {z:.4f}) m (z down), "
            f"{block['moved_m']:.4g} m from its start")


def row(machine: Machine, t_s: float, spin0_rpm: float, spin1_rpm: float,
        ground_torque_Nm: float) -> tuple:
    """The :data:`COLUMNS` at an output time (SI), in the wind of that time."""
    now = at(machine, t_s)
    return (spin1_rpm, ground_torque_Nm * spin0_rpm * RPM,
            thrust(now, spin1_rpm * RPM, t_s), now.wind_hub_m_s)


def stopped(why, t_s: float) -> SolverError:
    """The run's stop at ``t_s`` [s] for ``why`` (exit 1, the series kept)."""
    return SolverError(f"{why}; the run stopped at t = {t_s:.4g} s (simulated), its series "
                       f"kept up to there")


def at(machine: Machine, t_s: float) -> Machine:
    """``machine.at(t_s)``; the wind along the rotor's axis at or below zero stops the
    run with its time (a rotor's table knows no such wind: never a silent number)."""
    try:
        return machine.at(t_s)
    except WindBelowRotor as err:
        raise stopped(err, t_s) from None


def thrust(machine: Machine, omega_rad_s: float, t_s: float) -> float:
    """The rotor's thrust [N] at Omega; its tip-speed ratio out of the table (never a
    silent extrapolation) is SolverError naming the wind and rotor speeds (exit 1)."""
    try:
        return machine.thrust_N(omega_rad_s)
    except OutOfTable as err:
        raise stopped(err, t_s) from None


def check_step(machine: Machine, solver) -> None:
    """After each step: the rotor's tip-speed ratio inside its table (:func:`thrust`)."""
    if machine.rotor is not None:
        q = solver.q
        t_s = float(q.time_s(solver.t))
        thrust(at(machine, t_s), float(solver.probes.value("spin1")) / q.t_scale, t_s)


__all__ = ["COLUMNS", "check_step", "lifter_block", "lifter_line", "of", "row", "solver",
           "start_point", "start_wind", "starts_from_rest", "startup", "startup_line", "thrust", "top_position"]
