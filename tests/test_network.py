"""The network reference (references/network) against closed forms of the network
alone, each written out here from the chord geometry, independently of the module:
a single bay's axial, bending and torsional stiffness, Tulloch's collapse angle of one
bay, a weighted taut string of rings' sag and a taut string's frequencies.  All numpy,
under 3 s together."""

import math

import numpy as np
import pytest
from scipy.optimize import brentq, minimize_scalar

from rawehelix import members
from rawehelix.references.network import Network, Ring, solve
from rawehelix.references.network import energy as en
from rawehelix.references.network.modes import modes
from rawehelix.studies import scene

N_TETHERS, RADIUS, K, HEIGHT = 6, 0.19, 6000.0, 1.0  # [-], [m], [N], [m]


def bay(lay_rad=0.0, rest_m=0.99, k=K, height=HEIGHT, twist=0.0, torque=None):
    """One bay (two rings, tethers of rest length rest_m) standing on e3 = -k_E."""
    ring = Ring(1.0, 1.0, 1.0)
    return Network(n=N_TETHERS, radius_m=RADIUS, k_N=k, l0_m=rest_m,
                   chord_m=np.array([0.0, 0.0, -height]), lay_rad=lay_rad, rings=(ring, ring),
                   loads_N=np.zeros((2, 3)), end_twist_rad=twist, end_torque_Nm=torque)


def hand_energy(lay, rest, dz=0.0, bend=0.0, twist=0.0, k=K):
    """The bay's tether energy [J], written from its chord geometry: ground point m at
    R (cos phi, sin phi, 0), top point m at the top ring's centre (0, 0, HEIGHT + dz)
    plus R (cos(phi + lay + twist), sin(phi + lay + twist), 0) tilted by ``bend`` about
    the first axis; force k (L - rest) / rest when taut."""
    phi = 2 * np.pi * np.arange(N_TETHERS) / N_TETHERS
    lo = RADIUS * np.column_stack([np.cos(phi), np.sin(phi), 0 * phi])
    a = phi + lay + twist
    up = RADIUS * np.column_stack([np.cos(a), np.sin(a) * np.cos(bend), np.sin(a) * np.sin(bend)])
    up[:, 2] += HEIGHT + dz
    L = np.linalg.norm(up - lo, axis=1)
    return float(np.sum(k / (2 * rest) * np.maximum(L - rest, 0.0) ** 2))


def top_block(net):
    """The top ring's 6x6 stiffness in the chord frame (e1, e2, e3), ground held."""
    H = en.gradient_hessian(net, en.State(*net.reference()))[1].toarray()[6:, 6:]
    E = net.frame
    T = np.block([[E, np.zeros((3, 3))], [np.zeros((3, 3)), E]])
    return T.T @ H @ T


def second_difference(f, h=1e-4):  # truncation ~1e-8, round-off ~2e-7 relative
    return (f(h) - 2 * f(0.0) + f(-h)) / (h * h)


def test_bay_stiffness_at_zero_lay_is_the_closed_form():
    """beta = 0, chords of length h = 1 m at the force f = k (h - l0) / l0: axial n k / l0,
    bending (about a diameter) n k R^2 / (2 l0) (the tension adds nothing: the tilted
    chords' length is stationary to second order), torsion n f R^2 / h (Tulloch's
    geometric torsional stiffness, GJ = N R^2)."""
    rest = 0.99
    f = K * (HEIGHT - rest) / rest
    S = top_block(bay(rest_m=rest))
    # the chord frame's e3 is the chord (0, 0, -1): e3's translation and turn are the bay's
    assert S[2, 2] == pytest.approx(N_TETHERS * K / rest, rel=1e-12)
    assert S[3, 3] == pytest.approx(N_TETHERS * K * RADIUS**2 / (2 * rest), rel=1e-12)
    assert S[4, 4] == pytest.approx(N_TETHERS * K * RADIUS**2 / (2 * rest), rel=1e-12)
    assert S[5, 5] == pytest.approx(N_TETHERS * f * RADIUS**2 / HEIGHT, rel=1e-12)


