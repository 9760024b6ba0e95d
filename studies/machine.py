"""simulate with the machine (issue 43): the rotor at the top, the generator at the
ground, at a constant wind (solvers/end_torques.py).  A run with a rotor starts at the
rigid-shaft operating point (operation/rigid_shaft.py: the stable root of Q = tau at
the hub's wind, or the paper's law's target spin), on the stationary state twisted by
its torque and spinning uniformly: the relative equilibrium the run then keeps, or
settles back to after a gust.  Its time series gains :data:`COLUMNS`, its summary the
``machine`` (the start) and the ``energy`` block (solvers/energy_account.py)."""

from __future__ import annotations

from rawehelix.operation import generator
from rawehelix.operation.rigid_shaft import operating_points
from rawehelix.operation.rotor import RPM, OutOfTable  # RPM: rad/s per rpm
from rawehelix.solvers.end_torques import Machine, machine_of
from rawehelix.solvers.snes import SolverError
from rawehelix.studies.scene import SceneError

#: the machine's columns of time_series.csv, after the helix's
COLUMNS = ("rotor_rpm", "power_W", "thrust_N", "wind_hub_m_s")


def of(params) -> Machine:
    """The scene's machine (off: the paper's ends)."""
    return machine_of(params)


def start_point(params, machine: Machine):
    """The rigid-shaft operating point the run starts at, against the scene's ground law
    (the paper's Eq. 40 holds its target spin): the stable one of the fastest rotor;
    SceneError (exit 2) when the wind has none, naming the keys to change."""
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
    if machine.rotor is None:
        return DynamicsSolver.from_stationary(params, comm, options=options, scene=params.name), {}
    point = start_point(params, machine)
    q = params.normalised()
    sv = DynamicsSolver.spinning(params, machine, point.omega_rad_s * q.t_scale,
                                 point.rotor_torque_Nm / q.torque_scale, comm, options,
                                 scene=params.name)
    return sv, {"start_rotor_rpm": point.rotor_rpm, "start_torque_Nm": point.rotor_torque_Nm,
                "start_power_W": point.power_W, "wind_hub_m_s": machine.wind_hub_m_s,
                "wind_n_m_s": machine.wind_n_m_s, "tsr": point.tsr}


def row(machine: Machine, t_s: float, spin0_rpm: float, spin1_rpm: float,
        ground_torque_Nm: float) -> tuple:
    """The :data:`COLUMNS` at an output time (SI), in the wind of that time."""
    now = machine.at(t_s)
    return (spin1_rpm, ground_torque_Nm * spin0_rpm * RPM,
            thrust(now, spin1_rpm * RPM, t_s), now.wind_hub_m_s)


def thrust(machine: Machine, omega_rad_s: float, t_s: float) -> float:
    """The rotor's thrust [N] at Omega; its tip-speed ratio out of the table (never a
    silent extrapolation) is SolverError naming the wind and rotor speeds (exit 1)."""
    try:
        return machine.thrust_N(omega_rad_s)
    except OutOfTable as err:
        raise SolverError(f"{err}; the run stopped at t = {t_s:.4g} s (simulated), its series "
                          f"kept up to there") from None


def check_step(machine: Machine, solver) -> None:
    """After each step: the rotor's tip-speed ratio inside its table (:func:`thrust`)."""
    if machine.rotor is not None:
        q = solver.q
        t_s = float(q.time_s(solver.t))
        thrust(machine.at(t_s), float(solver.probes.value("spin1")) / q.t_scale, t_s)


__all__ = ["COLUMNS", "check_step", "of", "row", "solver", "start_point", "thrust"]
