"""`rawehelix operate` (issue 43, part 2) on the illustrative rotor's scene
(studies/scenes/rotor_example.toml) at small N: summary.json's points carry exactly the
issue's keys and agree with the rigid shaft where they must; the limits block names the
first limit; bad --wind and wind speeds outside the rotor's table exit 2 in one line,
writing nothing."""

import json
import math
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from mpi4py import MPI

import rawehelix as rh
from rawehelix.operation import rigid_shaft
from rawehelix.operation.generator import GeneratorLaw
from rawehelix.operation.rotor import from_params as rotor_of
from rawehelix.studies import operate

CLI = [sys.executable, "-m", "rawehelix.cli.main"]
SCENES = Path(rh.__file__).parent / "studies" / "scenes"


def test_summary_points_have_exactly_the_issues_keys(tmp_path):
    out = tmp_path / "o"
    r = subprocess.run([*CLI, "operate", "rotor_example", "--elements", "2", "--wind", "4:8:2",
                        "-o", str(out)], cwd=tmp_path, capture_output=True, text=True,
                       timeout=200)
    assert r.returncode == 0, r.stderr
    s = json.loads((out / "summary.json").read_text())
    assert [sorted(p) for p in s["points"]] == [sorted(operate.POINT_KEYS)] * 3
    assert [p["wind_m_s"] for p in s["points"]] == [4.0, 6.0, 8.0]
    assert "first_limit" in s["limits"] and "min_member_force_N" in s["limits"]
    assert (out / "power_curve.png").stat().st_size > 10_000
    # the progress lines are on stderr, the answer on stdout
    assert "operate: 4 m/s" in r.stderr and "first limit:" in r.stdout
    for p, d in zip(s["points"], s["details"]):
        omega = p["rotor_rpm"] * math.pi / 30
        assert p["power_W"] == pytest.approx(p["torque_ground_Nm"] * omega, rel=1e-12)
        assert p["torque_ground_Nm"] == pytest.approx(p["torque_top_Nm"], rel=1e-12)  # no loss
        assert p["stable"] and p["branch"] == 0
        assert d["stationary_solves"] <= 3


def test_mppt_runs_at_the_best_tip_speed_ratio_and_the_first_limit_stops_the_curve():
    """MPPT at the rotor's optimal gain: tsr = tsr_opt and P = 1/2 rho pi R^2 V_n^3 Cp_max
    at every point (V_n the solved top tangent's); the curve ends at the first point with
    a limit, which summary['first_limit'] names with its wind speed."""
    p = rh.load_scene("rotor_example", elements=2)
    rotor = rotor_of(p)
    k = 0.5 * 1.225 * math.pi * rotor.radius_m**5 * rotor.cp_max / rotor.tsr_opt**3
    p = p.replace(generator={"mppt_gain_Nms2": k})
    res = rh.operate(p, [6.0, 9.0, 12.0, 15.0], comm=MPI.COMM_SELF)
    s = res.summary
    for e, d in zip(s["points"], s["details"]):
        assert e["tsr"] == pytest.approx(rotor.tsr_opt, rel=1e-9)
        assert e["power_W"] == pytest.approx(
            0.5 * 1.225 * math.pi * rotor.radius_m**2 * d["v_n_m_s"]**3 * rotor.cp_max, rel=1e-9)
        # the same point as the rigid shaft's at that V_n (operation/rigid_shaft.py)
        (want,) = rigid_shaft.operating_points(rotor, GeneratorLaw("mppt", mppt_gain_Nms2=k),
                                               d["v_n_m_s"], 1.225)
        assert e["rotor_rpm"] == pytest.approx(want.rotor_rpm, rel=1e-9)
    first = s["first_limit"]
    assert first is not None and first["wind_m_s"] == s["points"][-1]["wind_m_s"]
    assert all(d["first_limit"] is None for d in s["details"][:-1])
    assert first["kind"] in s["stopped"]


