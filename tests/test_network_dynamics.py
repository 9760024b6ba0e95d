"""The network's time integration (references/network/dynamics.py), verified against
what it does not compute itself: the linearisation's modes (scipy's eigh on the
Hessian, references/network/modes.py) for the temporal order, the energy (conserved
without drag; balanced by the drag's work with it) and the angular momentum about
the chord (balanced by the end torques).  5-ring networks of the Table 2 helix with
the fitted self-stressed section; about 6 s together."""

import math

import numpy as np
import pytest

from rawehelix.references.network import Network, solve
from rawehelix.references.network import dynamics as dy
from rawehelix.references.network import energy as en
from rawehelix.references.network.modes import modes
from rawehelix.studies import scene

#: the tensegrity section that fits the lab's axial and torsion tests (network.md)
SECTION = {"law": "tensegrity", "torsion": "members", "self_stress_N": 632.6,
           "bar_EA_N": 18200.0, "rings": 5}


def table2(**model):
    return scene.load("stationary_table2").replace(
        section=SECTION, model={"kinematics": "extensible", **model})


def test_a_small_modes_motion_is_the_modes_cosine_at_second_order():
    """Started at rest on the lowest mode's shape (amplitude 10 um, its nonlinearity
    ~1e-6), the rings move as a phi cos(omega t), omega from eigh; at t = 1.25
    periods (cos = 0: the phase error shows at first order) the error falls 4x per
    halving of the step: the observed order 1.9-2.0."""
    net = Network.from_parameters(table2(drag=False))
    st = solve(net)
    mode = modes(st)[0]
    amp = 1e-5 / np.max(np.abs(mode.shape[:, :3]))
    T = 1 / mode.frequency_Hz
    h0 = dy.stable_step(net, st.state) / 2
    errors = []
    for h in (h0, h0 / 2, h0 / 4):
        mo = dy.at_rest(en.moved(net, st.state, amp * mode.shape.ravel()))
        dy.Integrator(net, dy.Drive(), h).advance(mo, 1.25 * T, 1.25 * T)
        exact = amp * mode.shape[:, :3] * math.cos(2 * math.pi * 1.25)
        errors.append(np.max(np.abs(mo.state.X - st.state.X - exact)) / amp)
    rates = np.log2(np.array(errors[:-1]) / errors[1:])
    assert np.all((rates > 1.8) & (rates < 2.2)), rates  # 1.87, 1.93 observed
    assert errors[-1] < 1e-4  # 3.8e-5 observed


def test_without_drag_the_energy_is_conserved_to_second_order():
    """A large motion (every interior ring pushed 5 cm off the chord, some tethers near
    slack) over 5 lateral periods: the total energy's largest excursion is bounded and
    falls 4x per halving of the step (a symplectic splitting: no drift)."""
    net = Network.from_parameters(table2(drag=False, gravity=False))
    st = solve(net)
    h0 = dy.stable_step(net, st.state) / 2
    push = np.zeros((net.count, 6))
    push[1:-1, 1] = 0.05 * np.sin(np.pi * np.arange(1, net.count - 1) / (net.count - 1))
    push[1:-1, 5] = 0.2  # and turned 0.2 rad
    spread = []
    for h in (h0, h0 / 2):
        mo = dy.at_rest(en.moved(net, st.state, push.ravel()))
        integ = dy.Integrator(net, dy.Drive(), h)
        E = []
        integ.advance(mo, 2.0, 0.01, lambda m: E.append(integ.total_energy_J(m)))
        E = np.array(E)
        scale = E[0] - en.energy(integ.net, st.state)  # the motion's energy [J]
        spread.append(np.max(np.abs(E - E[0])) / scale)
        half = len(E) // 2  # no secular drift: the second half's excursion as the first's
        assert np.max(np.abs(E[half:] - E[0])) < 1.5 * np.max(np.abs(E[:half] - E[0])) + 1e-12
    # relative to the motion's energy: 3.0 % at half the stability bound, 0.81 % at a quarter
    assert spread[0] < 0.05
    assert 3.0 < spread[0] / spread[1] < 5.0, spread


