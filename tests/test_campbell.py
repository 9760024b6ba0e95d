"""The Campbell diagram (studies/campbell.py) on the illustrative rotor scene, N = 4:
its limit Omega -> 0 against `modes` with the rotor's inertia lumped, the stability of
two coexisting operating points against the rigid shaft, and its outputs."""

import json

import numpy as np

import pytest
from mpi4py import MPI

import rawehelix as rh
from rawehelix.solvers.spin_modes import rod_polar_inertia_kgm2
from rawehelix.studies import campbell
from tests.test_docs import undocumented


def scene(**overrides):
    return rh.load_scene("rotor_example", elements=4, overrides=overrides or None)


def test_at_vanishing_wind_the_modes_are_those_with_the_rotor_lumped():
    """V = 1e-3 m/s (MPPT: Omega = 0.018 rpm, Q ~ V^2, dQ/dOmega and dtau/dOmega ~ V):
    every mode of the Campbell point equals `modes` of the torque-free state with the
    rotor's spin inertia lumped at the top, to 1e-6 (measured: 2.1e-7 at V = 1e-2,
    2.1e-11 at 1e-4: the end damping moves the frequencies by O(V^2))."""
    wind = 1e-3
    params = scene()
    reference = rh.modes(params.replace(wind={"speed_m_s": wind}), comm=MPI.COMM_SELF)
    point, = campbell.compute(params, [wind], comm=MPI.COMM_SELF).points
    assert {m["family"] for m in point.modes} == {"longitudinal", "lateral_in_plane",
                                                  "lateral_out_of_plane", "torsional"}
    for m in point.modes:
        ref = [r for r in reference if r.family == m["family"]][m["index"]]
        assert m["frequency_Hz"] == pytest.approx(ref.frequency_Hz, rel=1e-6), m
    # and the lumped inertia is in `modes`: the free-free shaft's first twist mode
    # (1.36 Hz with J = 1.2 kg m^2 at the top) is below the bare shaft's
    bare = rh.modes(params.replace(wind={"speed_m_s": wind}, rotor={"spin_inertia_kgm2": 0.0}),
                    comm=MPI.COMM_SELF)
    first = {r.family: r.frequency_Hz for r in reversed(reference)}["torsional"]
    assert first < 0.6 * {r.family: r.frequency_Hz for r in reversed(bare)}["torsional"]


def test_two_operating_points_and_their_stability():
    """A constant generator torque (20 N m) at 6.6 m/s meets the rotor's torque twice: at
    44 rpm, where dQ/dOmega > 0 = dtau/dOmega (unstable), and at 139 rpm (stable).  The
    growing root is the rigid shaft's (dQ/dOmega - dtau/dOmega) / (J + J_rod) within 2 %
    (measured 1.0 %: the shaft's flexibility)."""
    params = scene(**{"generator.law": "torque", "generator.torque_Nm": 20.0,
                      "generator.mppt_gain_Nms2": 0.0})
    result = campbell.compute(params, [6.6], comm=MPI.COMM_SELF)
    slow, fast = result.points
    assert (slow.branch, fast.branch) == (0, 1) and slow.rotor_rpm < fast.rotor_rpm
    assert (slow.stable, fast.stable) == (False, True)
    J = params.rotor.spin_inertia_kgm2 + rod_polar_inertia_kgm2(params.normalised())
    rigid = (slow.loads.rotor_dtorque_domega_Nms - slow.loads.generator_dtorque_domega_Nms) / J
    assert slow.max_real_part_per_s == pytest.approx(rigid, rel=0.02)
    assert fast.max_real_part_per_s <= 0


def test_outputs_list_the_crossings(tmp_path):
    """3 and 6 m/s: the blade passing line 3P passes the first lateral modes (4.57 Hz at
    91 rpm, between the points' 54 and 108 rpm); summary.json has every field
    documented, and the figure is written."""
    result = campbell.compute(scene(), [3.0, 6.0], comm=MPI.COMM_SELF)
    result.write(tmp_path)
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert undocumented(summary) == []
    lateral = [c for c in summary["crossings"] if c["line"] == "3P"
               and c["family"].startswith("lateral")]
    assert len(lateral) == 2
    for c in lateral:
        assert c["frequency_Hz"] == pytest.approx(3 * c["rotor_rpm"] / 60, rel=1e-12)
        assert 54 < c["rotor_rpm"] < 108 and 3.0 < c["wind_m_s"] < 6.0
    assert (tmp_path / "campbell.png").stat().st_size > 10_000