def _torque_scene(tmp_path, torque_Nm, table=None):
    """rotor_example with a constant generator torque (its own folder: the table's path
    is relative to the scene); ``table``: (tsr, cp, ct) instead of rotor_example.csv."""
    if table is None:
        shutil.copy(SCENES / "rotor_example.csv", tmp_path / "rotor_example.csv")
    else:
        rows = "\n".join(f"{x!r},{y!r},{z!r}" for x, y, z in zip(*table))
        (tmp_path / "rotor_example.csv").write_text("tsr,cp,ct\n" + rows + "\n")
    text = (SCENES / "rotor_example.toml").read_text()
    head, _, rest = text.partition("[generator]")
    _, _, tail = rest.partition("[wind]")
    scene = tmp_path / "torque.toml"
    scene.write_text(head + f'[generator]\nlaw = "torque"\ntorque_Nm = {torque_Nm}\n\n[wind]' + tail)
    return scene


def test_coexisting_stable_points_are_all_in_points_with_their_branch(tmp_path):
    """A rotor whose torque coefficient Cq = Cp / tsr has several humps, under a constant
    5 N m: at one wind the balance has several roots; every one is a point of
    summary.json, the stable ones on different branches, and their spins are scipy's
    roots of 1/2 rho pi R^3 V_n^2 Cq(tsr) = 5 N m at the point's V_n."""
    import numpy as np
    import scipy.interpolate
    import scipy.optimize
    lam = np.linspace(0.5, 10.0, 96)
    cq = 0.03 + 0.012 * np.sin(lam * 2 * np.pi / 4.0) - 0.002 * lam
    scene = _torque_scene(tmp_path, 5.0, (lam, cq * lam, 0.5 + 0 * lam))
    res = rh.operate(rh.load_scene(str(scene), elements=2), [5.5], comm=MPI.COMM_SELF)
    pts, det = res.summary["points"], res.summary["details"]
    stable = [p["branch"] for p in pts if p["stable"]]
    assert len(stable) >= 2 and len(set(stable)) == len(stable)
    v_n = det[0]["v_n_m_s"]
    assert all(d["v_n_m_s"] == pytest.approx(v_n, rel=1e-9) for d in det)  # one torque
    Cp = scipy.interpolate.PchipInterpolator(lam, cq * lam)
    c = 0.5 * 1.225 * math.pi * 2.0**3 * v_n**2
    f = lambda x: c * Cp(x) / x - 5.0  # noqa: E731
    x = np.linspace(lam[0], lam[-1], 4001)
    g = f(x)
    roots = [scipy.optimize.brentq(f, x[i], x[i + 1], xtol=1e-15) * v_n / 2.0
             for i in np.flatnonzero(np.sign(g[:-1]) != np.sign(g[1:]))]
    got = sorted(p["rotor_rpm"] * math.pi / 30 for p in pts)
    assert got == pytest.approx(roots, rel=1e-9)


@pytest.mark.parametrize("wind, says", [  # a malformed --wind: tests/test_faults.py's row
    ("9:4:1", "must be LO:HI:STEP with 0 < LO <= HI and STEP > 0"),
    ("1:12:1", "no operating point of the rotor and generator inside the rotor's table"),
])
def test_bad_wind_exits_2_in_one_line_and_writes_nothing(tmp_path, wind, says):
    """The constant 25 N m generator: below its cut-in the rotor's torque never reaches
    25 N m inside the table: those wind speeds are outside the table's operating points."""
    scene = _torque_scene(tmp_path, 25.0)
    r = subprocess.run([*CLI, "operate", str(scene), "--elements", "2", "--wind", wind,
                        "-o", str(tmp_path / "o")], cwd=tmp_path, capture_output=True,
                       text=True, timeout=200)
    assert r.returncode == 2, r.stderr
    assert len(r.stderr.splitlines()) == 1 and says in r.stderr, r.stderr
    assert not (tmp_path / "o").exists() and not (tmp_path / "results").exists()
    if "table" in says:  # it says where the operating points are
        assert "they have operating points from" in r.stderr and "1, 2, 3, 4 and" in r.stderr


@pytest.mark.parametrize("changes, says", [
    ({"ends": {"circle_radius_m": 0.1, "circle_frequency_Hz": 1.0}},
     "ends.circle_radius_m: 0.1 > 0: the circle of Eq. (70) moves the top end"),
    ({"lifter": {"top": "lifted", "force_N": 10.0}},
     "lifter.force_N: the lifter cannot hold the helix up"),
    ({"torsion_hysteresis": {"rho": 0.5, "beta_m_n": 0.5}},
     "torsion_hysteresis.rho: 0.5 < 1 (hysteretic torsion)"),
    ({"discretisation": {"scheme": "spline"}},
     "discretisation.scheme: 'spline': 'operate' solves the FE rod's relative equilibria"),
])
def test_what_operate_cannot_solve_is_refused_before_any_work(changes, says):
    p = rh.load_scene("rotor_example", elements=2).replace(**changes)
    with pytest.raises(rh.SceneError, match=says.replace("(", r"\(").replace(")", r"\)")):
        operate.plan(p, [5.0])


