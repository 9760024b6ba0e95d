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


def _torque_scene(tmp_path, torque_Nm):
    """rotor_example with a constant generator torque (its own folder: the table's path
    is relative to the scene)."""
    shutil.copy(SCENES / "rotor_example.csv", tmp_path / "rotor_example.csv")
    text = (SCENES / "rotor_example.toml").read_text()
    head, _, rest = text.partition("[generator]")
    _, _, tail = rest.partition("[wind]")
    scene = tmp_path / "torque.toml"
    scene.write_text(head + f'[generator]\nlaw = "torque"\ntorque_Nm = {torque_Nm}\n\n[wind]' + tail)
    return scene


@pytest.mark.parametrize("wind, says", [
    ("4:x", "--wind: 4:x: must be LO:HI:STEP in m/s"),
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