def test_a_scene_without_a_rotor_is_refused():
    with pytest.raises(rh.SceneError, match=r"'operate' needs a \[rotor\] section"):
        campbell.compute(rh.load_scene("stationary_table2", elements=2), [5.0])


def test_one_rod_serves_every_wind():
    """The point solvers reuse one rod across wind speeds (only v_w0 changes): the modes
    at 6 m/s after 3 m/s are those of fresh solvers at 6 m/s, bit for bit; a scene that
    changes another group is refused by the rod (and gets its own)."""
    from rawehelix.solvers.spin_modes import EndLoads
    from rawehelix.studies import operate
    params = scene()
    loads = EndLoads(rotor_inertia_kgm2=1.2, rotor_dtorque_domega_Nms=-0.5,
                     generator_dtorque_domega_Nms=2.0)
    reused = campbell.PointSolvers(MPI.COMM_SELF, "t")
    reused.modes(operate.at_wind(params, 3.0), 6.0, 5.0, loads)
    _, again = reused.modes(operate.at_wind(params, 6.0), 11.0, 20.0, loads)
    _, fresh = campbell.PointSolvers(MPI.COMM_SELF, "t").modes(operate.at_wind(params, 6.0),
                                                                11.0, 20.0, loads)
    assert [m.eigenvalue for m in again] == [m.eigenvalue for m in fresh]
    with pytest.raises(ValueError, match=r"changes \[.delta., .mu.\]"):  # EI: mu, delta
        reused.stationary.rod.set_wind(params.replace(helix={"EI_Nm2": 9000.0}))


def two_inertias(J_top, J_ground, k, K1, K2, dQ) -> float:
    """max Re lambda [1/s] of a two-inertia shaft: the rotor's J_top at the top, J_ground
    at the ground, the helix a torsional spring k = GJ/L0 between them, the ground held by
    Eq. (40)'s K1 (spring) and K2 (damper), the rotor's torque slope dQ at the top."""
    M = np.diag([J_top, J_ground])
    C = np.array([[-dQ, 0.0], [0.0, K2]])
    K = np.array([[k, -k], [-k, k + K1]])
    A = np.block([[np.zeros((2, 2)), np.eye(2)],
                  [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    return float(np.linalg.eigvals(A).real.max())


def test_the_paper_law_loses_the_rotor_mode_the_rigid_shaft_keeps():
    """The paper's law (k1 = k2 = 0.5, 120 rpm) holds the rotor at 120 rpm; as the wind
    rises the tip-speed ratio falls and dQ/dOmega turns positive.  The rigid shaft's
    slope dQ/dOmega - K2 stays negative (operate: stable), but K2 acts at the ground and
    the rotor's mode (J on the helix's twist spring, 0.3 Hz) lives at the top: at 11 m/s
    it grows.  A two-inertia model (half the helix's inertia at each end, numpy) gives
    the same growth rates within 0.06 /s (measured at N = 8: -0.685 / -0.645 at 9 m/s,
    +0.202 / +0.217 at 11 m/s)."""
    params = scene(**{"generator.law": "paper", "generator.mppt_gain_Nms2": 0.0,
                      "controller.k1": 0.5, "controller.k2": 0.5, "controller.target_rpm": 120.0})
    result = campbell.compute(params, [9.0, 11.0], comm=MPI.COMM_SELF)
    q = params.normalised()
    J_rod, k = rod_polar_inertia_kgm2(q), q.torque_scale
    K1, K2 = 0.5 * q.torque_scale, 0.5 * q.torque_scale * q.t_scale  # Eq. (40) in SI
    for point in result.points:
        dQ = point.loads.rotor_dtorque_domega_Nms
        assert dQ - K2 < 0  # the rigid shaft: stable at both
        lumped = two_inertias(params.rotor.spin_inertia_kgm2 + J_rod / 2, J_rod / 2, k, K1, K2, dQ)
        assert point.max_real_part_per_s == pytest.approx(lumped, abs=0.06), point.wind_m_s
        assert point.stable == (lumped < 0)
    assert [p.stable for p in result.points] == [True, False]