def test_with_drag_the_energy_lost_is_the_drags_work():
    """In Table 2's wind (10 m/s), released from the chord's stationary state pushed
    5 cm aside: E(t) - E(0) equals the drag's work (its power beyond the dead drag at
    rest, trapezoidal in time) to 1e-3 of that work over 2 s."""
    net = Network.from_parameters(table2(gravity=False))
    st = solve(net)
    h = dy.stable_step(net, st.state) / 4
    push = np.zeros((net.count, 6))
    push[1:-1, 1] = 0.05
    mo = dy.at_rest(en.moved(net, st.state, push.ravel()))
    integ = dy.Integrator(net, dy.Drive(), h)
    E0, work, P = integ.total_energy_J(mo), 0.0, integ.drag_power_W(mo)
    for _ in range(int(round(2.0 / h))):
        integ.step(mo)
        P_new = integ.drag_power_W(mo)
        work += h * (P + P_new) / 2
        P = P_new
    assert work < -1e-3  # it dissipates (-0.05 J)
    assert integ.total_energy_J(mo) - E0 == pytest.approx(work, rel=1e-3)


def test_the_spin_up_balances_the_end_torques():
    """The Sec. 5.2 ends on a weightless, windless helix: the top torque ramp (Eq. 69)
    and the ground's controller (Eq. 40).  About the chord the rings' angular
    momentum sum J_i omega_i changes by the integral of M_N - m_0 (1e-6), and the
    spin settles at the controller's target (within 1 %)."""
    p = scene.load("nominal_operation").replace(
        section={**SECTION, "rings": 5}, model={"kinematics": "extensible", "gravity": False,
                                                 "drag": False})
    net = Network.from_parameters(p, end_torque_Nm=0.0)
    st = solve(net)
    drive = dy.Drive.from_parameters(p)
    integ = dy.Integrator(net, drive, dy.default_step(net, st.state))
    mo = dy.at_rest(st.state)
    e3 = net.frame[:, 2]

    def momentum(m):
        inner = np.einsum("ri,ri->r", m.L[1:-1], np.broadcast_to(e3, m.L[1:-1].shape)).sum()
        return inner + integ.Jp[0] * m.ground_spin + integ.Jp[-1] * m.top_spin

    def net_torque(m):
        return drive.top_torque(m.t) - integ.ground_torque_Nm(m)

    impulse, tq = 0.0, net_torque(mo)
    for _ in range(int(round(12.0 / integ.dt))):
        integ.step(mo)
        tq_new = net_torque(mo)
        impulse += integ.dt * (tq + tq_new) / 2
        tq = tq_new
    assert momentum(mo) == pytest.approx(impulse, rel=1e-6)
    target = p.controller.target_rpm * 2 * math.pi / 60
    assert integ.spin(mo) == pytest.approx(target, rel=1e-2)


def test_a_step_past_the_stability_bound_fails_with_advice():
    """Three times the splitting's stability bound: the motion diverges and the error
    names time.dt_s."""
    from rawehelix.references.network import NetworkError
    net = Network.from_parameters(table2(drag=False))
    st = solve(net)
    push = np.zeros((net.count, 6))
    push[1:-1, 2] = 1e-3
    mo = dy.at_rest(en.moved(net, st.state, push.ravel()))
    integ = dy.Integrator(net, dy.Drive(), 3 * dy.stable_step(net, st.state))
    with pytest.raises(NetworkError, match="lower time.dt_s"):
        for _ in range(2000):
            integ.step(mo)