@pytest.mark.parametrize("lay_deg", [10.0, 25.0])
def test_laid_bay_stiffness_against_its_chord_geometry(lay_deg):
    """A laid bay (the top ring turned by delta_0): its axial, bending and torsional
    stiffness against the second differences of the energy of the chords written
    out by hand (relative 1e-6: the differences' truncation)."""
    lay = math.radians(lay_deg)
    rest = 0.995 * math.hypot(HEIGHT, 2 * RADIUS * math.sin(lay / 2))
    S = top_block(bay(lay_rad=lay, rest_m=rest))
    # the network's e3 points up (0, 0, -1 in k_E): a rise dz is a move along e3
    axial = second_difference(lambda h: hand_energy(lay, rest, dz=h))
    bending = second_difference(lambda h: hand_energy(lay, rest, bend=h))
    torsion = second_difference(lambda h: hand_energy(lay, rest, twist=h))
    assert S[2, 2] == pytest.approx(axial, rel=1e-6)
    assert max(S[3, 3], S[4, 4]) == pytest.approx(bending, rel=1e-6)
    assert min(S[3, 3], S[4, 4]) == pytest.approx(bending, rel=1e-6)  # n = 6: isotropic
    assert S[5, 5] == pytest.approx(torsion, rel=1e-6)


def tulloch_angle(R, l_t):
    """Derived here: a bay of inextensible tethers l_t under the axial force F has the
    height h(d) = sqrt(l_t^2 - 2 R^2 (1 - cos d)) at the twist d, each tether's
    tangential share (R sin d) / l_t of its force and axial share h / l_t, so the torque
    is Q = F R^2 sin d / h(d); dQ/dd = 0 at cos d h^2 + R^2 sin^2 d = 0, i.e.
    R^2 (1 - c)^2 + l_t^2 c = 0, c = cos d, the root in [-1, 0]."""
    return math.acos(brentq(lambda c: R * R * (1 - c) ** 2 + l_t * l_t * c, -1.0, 0.0))


def test_one_bays_torque_peaks_at_tullochs_collapse_angle():
    """One bay of nearly inextensible tethers (k = 1e6 N, F = 100 N) held at the axial force F by
    its height: the network's torque reaction peaks at the twist the closed form gives
    (and members.critical_twist, the limits' criterion, agrees)."""
    l_t, F = 1.0, 100.0  # [m], [N]
    stiff = 1e6  # stretch ~1e-5: the argmax moves by ~1e-5, and the torque keeps 1e-11 digits

    def reactions(twist, height):
        net = bay(rest_m=l_t, k=stiff, height=height, twist=twist)
        g = en.gradient_hessian(net, en.State(*net.reference()))[0]
        e3 = net.frame[:, 2]
        return g[6:9] @ e3, g[9:12] @ e3  # the force and torque holding the top ring

    def torque(twist):
        hi = math.sqrt(max(l_t**2 - 2 * RADIUS**2 * (1 - math.cos(twist)), 1e-12))
        h = brentq(lambda z: reactions(twist, z)[0] - F, 0.5 * hi, hi * 1.001, xtol=1e-14)
        return reactions(twist, h)[1]

    peak = minimize_scalar(lambda d: -torque(d), bounds=(1.2, 2.5), method="bounded",
                           options={"xatol": 1e-7}).x
    expected = tulloch_angle(RADIUS, l_t)
    assert expected == pytest.approx(members.critical_twist(RADIUS, l_t), abs=1e-12)
    assert peak == pytest.approx(expected, abs=1e-4)  # 2e-5 observed
    assert torque(expected) == pytest.approx(F * RADIUS**2 * math.sin(expected) / math.sqrt(
        l_t**2 - 2 * RADIUS**2 * (1 - math.cos(expected))), rel=1e-4)  # the stretch f / k ~ 2e-5


def string_scene(rings, elevation_deg=45.0, gravity=False, drag=False):
    """Table 2's helix as a bending-free (R = 1 mm), unlaid, weightless-or-not string of
    rings, without drag unless asked."""
    return scene.load("stationary_table2").replace(
        section={"rings": rings, "radius_m": 1e-3}, model={"gravity": gravity, "drag": drag},
        ends={"elevation_deg": elevation_deg})


