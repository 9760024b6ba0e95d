"""ends.tension_N (issue 41): the elongation whose stationary state has the scene's
mean tension, found once (solvers/tension_target.py) and used by every command."""

import json
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI
from scipy.integrate import quad

import rawehelix as rh
from rawehelix.parameters import ParameterError
from rawehelix.references import shooting
from rawehelix.solvers import tension_target
from rawehelix.studies import quantities, scene
from tests_util import write_scene

OWN = Path(__file__).parent / "data" / "own_helix.toml"
CLI = [sys.executable, "-m", "rawehelix.cli.main"]


def _run(args, cwd):
    return subprocess.run([*CLI, *args], cwd=cwd, capture_output=True, text=True, timeout=300)


def _mean_stationary_tension(params) -> float:
    """The mean tension [N] of the FE stationary state of ``params`` (with its elongation)."""
    from rawehelix.studies import stationary
    solver, _, _ = stationary.solve(params, MPI.COMM_SELF)
    return float(params.normalised().tension_N(solver.mean_tension()))


def test_the_own_helix_gets_its_tension():
    """The user's helix of issue 41 (30 m, 3 kg, R = 0.5 m, T = 500 N): the elongation
    found gives 500 N to RTOL; the hand-computed T / EA misses it by far more."""
    params = scene.load(OWN, elements=8)
    assert not params.ends.resolved
    found = tension_target.find(params, MPI.COMM_SELF)
    assert found.mean_tension_N == pytest.approx(500.0, rel=tension_target.RTOL)
    resolved = tension_target.resolve(params, MPI.COMM_SELF)
    assert resolved.ends.elongation == found.elongation and resolved.ends.tension_N == 500.0
    # an independent evaluation of the state at that elongation: a fresh solve
    assert _mean_stationary_tension(resolved) == pytest.approx(500.0, rel=1e-9)
    by_hand = params.replace(ends={"elongation": 500.0 / params.helix.EA_N})
    assert abs(_mean_stationary_tension(by_hand) - 500.0) > 1.0  # the dead end


@pytest.mark.parametrize("tension_N", [150.0, 400.0])
def test_the_tension_found_is_the_shooting_references(tension_N):
    """Independent of the FE: the shooting solution of Sys. (67) at the elongation
    found has the asked mean tension (int_0^1 T ds by quadrature) to the FE's
    discretisation error."""
    params = scene.load("stationary_table2", elements=16).replace(ends={"tension_N": tension_N})
    resolved = tension_target.resolve(params, MPI.COMM_SELF)
    q = resolved.normalised()
    ref = shooting.solve(q)
    mean, _ = quad(lambda s: float(ref.tension(np.array([s]))[0]), 0.0, 1.0, limit=200)
    assert float(q.tension_N(mean)) == pytest.approx(tension_N, rel=1e-5)


def test_a_weightless_straight_rod_has_T_equal_EA_eps():
    """Closed form: without gravity and drag the rod is straight, T = EA eps0."""
    params = scene.load("stationary_table2", elements=4).replace(
        ends={"tension_N": 321.0}, model={"gravity": False, "drag": False})
    resolved = tension_target.resolve(params, MPI.COMM_SELF)
    assert resolved.ends.elongation == pytest.approx(321.0 / params.helix.EA_N, rel=1e-9)


def test_the_elongation_is_found_again_when_the_state_moves():
    """Parameters.replace drops the elongation found when a change moves the
    stationary state, keeps it otherwise; a given elongation drops the tension."""
    params = tension_target.resolve(
        scene.load("stationary_table2", elements=4).replace(ends={"tension_N": 200.0}),
        MPI.COMM_SELF)
    assert params.ends.resolved
    for kept in ({"discretisation": {"elements": 8}}, {"time": {"dt_s": 1e-4}},
                 {"torque": {"top_Nm": 5.0}}, {"ends": {"circle_radius_m": 0.1}}):
        assert params.replace(**kept).ends.elongation == params.ends.elongation, kept
    for moved in ({"helix": {"EA_N": 4e4}}, {"environment": {"wind_speed_m_s": 3.0}},
                  {"model": {"gravity": False}}, {"ends": {"elevation_deg": 30.0}},
                  {"ends": {"tension_N": 250.0}}):
        p = params.replace(**moved)
        assert not p.ends.resolved, moved
        with pytest.raises(ParameterError, match="ends.tension_N"):
            p.normalised()  # never the stale elongation, never T / EA
    given = params.replace(ends={"elongation": 0.004})
    assert given.ends.tension_N is None and given.ends.elongation == 0.004
    # the fingerprint is the scene's input, not what a solve found
    assert params.as_dict()["ends"]["elongation"] is None


def test_a_study_point_finds_its_own_elongation():
    """study/calibrate points (quantities.evaluate) resolve each point's scene."""
    params = scene.load("stationary_table2", elements=4).replace(ends={"tension_N": 250.0})
    out = quantities.evaluate(params, ["tension_s0_N"])
    assert out["errors"] == {}
    assert out["values"]["tension_s0_N"] == pytest.approx(250.0, rel=0.02)


def test_commands_run_a_tension_scene(tmp_path):
    """stationary (CLI: both figures in summary.json and on screen) and modes (API)."""
    r = _run(["stationary", str(OWN), "--elements", "4", "-o", str(tmp_path / "st")], tmp_path)
    assert r.returncode == 0, r.stderr
    s = json.loads((tmp_path / "st" / "summary.json").read_text())
    assert s["ends"]["tension_N"] == 500.0 and s["ends"]["elongation"] > 0
    assert s["ends"]["tension_at"] == tension_target.WHERE
    assert "ends.tension_N = 500 N (mean over s of the torque-free state): elongation found" \
        in r.stdout
    modes = rh.modes(rh.load_scene(OWN, elements=4), count=4, comm=MPI.COMM_SELF)
    assert len(modes) == 4 and all(m.frequency_Hz >= 0 for m in modes)
    # a forced scene: its response about the state with the end at the circle's centre
    # (which keeps the elongation found: it is found there)
    forced = rh.load_scene("mobile_end", elements=4).replace(ends={"tension_N": 75.0})
    response = rh.response(forced, f1_Hz=[5.0], comm=MPI.COMM_SELF)
    assert response.tension_amplitude_N[0] > 0


@pytest.mark.parametrize("ends, given", [({"tension_N": 200.0}, "both"),
                                         (None, "neither")])
def test_exactly_one_of_elongation_and_tension(tmp_path, ends, given):
    """Both or neither: one line on stderr naming the two keys, exit 2, nothing written."""
    data = tomllib.loads(scene.resolve("stationary_table2").read_text())
    if ends is None:
        del data["ends"]["elongation"]
    path = write_scene(tmp_path / "s.toml", {"ends": ends or {}}, base=data)
    r = _run(["stationary", str(path), "--elements", "2", "-o", str(tmp_path / "o")], tmp_path)
    assert r.returncode == 2
    assert len(r.stderr.splitlines()) == 1, r.stderr
    assert "ends.elongation" in r.stderr and "ends.tension_N" in r.stderr
    assert f"the scene gives {given}" in r.stderr
    assert not (tmp_path / "o").exists()


def test_an_elongation_scene_keeps_its_fingerprint():
    """ends.tension_N is a later switch: absent from as_dict at None, so the results
    stored before it (sweep checkpoints, converge's runs/) keep their fingerprints."""
    ends = scene.load("stationary_table2").as_dict()["ends"]
    assert "tension_N" not in ends and ends["elongation"] == 0.0055