def test_simulate_through_the_scheme_registry_starts_from_the_stationary_network():
    """``simulate --scheme network`` (studies/simulate.py through the registry): the
    first row's bay forces are the stationary network's T at the ground and the top
    (StationaryNetwork.tension_N, 1e-9), at rest; the spins then rise under the
    torque ramp, the top's first."""
    from rawehelix.studies import simulate
    p = scene.load("nominal_operation").replace(
        section=SECTION, model={"kinematics": "extensible"},
        discretisation={"scheme": "network"})
    series = simulate.compute(p, until_s=0.3)
    T = solve(Network.from_parameters(p, end_torque_Nm=0.0)).tension_N()
    assert series.tension_s0_N[0] == pytest.approx(T[0], rel=1e-9)
    assert series.tension_s1_N[0] == pytest.approx(T[-1], rel=1e-9)
    assert np.all(series.spin_rpm[0] == 0)
    assert len(series.t_s) == round(0.3 / p.time.output_every_s) + 1
    final = series.spin_rpm[-1]
    assert final[2] > final[1] > final[0] > 0  # the torque enters at the top
    assert series.summary["network"]["rings"] == 5
    assert "network: 5 rings" in simulate.report(series)


def test_the_sweeps_backend_resumes_from_its_packed_state_exactly():
    """The sweep's backend (references/network/forced.py) on Sec. 5.3's circle at 3 Hz:
    advancing 0.2 s in one go or stopping, packing, unpacking and continuing gives the
    same motion and the same T(0) (to 1e-12: the restart puts the top on its circle at
    the stored time, not the time summed step by step)."""
    from rawehelix.references.network.forced import NetworkBackend
    p = scene.load("mobile_end").replace(section=SECTION, model={"kinematics": "extensible"})
    ts = p.normalised().t_scale
    b = NetworkBackend(p)
    start = b.stationary()
    b.set_frequency(3.0, 0.0)
    whole, T_whole = b.advance(start, 0.0, 0.2 / ts, np.array([0.1 / ts, 0.2 / ts]))
    half, T1 = b.advance(start, 0.0, 0.1 / ts, np.array([0.1 / ts]))
    again, T2 = b.advance(NetworkBackend.unpack(NetworkBackend.pack(half)), 0.1 / ts, 0.2 / ts,
                          np.array([0.2 / ts]))
    assert np.max(np.abs(again.state.X - whole.state.X)) < 1e-12
    assert np.r_[T1, T2] == pytest.approx(T_whole, rel=1e-12)
    assert abs(T_whole[0] - T_whole[1]) > 1e-6  # the circle moves it


def test_the_members_twist_inertia_puts_the_continuums_torsional_modes_at_the_hoops():
    """section.twist_inertia = "members" without rings: the helix's mass at the
    tethers' radius, J' = (M / L0) R^2 per unit length (the network's default hoop),
    instead of Eq. (27)'s 2 (M / L0) EI / EA (19.5x larger here).  The FE continuum's
    torsional modes (Table 2, fixed ends, gamma off) are then the twist wave's
    k / (2 L0) sqrt(GJ / J') (5e-4 at N = 4, p = 3), and the default scene's delta is
    unchanged."""
    from mpi4py import MPI
    from rawehelix.studies import modes as fe_modes
    base = scene.load("stationary_table2", elements=4, degree=3)
    p = base.replace(section={"twist_inertia": "members"})
    h = p.helix
    J = h.mass_kg / h.length_m * h.radius_m ** 2  # [kg m]
    assert p.normalised().delta / base.normalised().delta == pytest.approx(
        2 * h.EI_Nm2 / (h.EA_N * h.radius_m ** 2), rel=1e-12)
    found = fe_modes.compute(p, comm=MPI.COMM_SELF)
    f = sorted(m.frequency_Hz for m in found if m.family == "torsional" and m.period_s)[:2]
    k = np.arange(1, 3)
    assert f == pytest.approx(k / (2 * h.length_m) * math.sqrt(h.GJ_Nm2 / J), rel=5e-4)
