"""The lifted top end (issue 43, solvers/lifted.py): the top's position is an unknown
held by forces.  Checked against the elastic catenary in closed form (Irvine,
references/catenary.py) and the straight weightless rod under an axial force; a lifter
too weak to hold the helix up is refused before any work."""

import math

import numpy as np
import pytest
from mpi4py import MPI

from rawehelix.errors import SceneError
from rawehelix.references import catenary
from rawehelix.solvers import lifted
from rawehelix.studies import scene

PULL_N = 200.0  # the lifter's pull [N] (Table 2's nominal tension)


def _cable(N, degree=3, **model):
    """Table 2's helix as a cable: no bending, twist or drag; the extensible kinematics,
    whose tension law N = EA (|r'| - 1) along the tangent is Irvine's."""
    p = scene.load("stationary_table2", elements=N)
    return p.replace(model={"drag": False, "bending": False, "twist": False,
                            "kinematics": "extensible", **model},
                     discretisation={"degree": degree})


def _catenary_errors(N, degree):
    """(max |T - T_cat| [N], max |r - r_cat| at the nodes [m], top [m]) of the lifted
    cable pulled by 200 N at 45 deg."""
    p = _cable(N, degree)
    F = PULL_N * lifted.lifter_direction(45.0, 0.0)
    _, out = lifted.solve(p, lifted.TopLoad(lifter_N=F), MPI.COMM_SELF)
    res, q = out.result, p.normalised()
    H, V, L0, EA = -F[0], -F[2], p.helix.length_m, p.helix.EA_N
    w = p.helix.mass_kg * p.environment.g_m_s2 / L0  # [N/m]
    sT = q.length_m(res.s_tension)
    T_err = np.max(np.abs(q.tension_N(res.tension) - np.hypot(H, V - w * (L0 - sT))))
    # the cable from 0 to s is a catenary pulled at s by (H, V - w (L0 - s))
    s, x = q.length_m(res.s), q.length_m(res.centre_line)
    ref = np.array([catenary.top(H, V - w * (L0 - si), w, EA, si) if si > 0 else (0.0, 0.0)
                    for si in s])
    r_err = np.max(np.hypot(-x[:, 0] - ref[:, 0], -x[:, 2] - ref[:, 1]))
    assert np.allclose(x[:, 1], 0.0, atol=1e-12)  # azimuth 0: in the x-z plane
    return T_err, r_err, out


# p = 2 compiles its own forms (21 s on a cold JIT cache): make test-long; p = 3 is the
# same check in make test
@pytest.mark.parametrize("degree", [pytest.param(2, marks=pytest.mark.long), 3])
def test_lifted_cable_is_the_elastic_catenary(degree):
    """The FE tension converges to the catenary's at rate p, the nodes at rate >= 2p - 1
    (measured at N = 2, 4, 8: p = 3: T 1.3e-3, 1.7e-4, 2.1e-5 N (rate 3.0), nodes
    9.5e-9, 3.0e-10, 9.5e-12 m (rate 5.0); p = 2: T rate 2.0, nodes rate 4.0)."""
    errors = [_catenary_errors(N, degree)[:2] for N in (2, 4, 8)]
    T_rates = [math.log2(a[0] / b[0]) for a, b in zip(errors, errors[1:])]
    r_rates = [math.log2(a[1] / b[1]) for a, b in zip(errors, errors[1:])]
    assert min(T_rates) > degree - 0.2, T_rates
    assert min(r_rates) > 2 * degree - 1.2, r_rates
    assert errors[-1][0] < 0.02 and errors[-1][1] < 1e-7


def test_lifted_top_and_chord_elevation():
    """The top sits where Irvine's closed form puts it; the chord's elevation is that of
    the top, below the 45 deg pull since the helix's weight pulls it down."""
    _, _, out = _catenary_errors(4, 3)
    p = _cable(4)
    F = PULL_N * lifted.lifter_direction(45.0, 0.0)
    x, h = catenary.top(-F[0], -F[2], p.helix.mass_kg * 9.81 / p.helix.length_m,
                        p.helix.EA_N, p.helix.length_m)
    assert out.top_m == pytest.approx([-x, 0.0, -h], abs=1e-9)
    assert out.chord_elevation_deg == pytest.approx(math.degrees(math.atan2(h, x)), abs=1e-9)
    assert out.chord_elevation_deg < 45.0


@pytest.mark.parametrize("azimuth_deg", [0.0, 30.0])
def test_weightless_rod_stretches_by_F_L0_over_EA(azimuth_deg):
    """Gravity off: the rod is straight along the pull and stretched by F L0 / EA
    (extensible kinematics), or by eps (1 + eps) = F / EA (the paper's force T r',
    Eq. 32, solved for eps in closed form)."""
    F = 500.0 * lifted.lifter_direction(60.0, azimuth_deg)
    for kinematics, closed in (("extensible", lambda f, EA: f / EA),
                               ("paper", lambda f, EA: (math.sqrt(1 + 4 * f / EA) - 1) / 2)):
        p = _cable(4, gravity=False, kinematics=kinematics, bending=True)
        _, out = lifted.solve(p, lifted.TopLoad(lifter_N=F), MPI.COMM_SELF)
        L0, EA = p.helix.length_m, p.helix.EA_N
        expected = L0 * (1 + closed(500.0, EA)) * F / 500.0
        assert out.top_m == pytest.approx(expected, abs=1e-9 * L0), kinematics
    assert catenary.elongation(500.0, EA, L0) == pytest.approx(L0 * 500.0 / EA)


