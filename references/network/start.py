"""Where a network run starts (``rawehelix simulate --scheme network``): at rest in the
stationary state, or with a rotor at its operating point (machine.py)."""

from __future__ import annotations

import numpy as np

from rawehelix.references.network import dynamics as dy
from rawehelix.references.network import machine
from rawehelix.references.network.network import Network
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
    st = solve(net)
    mo = dy.at_rest(st.state, 0.0, drive)
    if omega > 0:
        polar = np.array([r.polar_kgm2 for r in net.rings])[1:-1]
        mo.L[1:-1] = (polar * omega)[:, None] * st.state.R[1:-1, :, 2]
        mo.top_spin = mo.ground_spin = omega
    return net, st, drive, mo