def test_taut_string_of_rings_frequencies():
    """Weightless, bending-free: the lateral (and, with the hoop's inertia, the
    torsional) frequencies are the beaded string's,
    f_k = (1 / pi) sqrt(T / (m l)) sin(k pi / (2 (rings - 1))), and tend to the
    string's k / (2 L) sqrt(T / mu) (within the beads' (k pi / (2 (rings - 1)))^2 / 6);
    T = n k eps0, m = M / (rings - 1), l = (1 + eps0) L0 / (rings - 1)."""
    rings = 17
    p = string_scene(rings)
    h = p.helix
    eps0, bays = p.ends.elongation, rings - 1
    T = h.EA_N * eps0  # the tethers' k = EA / n (members.py) at the strain eps0
    m, l, L = h.mass_kg / bays, (1 + eps0) * h.length_m / bays, (1 + eps0) * h.length_m
    result = solve(Network.from_parameters(p))
    assert result.tension_N() == pytest.approx(T, rel=1e-9)
    found = modes(result)
    for family in ("lateral_in_plane", "lateral_out_of_plane"):
        f = np.array([x.frequency_Hz for x in found if x.family == family][:4])
        k = np.arange(1, 5)
        beads = np.sqrt(T / (m * l)) / np.pi * np.sin(k * np.pi / (2 * bays))
        assert f == pytest.approx(beads, rel=2e-5)  # the rings' R = 1 mm bending: ~1e-6
        string = k / (2 * L) * math.sqrt(T / (h.mass_kg / L))
        assert np.all(np.abs(f / string - 1) < (k * np.pi / (2 * bays)) ** 2 / 6 * 1.01 + 1e-5)
    # the rings' turns: each bay's torsional stiffness n f R^2 / l (Tulloch's), each
    # ring's polar inertia the hoop's m R^2: the beaded string's frequencies again
    R = p.helix.radius_m if p.model.section.radius_m is None else p.model.section.radius_m
    f = np.array([x.frequency_Hz for x in found if x.family == "torsional"][:4])
    k = np.arange(1, 5)
    GJ_per_l = T * R * R / l  # n f = T, unlaid
    assert f == pytest.approx(np.sqrt(GJ_per_l / (m * R * R)) / np.pi
                              * np.sin(k * np.pi / (2 * bays)), rel=1e-9)


def test_string_of_rings_sags_as_the_weighted_string():
    """A horizontal chord under the rings' weight: the beads' polygon has the string's
    parabola at its rings, y(x) = w x (L - x) / (2 H), H the chord-wise tension (the
    same in every bay), w = M g / L per unit chord L (each ring M / (rings - 1) every
    L / (rings - 1)): the sag at the middle ring is M g L / (8 H), within the string's
    small-sag error (sag / L)^2."""
    p = string_scene(9, elevation_deg=0.0, gravity=True)
    h, eps0 = p.helix, p.ends.elongation
    result = solve(Network.from_parameters(p))
    L = (1 + eps0) * h.length_m
    H = float(result.bay_forces_N()[0] @ (result.network.chord_m / L))  # chord-wise, constant
    sag = h.mass_kg * p.environment.g_m_s2 * L / (8 * H)
    assert result.sag_m() == pytest.approx(sag, rel=1e-3)
    assert abs(result.sag_m() / L) ** 2 < 1e-3


def test_string_of_rings_sags_downwind_as_eq_14s_drag_says():
    """A vertical chord, weightless, in the wind of Table 2 (10 m/s along -i_E): Eq. (14)'s
    drag at rest, q = rho_0 l_a C_D v_w0^2 / 2 per unit unstretched length, pushes the
    middle ring downwind (-x) by q L0 L / (8 H) (the weighted string's parabola, the load
    per unit chord q L0 / L), within the small-sag error."""
    p = string_scene(9, elevation_deg=90.0, drag=True)
    h, env, eps0 = p.helix, p.environment, p.ends.elongation
    result = solve(Network.from_parameters(p))
    L = (1 + eps0) * h.length_m
    H = float(result.bay_forces_N()[0] @ (result.network.chord_m / L))
    q = env.air_density_kg_m3 * h.drag_length_m * h.drag_coefficient * env.wind_speed_m_s**2 / 2
    middle = result.positions_m[4]
    assert middle[0] == pytest.approx(-q * h.length_m * L / (8 * H), rel=1e-3)
    assert abs(middle[1]) < 1e-12