def test_the_figure_names_the_branches_the_fold_and_the_first_limit(tmp_path, monkeypatch):
    """power_curve.png from a summary with a stable and an unstable branch: each branch
    in the legend once, the unstable one dashed, the fold and the first limit drawn."""
    from rawehelix.studies.present import operate_figure
    from rawehelix.studies.store import writers
    kept = {}
    finish = writers._finish
    monkeypatch.setattr(writers, "_finish",
                        lambda fig, path, title: kept.setdefault("fig", fig) and finish(fig, path, title))
    s = json.loads((Path(rh.__file__).parent / "docs" / "operate" / "torque_N8" /
                    "summary.json").read_text())
    s["folds"][0]["wind_m_s"] = 7.0  # inside the plotted winds
    operate_figure.power_curve_png(tmp_path / "p.png", s, "t")
    top = kept["fig"].axes[0]
    labels = top.get_legend_handles_labels()[1]
    assert labels == ["branch 0", "branch 1", "fold", "unstable (dashed)"]
    styles = {line.get_label(): line.get_linestyle() for line in top.lines}
    assert styles["branch 0"] == "-" and styles["branch 1"] == "--"
    assert any(abs(line.get_xdata()[0] - 11.0) < 1e-12 and line.get_linestyle() == ":"
               for line in top.lines)  # the first limit's wind speed
    assert any("first limit: slack" in t.get_text() for t in top.texts)
    assert (tmp_path / "p.png").stat().st_size > 10_000


def test_stable_is_the_linearisations_not_the_rigid_shafts():
    """The paper's law (k1 = k2 = 0.5, 120 rpm): the rigid shaft's slope dQ/dOmega - K2
    stays negative at 9 and 11 m/s, but the rotor's 0.3 Hz mode on the helix's twist
    grows at 11 m/s (docs/explanation/campbell.md): operate's ``stable`` says so, and its
    growth rate is the two-inertia model's (numpy, tests/test_campbell.py) within 0.06 /s
    (measured at N = 4: -0.66 / -0.65 at 9 m/s, +0.20 / +0.22 at 11 m/s)."""
    from rawehelix.solvers.spin_modes import rod_polar_inertia_kgm2
    from tests.test_campbell import two_inertias
    params = rh.load_scene("rotor_example", elements=4, overrides={
        "generator.law": "paper", "generator.mppt_gain_Nms2": 0.0, "controller.k1": 0.5,
        "controller.k2": 0.5, "controller.target_rpm": 120.0})
    result = operate.compute(params, [9.0, 11.0], comm=MPI.COMM_SELF)
    s = result.summary
    assert [p["stable"] for p in s["points"]] == [True, False]
    assert [d["rigid_shaft_stable"] for d in s["details"]] == [True, True]
    q = params.normalised()
    J_rod, k = rod_polar_inertia_kgm2(q), q.torque_scale
    K1, K2 = 0.5 * q.torque_scale, 0.5 * q.torque_scale * q.t_scale  # Eq. (40) in SI
    rotor = rotor_of(params)
    for p, d in zip(result.points, s["details"]):
        dQ = rotor.dtorque_domega(p.omega_rad_s, p.v_n_m_s, 1.225)
        lumped = two_inertias(params.rotor.spin_inertia_kgm2 + J_rod / 2, J_rod / 2, k, K1,
                              K2, dQ)
        assert d["max_real_part_per_s"] == pytest.approx(lumped, abs=0.06), p.wind_m_s


