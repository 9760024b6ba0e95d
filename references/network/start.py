"""Where a network run starts (``rawehelix simulate --scheme network``): at rest in the
stationary state, or with a rotor at its operating point (machine.py)."""

from __future__ import annotations

import numpy as np

from rawehelix.references.network import dynamics as dy
from rawehelix.references.network import machine
from rawehelix.references.network.network import Network, NetworkError
from rawehelix.references.network.stationary import solve


def start(params):
    """(network, its stationary result, drive, motion) where a run of the scene starts:
    at rest in the stationary state (the ramp starts at 0); with a rotor, as the FE run
    (docs/explanation/machine_dynamics.md), at the rigid shaft's operating point
    Omega_0 (machine.operating_point; a generator with a release speed: at rest), the
    stationary state under Q(Omega_0) at the top, every ring spinning at Omega_0 about
    its own axis: the helix's relative equilibrium (a symmetric top spinning about its
    axis needs no torque)."""
    drive = dy.Drive.from_parameters(params)
    rotor, generator, ctl = drive.rotor, drive.generator, drive.controller
    omega = 0.0
    if rotor is not None and (generator is None or generator.release_rad_s is None):
        holds = ctl.target_rad_s if generator is None and ctl is not None and ctl.k1_Nm > 0 else None
        omega = machine.operating_point(rotor, generator, 0.0, holds)
    torque = (rotor.torque(omega, 0.0)[0] + (drive.top_torque(0.0) if drive.top_torque else 0.0)
              if omega > 0 else 0.0)
    net = Network.from_parameters(params, end_torque_Nm=torque)
    try:
        st = solve(net)
    except NetworkError as err:
        if omega == 0:
            raise
        raise NetworkError(
            f"the network cannot hold the rotor's torque {torque:.4g} N m at its operating "
            f"point ({omega * 30 / np.pi:.4g} rpm): its twisted helix buckles or its bays "
            "collapse; run a lower wind.speed_m_s or give more rings (section.rings)") from err
    mo = dy.at_rest(st.state, 0.0, drive)
    if omega > 0:
        polar = np.array([r.polar_kgm2 for r in net.rings])[1:-1]
        mo.L[1:-1] = (polar * omega)[:, None] * st.state.R[1:-1, :, 2]
        mo.top_spin = mo.ground_spin = omega
    return net, st, drive, mo


def operating_state(params, iterations: int = 20) -> dict:
    """The network's relative equilibrium at the scene's wind, as ``rawehelix operate``
    defines it (docs/explanation/operate.md): V_n = V_hub |t . i_E| with t the top's
    tangent in the solved state (here the last bay's chord), Omega the stable root of
    Q(Omega, V_n) = tau(Omega) (machine.operating_point), and the stationary network
    under Q(Omega) at the top; a fixed point on a = V_n / V_hub (from the chord's),
    to 1e-12.  SI: rpm, torque, power, both ends' axial forces, a."""
    drive = dy.Drive.from_parameters(params)
    rotor, generator, ctl = drive.rotor, drive.generator, drive.controller
    holds = ctl.target_rad_s if generator is None and ctl is not None and ctl.k1_Nm > 0 else None
    a, state = rotor.normal, None
    for _ in range(iterations):
        here = machine.RotorEnd(rotor.law, rotor.density_kg_m3, a, rotor.hub_m_s)
        omega = machine.operating_point(here, generator, 0.0, holds)
        Q = here.torque(omega, 0.0)[0]
        r = solve(Network.from_parameters(params, end_torque_Nm=Q), state=state)
        state = r.state
        t = r.state.X[-1] - r.state.X[-2]
        new = float(rotor.law.normal_speed(1.0, t / np.linalg.norm(t)))
        if abs(new - a) <= 1e-12:
            break
        a = new
    T = r.tension_N()
    return {"rotor_rpm": omega * 30 / np.pi, "torque_Nm": Q, "power_W": Q * omega,
            "tension_ground_N": float(T[0]), "tension_top_N": float(T[-1]), "axis_factor": a,
            "hub_wind_m_s": rotor.hub_m_s(0.0), "smallest_tether_force_N": r.smallest_tether_force[0],
            "sag_m": r.sag_m(), "twist_deg": float(np.degrees(r.state.theta))}