def test_stationary_solve_refuses_a_collapsed_bay():
    """A torque far past what one bay can carry: no stationary state; the error names
    the torque key to lower."""
    from rawehelix.references.network import NetworkError
    net = bay(rest_m=0.99, torque=1e4)
    with pytest.raises(NetworkError, match="torque.top_Nm"):
        solve(net, max_iterations=30)


def test_a_torque_that_unwinds_the_lay_collapses_the_helix():
    """Table 2 laid at 16.8 deg, its top ring free under a torque: with the lay's hand
    (+20 N m) it holds (every tether taut); against it (-5 N m, below the lay's own
    unwinding torque T R tan(beta) ~ 12 N m) the tethers straighten, shorten past their
    4.5 % lay and go slack: no state near the straight chord, and the error says why."""
    from rawehelix.references.network import NetworkError
    p = scene.load("stationary_table2").replace(
        section={"rings": 65, "lay_angle_deg": 16.8, "tether_EA_N": 6910.2})  # delta_0 0.4 rad
    held = solve(Network.from_parameters(p.replace(torque={"top_Nm": 20.0})))
    assert held.slack == [] and held.state.theta > 0
    with pytest.raises(NetworkError, match="unwinds the lay"):
        solve(Network.from_parameters(p.replace(torque={"top_Nm": -5.0})))


def test_modes_through_the_scheme_registry_are_the_networks_in_hertz():
    """`rawehelix modes SCENE --scheme network`'s path (studies/modes.py through the
    registry): the lowest lateral frequency is the beaded string's (Table 2's rings of
    R = 1 mm, weightless) in Hz, whatever the normalisation in between."""
    from rawehelix.studies import modes as modes_study
    p = string_scene(9).replace(discretisation={"scheme": "network"})
    result = modes_study.compute(p)
    h, bays = p.helix, 8
    T = h.EA_N * p.ends.elongation
    m, l = h.mass_kg / bays, (1 + p.ends.elongation) * h.length_m / bays
    lowest = min(x.frequency_Hz for x in result if x.family == "lateral_out_of_plane")
    assert lowest == pytest.approx(np.sqrt(T / (m * l)) / np.pi * np.sin(np.pi / (2 * bays)),
                                   rel=2e-5)
    assert "9 rings" in modes_study.report(result)


def test_stationary_prints_the_network_beside_the_continuum():
    """`rawehelix stationary SCENE --scheme network`: the FE continuum (N = 8, p = 3) and
    the network beside it, both of the same members (the self-stressed section the lab
    tests fit, docs/explanation/network.md) under the top torque 10 N m: the network's
    T(0) is the continuum's within 1 % (209.0 against 208.5 N) and its twist, of the
    same sign, within 2 % (1.1489 against 1.1516 rad: both Tulloch's GJ = n f R^2 of
    the tethers' tension).  Not the
    solid section's T(0): the sag's stretch, ~8/3 (sag/L)^2 EA = 4.5 N of T, needs the
    same bending stiffness, and the solid's EI, 20x the members', gives 203.1 N."""
    from mpi4py import MPI

    from rawehelix.studies import stationary
    p = scene.load("stationary_table2", elements=8, degree=3).replace(
        section={"rings": 9, "law": "tensegrity", "torsion": "members", "self_stress_N": 632.6,
                 "bar_EA_N": 18200.0},
        discretisation={"scheme": "network"}, model={"kinematics": "extensible"},
        torque={"top_Nm": 10.0})
    result = stationary.compute(p, MPI.COMM_SELF)
    s = result.summary
    assert s["beside"]["rings"] == 9
    assert s["beside"]["tension_s0_N"] == pytest.approx(s["tension_N"]["s0"], rel=1e-2)
    assert s["beside"]["twist_end_to_end_rad"] == pytest.approx(
        s["torque"]["twist_end_to_end_rad"], rel=2e-2)
    assert "network beside it (9 rings" in stationary.report(result)