def test_top_mass_and_thrust_enter_the_end_force():
    """F = lifter + thrust + m g k_E: a thrust that cancels the top's weight leaves the
    state of the lifter alone (same top to round-off)."""
    p = _cable(2)
    F = PULL_N * lifted.lifter_direction(45.0, 0.0)
    m = 2.0
    alone = lifted.TopLoad(lifter_N=F)
    both = lifted.TopLoad(lifter_N=F, thrust_N=(0.0, 0.0, -m * 9.81), mass_kg=m)
    assert both.total_N() == pytest.approx(alone.total_N(), abs=1e-12)
    heavy = lifted.TopLoad(lifter_N=F, mass_kg=m)
    _, a = lifted.solve(p, alone, MPI.COMM_SELF)
    _, b = lifted.solve(p, heavy, MPI.COMM_SELF)
    assert b.top_m[2] > a.top_m[2]  # the heavier top hangs lower (z points down)


def test_a_lifter_too_weak_is_refused_before_any_work():
    """Upward pull below the weight of helix + top: one SceneError naming lifter.force_N."""
    p = _cable(2)
    weight = p.helix.mass_kg * p.environment.g_m_s2  # 5.0 N
    F = 0.9 * weight / math.sin(math.radians(30.0)) * lifted.lifter_direction(30.0, 0.0)
    with pytest.raises(SceneError, match=r"lifter\.force_N: the lifter cannot hold the helix up"):
        lifted.check_holds(p, lifted.TopLoad(lifter_N=F))
    strong = 1.2 * weight / math.sin(math.radians(30.0)) * lifted.lifter_direction(30.0, 0.0)
    lifted.check_holds(p, lifted.TopLoad(lifter_N=strong))  # holds: no error
    with pytest.raises(SceneError, match="cannot hold"):  # the top's mass counts too
        lifted.check_holds(p, lifted.TopLoad(lifter_N=strong, mass_kg=0.5))


def test_stationary_of_a_lifted_scene_reports_the_catenary_top():
    """rh.stationary on a scene with [lifter] top = "lifted" (the cable of the tests
    above, and a rotor's mass at the top): summary.json's lifter block holds the top
    where Irvine's closed form puts it, under the lifter and the rotor's weight."""
    import rawehelix as rh
    p = _cable(4).replace(lifter={"top": "lifted", "force_N": PULL_N, "elevation_deg": 45.0})
    s = rh.stationary(p, MPI.COMM_SELF).summary
    F = PULL_N * lifted.lifter_direction(45.0, 0.0)
    x, h = catenary.top(-F[0], -F[2], p.helix.mass_kg * 9.81 / p.helix.length_m,
                        p.helix.EA_N, p.helix.length_m)
    block = s["lifter"]
    assert block["top_position_m"] == pytest.approx([-x, 0.0, -h], abs=1e-8)
    assert block["chord_elevation_deg"] == pytest.approx(math.degrees(math.atan2(h, x)),
                                                         abs=1e-8)
    assert block["top_force_N"] == pytest.approx(list(F), abs=1e-12)
    assert s["shooting"].startswith("not applicable: lifter.top = 'lifted'")


