"""'stationary' under the ends' torques (issue 41): a balanced end torque gives the
static twisted state (Omega = 0), a controller that spins the helix up is refused with
what to run; never a message that contradicts the scene."""

import json
import subprocess
import sys

import pytest
from mpi4py import MPI

from rawehelix.errors import SceneError
from rawehelix.studies import scene, stationary

CLI = [sys.executable, "-m", "rawehelix.cli.main"]


def _straight(N=4, **changes):
    """Table 2's helix without gravity and drag: straight, the twist decoupled."""
    p = scene.load("stationary_table2", elements=N)
    return p.replace(model={"gravity": False, "drag": False}, **changes)


@pytest.mark.parametrize("top_Nm, GJ", [(25.0, 140.0), (100.0, 800.0), (-40.0, 300.0)])
def test_twist_is_the_closed_form(top_Nm, GJ):
    """Solid section, gravity and drag off: alpha(L0) - alpha(0) = M L0 / GJ."""
    p = _straight(torque={"top_Nm": top_Nm}, helix={"GJ_Nm2": GJ})
    s = stationary.compute(p, MPI.COMM_SELF).summary
    closed = top_Nm * p.helix.length_m / GJ
    assert s["torque"]["twist_end_to_end_rad"] == pytest.approx(closed, rel=1e-9)
    assert s["torque"]["top_Nm"] == s["torque"]["ground_Nm"] == top_Nm
    assert "carry no torque" not in s["model"] and s["model"].startswith("full (r, alpha)")
    assert s["shooting"].startswith("not applicable: the state is twisted")


@pytest.mark.parametrize("controller", [{"k1": 0.5, "k2": 0.5, "target_rpm": 0.0},
                                        {"k1": 0.0, "k2": 0.5, "target_rpm": 120.0}])
def test_a_controller_whose_static_torque_balances_gives_the_twisted_state(controller):
    """Eq. (40) at rest: m0 = mN + k1 (alpha(0) - alpha_dot* t) + C is constant when
    k1 alpha_dot* = 0: the ground holds the rotor's torque; the sagging helix twists."""
    p = scene.load("stationary_table2", elements=4).replace(
        torque={"top_Nm": 25.0}, controller=controller)
    s = stationary.compute(p, MPI.COMM_SELF).summary
    assert s["torque"]["twist_end_to_end_rad"] == pytest.approx(
        25.0 * p.helix.length_m / p.helix.GJ_Nm2, rel=1e-3)
    assert "carry no torque" not in s["model"]


def test_a_torque_free_scene_stays_planar():
    s = stationary.compute(scene.load("stationary_table2", elements=4), MPI.COMM_SELF).summary
    assert s["torque"] is None and "carry no torque" in s["model"]


@pytest.mark.parametrize("name", ["nominal_operation", "mobile_end"])
def test_a_spinning_controller_is_refused_with_what_to_run(tmp_path, name):
    """k1 > 0 with a target spin: no static state; exit 2, one line that says why
    and the command that runs the spin-up, nothing written."""
    r = subprocess.run([*CLI, "stationary", name, "--elements", "2", "-o", str(tmp_path / "o")],
                       cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert r.returncode == 2
    assert len(r.stderr.splitlines()) == 1, r.stderr
    assert "controller.target_rpm" in r.stderr and "no static state" in r.stderr
    assert f"run 'rawehelix simulate {name} --until " in r.stderr
    assert not (tmp_path / "o").exists() and r.stdout == ""


def test_the_refusal_comes_before_any_work():
    p = scene.load("nominal_operation", elements=2)
    with pytest.raises(SceneError, match="spins the helix up to 120 rpm"):
        stationary.static_torque(p)


def test_a_hysteretic_twist_under_torque_is_refused():
    """Bouc-Wen torsion (rho < 1) is rate-independent: the static twist under a torque
    depends on its history; refused with what to run, not a state with z = 0."""
    p = scene.load("stationary_table2", elements=2).replace(
        torque={"top_Nm": 10.0}, torsion_hysteresis={"rho": 0.5, "beta_m_n": 0.5})
    with pytest.raises(SceneError, match="torsion_hysteresis.rho.*rawehelix simulate"):
        stationary.compute(p, MPI.COMM_SELF)
    torque_free = p.replace(torque={"top_Nm": 0.0})
    assert stationary.compute(torque_free, MPI.COMM_SELF).summary["torque"] is None