def test_a_self_stressed_bays_shear_stiffness_is_its_net_tensions():
    """An unlaid bay with the self-stress P0 balanced by its bar (on the axis, between the
    ring centres): the top ring moved sideways by u, not turned, tilts every tether and
    the bar by u / h, so its stiffness is (n f - C) / h with f the tethers' force and C
    the bar's compression, i.e. the bay's net axial force T / h: the self-stress drops
    out (members.py::Members.shear_stiffness counts n f, its bars adding nothing)."""
    n, P0, EA_b, stretch = N_TETHERS, 600.0, 2e4, 1.001  # [-], [N], [N], the bay's stretch
    rest = HEIGHT / (1 + P0 / K)
    ring = Ring(1.0, 1.0, 1.0)
    bar_l0 = HEIGHT / (1 - n * P0 / EA_b)
    h = stretch * HEIGHT
    net = Network(n=n, radius_m=RADIUS, k_N=K, l0_m=rest, chord_m=np.array([0.0, 0.0, -h]),
                  lay_rad=0.0, rings=(ring, ring), loads_N=np.zeros((2, 3)), bar_EA_N=EA_b,
                  bar_l0_m=bar_l0)
    f = K * (h - rest) / rest
    compression = -EA_b * (h - bar_l0) / bar_l0
    S = top_block(net)
    assert S[0, 0] == pytest.approx((n * f - compression) / h, rel=1e-12)
    assert n * f - compression < 0.05 * n * P0  # the net tension, not the self-stress
    assert members.Members(n=n, R=RADIUS, beta=0.0, k=K, P0=P0, EA_b=EA_b).shear_stiffness(f) \
        == pytest.approx(n * f)


def test_the_hessian_is_the_energys_second_derivative():
    """At a state off equilibrium (rings moved and turned at random, some tethers slack,
    bars, a torque end), the analytic gradient and Hessian against central differences
    of the energy in the exponential chart (1e-6 and 1e-4 relative: the differences)."""
    from rawehelix.references.network import energy as en
    p = scene.load("stationary_table2").replace(
        section={"rings": 4, "lay_angle_deg": 2.0, "self_stress_N": 50.0, "bar_EA_N": 1e4})
    net = Network.from_parameters(p, end_torque_Nm=3.0)
    rng = np.random.default_rng(1)
    X, R = net.reference()
    s = en.moved(net, en.State(X + 0.01 * rng.standard_normal(X.shape), R),
                 0.05 * rng.standard_normal(6 * net.count))
    assert 0 < np.sum(en.tether_forces(net, s) == 0) < net.n * (net.count - 1)  # some slack
    g, H = en.gradient_hessian(net, s)
    P = en.free_basis(net)
    g, H = P.T @ g, (P.T @ H @ P).toarray()
    free = P.shape[1]

    def E(v):
        return en.energy(net, en.moved(net, s, P @ v))

    h, I = 1e-4, np.eye(free)
    fd_g = np.array([(E(h * I[i]) - E(-h * I[i])) / (2 * h) for i in range(free)])
    fd_H = np.array([[(E(h * (I[i] + I[j])) - E(h * (I[i] - I[j])) - E(h * (I[j] - I[i]))
                       + E(-h * (I[i] + I[j]))) / (4 * h * h) for j in range(free)]
                     for i in range(free)])
    assert np.abs(fd_g - g).max() < 1e-6 * np.abs(g).max()
    assert np.abs(fd_H - H).max() < 1e-4 * np.abs(H).max()
    assert np.abs(H - H.T).max() < 1e-12 * np.abs(H).max()


@pytest.mark.parametrize("law,advised", [("solid", True), ("saturating", True),
                                         ("tensegrity", False)])
def test_the_beside_line_says_when_the_continuum_has_other_members(law, advised):
    """The network is the members' helix: beside a continuum whose section is not the
    members' (the solid's EI is 20x theirs: sag +228 % at 9 rings) the line says how to
    compare the same members."""
    from rawehelix.studies import stationary
    beside = {"scheme": "network", "rings": 9, "spacing_m": 2.015, "newton_iterations": 4,
              "wall_s": 0.1, "sag_m": 0.1176, "tension_s0_N": 207.4,
              "smallest_tether_force_N": 33.9, "smallest_at_s_m": 15.1, "slack_tethers": 0,
              "twist_end_to_end_rad": 0.0}
    s = {"sag_m": 0.0359, "tension_N": {"s0": 202.9}, "torque": None,
         "limits": {"law": law, "min_member_force_N": {"value": 3.66}}}
    line = stationary._beside_line(beside, s)
    assert "sag 0.11760 m (+227.58 %)" in line
    assert ("--set section.law=tensegrity --set model.kinematics=extensible" in line) == advised