def test_the_spin_drag_takes_its_loss_between_the_rotor_and_the_ground():
    """``[spin_drag]`` on (a thick tether, d = 2 cm), gravity and drag off (a straight
    solid helix): the ground's torque is Q - c L0 Omega|Omega| (parameters/spin_drag.py's
    loss), the point still balances Q = tau_gen + loss, and the twist end to end is the
    closed form of a linearly varying torque (tests/test_spin_drag.py), to 1e-9."""
    from rawehelix.parameters import spin_drag
    from tests.test_spin_drag import linear_torque_twist
    params = rh.load_scene("rotor_example", elements=4, overrides={
        "spin_drag.tether_diameter_m": 0.02, "model.gravity": False, "model.drag": False})
    point, = operate.compute(params, [6.0], comm=MPI.COMM_SELF).points
    omega, Q = point.omega_rad_s, point.torque_top_Nm
    loss = float(spin_drag.loss_of(params).torque(omega))
    assert loss > 0.03 * Q  # seen, not lost in the tolerance
    assert point.torque_ground_Nm == pytest.approx(Q - loss, rel=1e-12)
    tau = GeneratorLaw("mppt", mppt_gain_Nms2=params.generator.mppt_gain_Nms2).torque(omega)
    assert Q == pytest.approx(tau + loss, rel=1e-9)
    L0, GJ = params.helix.length_m, params.helix.GJ_Nm2
    closed = linear_torque_twist(L0, Q, spin_drag.coefficient(params), omega, L0, GJ)
    assert point.twist_rad == pytest.approx(closed, rel=1e-9)


def lifted_scene(N=2, **changes):
    """rotor_example with its top lifted by 300 N at 50 deg (MPPT)."""
    return rh.load_scene("rotor_example", elements=N).replace(
        lifter={"top": "lifted", "force_N": 300.0, "elevation_deg": 50.0}, **changes)


def test_a_lifted_top_takes_the_thrust_into_the_tension():
    """``lifter.top = "lifted"``: each point is the lifted stationary state under the
    rotor's torque and its thrust along the solved end tangent (solvers/lifted.py), so
    the tension at the ground rises with the thrust; the point's top is where a lifted
    stationary solve from the chord under the same thrust and torque puts it (1e-8 m),
    V_n is the wind along that solved end tangent, and the verdict is the rigid shaft's."""
    from rawehelix.solvers import lifted
    params = lifted_scene()
    result = operate.compute(params, [5.0, 8.0], comm=MPI.COMM_SELF)
    (low, high), details = result.points, result.summary["details"]
    assert high.thrust_N > low.thrust_N + 50
    ground = [d["tension_ground_N"] for d in details]
    # the ground's tension takes the extra thrust (within the lifter's turn and the drag)
    assert ground[1] - ground[0] == pytest.approx(high.thrust_N - low.thrust_N, rel=0.2)
    for p, d in zip(result.points, details):
        assert d["stability_from"] == "rigid shaft" and p.stable == p.rigid_shaft_stable
        at = operate.at_wind(params, p.wind_m_s)
        _, alone = lifted.stationary(at, comm=MPI.COMM_SELF, top_torque_Nm=p.torque_top_Nm,
                                     omega_rad_s=p.omega_rad_s, tangent_thrust_N=p.thrust_N)
        assert d["top_m"] == pytest.approx(alone.top_m, abs=1e-8)
        assert p.v_n_m_s == pytest.approx(p.hub_wind_m_s * abs(alone.end_tangent[0]), rel=1e-8)


def test_a_scene_given_by_its_tension_runs_with_the_elongation_found_once(tmp_path):
    """A designer's scene gives ``ends.tension_N`` (it failed with a traceback: the wind of
    each point dropped the elongation found for the scene's own wind).  The helix is
    anchored once: every point runs at the elongation found at the scene's wind, which
    gives the asked mean tension there."""
    from rawehelix.solvers import tension_target
    from rawehelix.studies import operate as study
    shipped = Path(rh.__file__).parent / "studies" / "scenes"
    text = (shipped / "rotor_example.toml").read_text()
    scene = tmp_path / "own.toml"
    scene.write_text(text.replace("elongation = 0.0055", "tension_N = 210.0"))
    shutil.copy(shipped / "rotor_example.csv", tmp_path)
    p = rh.load_scene(scene, elements=2)
    assert not p.ends.resolved
    result = rh.operate(p, [5.0, 6.0], comm=MPI.COMM_SELF)
    assert [pt["wind_m_s"] for pt in result.summary["points"]] == [5.0, 6.0]
    found = tension_target.resolve(p, MPI.COMM_SELF).ends.elongation
    for V in (5.0, 6.0):
        at = study.at_wind(tension_target.resolve(p, MPI.COMM_SELF), V)
        assert at.ends.elongation == found and at.ends.resolved
