"""The rotor and the generator on the network (references/network/machine.py) against
what the network does not compute itself: the scene's own operating point (its header:
the MPPT gain and the wind put the rotor at 25 N m and 120 rpm), the relative
equilibrium a run starts in, and the balance of the helix's angular momentum about the
chord against the impulse of the rotor's and the generator's torques.  About 2 s."""

import numpy as np
import pytest

from rawehelix.operation import generator as generator_laws
from rawehelix.operation import rotor as rotor_laws
from rawehelix.parameters.normalised import RPM
from rawehelix.references.network import dynamics as dy
from rawehelix.references.network import machine
from rawehelix.references.network.start import start
from rawehelix.studies import scene

SECTION = {"law": "tensegrity", "torsion": "members", "self_stress_N": 632.6,
           "bar_EA_N": 18200.0, "rings": 5}


def rotor_scene(**changes):
    return scene.load("rotor_example").replace(model={"kinematics": "extensible", **changes},
                                               section=SECTION)


def test_the_operating_point_is_the_scenes_120_rpm_at_25_Nm():
    p = rotor_scene()
    ends = machine.ends_of(p)
    omega = machine.operating_point(ends["rotor"], ends["generator"])
    assert omega / RPM == pytest.approx(120.0, abs=1e-3)  # the header's V has 5 digits
    # the torque by the rotor's own law (operation/rotor.py) at V_n = V cos 45 deg
    law, v_n = rotor_laws.from_params(p), 6.6131 * np.cos(np.radians(45.0))
    assert ends["rotor"].torque(omega, 0.0)[0] == pytest.approx(
        float(law.torque(omega, v_n, 1.225)), rel=1e-9)
    assert ends["rotor"].torque(omega, 0.0)[0] == pytest.approx(
        float(generator_laws.from_params(p).torque(omega)), rel=1e-12)


def test_a_run_from_the_operating_point_stays_there():
    """Every ring spinning at Omega_0 on the state twisted by Q(Omega_0) is the helix's
    relative equilibrium: after 0.1 s every ring's spin is Omega_0 to 1e-9."""
    net, st, drive, mo = start(rotor_scene())
    omega = mo.top_spin
    integ = dy.Integrator(net, drive, dy.default_step(net, st.state))
    integ.advance(mo, 0.1, 0.1)
    assert integ.spin(mo) == pytest.approx(np.full(net.count, omega), rel=1e-9)
    assert integ.ground_torque_Nm(mo) == pytest.approx(drive.rotor.torque(omega, 0.1)[0], rel=1e-9)


def test_the_angular_momentum_about_the_chord_is_the_torques_impulse():
    """Weightless and windless, started 3 % fast: H(t) - H(0) = the integral of
    Q(Omega_top) - tau(Omega_ground) (the trapezoid on every step, 150 steps), H the rings' spins'
    and the rotor's angular momentum about the chord."""
    p = rotor_scene(gravity=False, drag=False)
    net, st, drive, mo = start(p)
    mo.L *= 1.03
    mo.top_spin *= 1.03
    mo.ground_spin *= 1.03
    integ = dy.Integrator(net, drive, dy.default_step(net, st.state))
    e3 = net.frame[:, 2]
    m = np.array([r.mass_kg for r in net.rings])

    def H(mo):
        orbital = np.sum(m[:, None] * np.cross(mo.state.X, mo.V), axis=0) @ e3
        return (mo.L[1:-1] @ e3).sum() + integ.Jp[0] * mo.ground_spin \
            + integ.Jp[-1] * mo.top_spin + orbital

    def net_torque(mo):
        return drive.rotor.torque(mo.top_spin, mo.t)[0] - drive.generator.torque(mo.ground_spin)[0]

    H0, impulse, before = H(mo), 0.0, net_torque(mo)
    for _ in range(150):
        integ.step(mo)
        after = net_torque(mo)
        impulse += integ.dt * (before + after) / 2
        before = after
    assert abs(impulse) > 0.05 * abs(H0 - H0 / 1.03)  # the torques did work on it
    # the splitting's half-kicks take the end torques at the spins the trapezoid
    # samples: the balance is exact to round-off (3e-14 measured)
    assert H(mo) - H0 == pytest.approx(impulse, rel=1e-9)


def test_a_torque_the_network_cannot_hold_fails_with_advice():
    """At 40 m/s the operating point's torque (915 N m) is past what the 5-ring helix
    holds: a NetworkError (exit 1) naming the torque and what to change."""
    from rawehelix.references.network import NetworkError
    with pytest.raises(NetworkError, match="cannot hold the rotor's torque .* lower "
                                           "wind.speed_m_s or give more rings"):
        start(rotor_scene().replace(wind={"speed_m_s": 40.0}))


def test_a_start_up_runs_the_rotor_unloaded_until_the_release():
    """startup (a table from tsr 0, the generator released at 60 rpm): the run starts at
    rest, the rotor's torque at rest is its law's limit Q(Omega -> 0) (operation/rotor.py
    at 1e-6 rad/s), and in the first 0.2 s, far below 60 rpm, the ground carries no
    torque and the helix's angular momentum is the rotor's impulse alone."""
    p = scene.load("startup").replace(model={"kinematics": "extensible", "gravity": False,
                                             "drag": False}, section=SECTION)
    net, st, drive, mo = start(p)
    assert mo.top_spin == 0 and mo.ground_spin == 0
    v_n = 6.6131 * np.cos(np.radians(45.0))
    law = rotor_laws.from_params(p)
    assert drive.rotor.torque(0.0, 0.0)[0] == pytest.approx(float(law.torque(1e-6, v_n, 1.225)),
                                                             rel=1e-5)
    integ = dy.Integrator(net, drive, dy.default_step(net, st.state))
    e3, impulse, before = net.frame[:, 2], 0.0, drive.rotor.torque(0.0, 0.0)[0]
    for _ in range(150):
        integ.step(mo)
        assert integ.ground_torque_Nm(mo) == 0.0
        after = drive.rotor.torque(mo.top_spin, mo.t)[0]
        impulse += integ.dt * (before + after) / 2
        before = after
    H = (mo.L[1:-1] @ e3).sum() + integ.Jp[0] * mo.ground_spin + integ.Jp[-1] * mo.top_spin
    assert 0 < mo.top_spin < 60 * RPM and integ.released_at is None
    assert H == pytest.approx(impulse, rel=1e-9)