def test_a_failed_lifted_solve_exits_1_with_advice(tmp_path):
    """Newton stopped early (-rawehelix_snes_max_it 2): exit 1, one line naming the
    lifted top and what to raise, nothing written."""
    import subprocess
    import sys
    run = subprocess.run(
        [sys.executable, "-m", "rawehelix.cli.main", "stationary", "stationary_table2",
         "--elements", "2", "--set", 'lifter.top="lifted"', "--set", "lifter.force_N=200",
         "-rawehelix_snes_max_it", "2", "-o", str(tmp_path / "OUT")],
        cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert run.returncode == 1, run.stderr
    lines = run.stderr.splitlines()
    assert len(lines) == 1 and "The lifted top found no stationary state" in lines[0]
    assert "raise lifter.force_N" in lines[0]
    assert list(tmp_path.iterdir()) == []


def test_operating_point_entry_takes_the_thrust_and_restarts_warm():
    """lifted.stationary(params, thrust_N, solver=...): the entry of the operating
    points.  A thrust along the chord and the rotor's weight, from the state of the last
    call (a warm start), put the top where the catenary under
    lifter + thrust + weight puts it."""
    p = _cable(4, twist=True).replace(  # a rotor's torque needs the twist (none here)
        lifter={"top": "lifted", "force_N": PULL_N, "elevation_deg": 45.0},
        rotor={"radius_m": 2.0, "mass_kg": 1.5, "tsr": (1.0, 5.0, 9.0),
                                 "cp": (0.1, 0.4, 0.1), "ct": (0.3, 0.8, 0.9)})
    solver, cold = lifted.stationary(p, comm=MPI.COMM_SELF)
    thrust = 60.0 * lifted.lifter_direction(40.0, 0.0)
    solver, warm = lifted.stationary(p, thrust_N=thrust, comm=MPI.COMM_SELF, solver=solver)
    F = PULL_N * lifted.lifter_direction(45.0, 0.0) + thrust + [0.0, 0.0, 1.5 * 9.81]
    x, h = catenary.top(-F[0], -F[2], p.helix.mass_kg * 9.81 / p.helix.length_m,
                        p.helix.EA_N, p.helix.length_m)
    assert warm.top_m == pytest.approx([-x, 0.0, -h], abs=1e-8)
    assert warm.result.newton_iterations <= cold.result.newton_iterations  # 4 and 4 at N = 4


def test_a_lifted_straight_helix_under_torque_twists_by_Q_L0_over_GJ():
    """Gravity and drag off, the rotor's torque at the lifted top, held by the ground:
    the rod stays straight along the pull and twists by Q L0 / GJ end to end."""
    import rawehelix as rh
    p = scene.load("stationary_table2", elements=4).replace(
        model={"gravity": False, "drag": False}, torque={"top_Nm": 25.0},
        lifter={"top": "lifted", "force_N": PULL_N, "elevation_deg": 60.0})
    s = rh.stationary(p, MPI.COMM_SELF).summary
    L0, GJ = p.helix.length_m, p.helix.GJ_Nm2
    assert s["torque"]["twist_end_to_end_rad"] == pytest.approx(25.0 * L0 / GJ, rel=1e-9)
    assert s["lifter"]["chord_elevation_deg"] == pytest.approx(60.0, abs=1e-9)


def test_thrust_along_the_end_tangent_is_a_follower_force():
    """The rotor's thrust F_t along its axis "tangent" turns with the end.  On a cable
    (no bending) n(L0) = T t(L0) = F_lifter + F_t t(L0), so t(L0) lies along the
    lifter's pull and the cable is the catenary pulled by (1 + F_t / |F_lifter|) times
    it: Irvine's closed form with 280 N at 45 deg for 200 N + 80 N."""
    p = _cable(4).replace(lifter={"top": "lifted", "force_N": PULL_N, "elevation_deg": 45.0})
    solver, out = lifted.stationary(p, comm=MPI.COMM_SELF, tangent_thrust_N=80.0)
    F = (PULL_N + 80.0) * lifted.lifter_direction(45.0, 0.0)
    x, h = catenary.top(-F[0], -F[2], p.helix.mass_kg * 9.81 / p.helix.length_m,
                        p.helix.EA_N, p.helix.length_m)
    assert out.top_m == pytest.approx([-x, 0.0, -h], abs=1e-8)
    assert out.end_tangent == pytest.approx(lifted.lifter_direction(45.0, 0.0), abs=1e-6)


@pytest.mark.mpi
def test_lifted_state_is_the_same_on_one_and_two_ranks():
    """Table 2's helix with wind, lifted by 200 N at 50 deg and twisted by 25 N m (a
    3D state): the top, its end tangent and the centre line on MPI.COMM_WORLD equal the
    serial ones (COMM_SELF on each rank) to 1e-10."""
    p = scene.load("stationary_table2", elements=4).replace(
        lifter={"top": "lifted", "force_N": PULL_N, "elevation_deg": 50.0},
        torque={"top_Nm": 25.0})
    _, serial = lifted.stationary(p, comm=MPI.COMM_SELF, top_torque_Nm=25.0)
    _, world = lifted.stationary(p, comm=MPI.COMM_WORLD, top_torque_Nm=25.0)
    assert np.max(np.abs(serial.top_m - world.top_m)) < 1e-10
    assert np.max(np.abs(serial.end_tangent - world.end_tangent)) < 1e-10
    if MPI.COMM_WORLD.rank == 0:
        assert np.max(np.abs(serial.result.centre_line - world.result.centre_line)) < 1e-10


def test_a_study_point_of_a_lifted_scene_is_the_catenary():
    """The studies' stationary stage (study, calibrate) solves the lifted top: T(0) of
    the lifted cable is the catenary's, |(H, V - W)| (the helix's weight W below the
    pull), and the sag is measured from the chord to where the top found itself."""
    from rawehelix.studies import quantities
    p = _cable(4).replace(lifter={"top": "lifted", "force_N": PULL_N, "elevation_deg": 45.0})
    values = quantities.evaluate(p, ["tension_s0_N", "sag_m"])
    F = PULL_N * lifted.lifter_direction(45.0, 0.0)
    W = p.helix.mass_kg * p.environment.g_m_s2
    # to the FE tension's error at N = 4 (1.7e-4 N, test_lifted_cable_is_the_elastic_catenary)
    assert values["values"]["tension_s0_N"] == pytest.approx(math.hypot(F[0], -F[2] - W), abs=3e-4)
    assert 0 < values["values"]["sag_m"] < 0.1
