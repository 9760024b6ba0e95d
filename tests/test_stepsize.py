"""The fixed-step criterion (solvers/stepsize.py): accepted steps, refused steps
and their message, and the refusal before any run in simulate and sweep."""

import math

import pytest
from mpi4py import MPI

from rawehelix.errors import SceneError
from rawehelix.solvers import analytic, stepsize
from rawehelix.studies import scene, simulate, sweep


def mobile(dt_s, **over):
    return scene.load("mobile_end", elements=2, overrides={"time.dt_s": dt_s, **over})


def test_limit_is_the_first_longitudinal_mode():
    """Sec. 5.3: omega_L = 2 pi 68.7 Hz (EA = 3.64e4 N, 0.25 kg over 7.9 m: the
    bar c / 2 L0 = 67.8 Hz, stiffened by the tension and the bending term)."""
    p = mobile(5e-4)
    q = p.normalised()
    lim = stepsize.limit(p)
    f_L = float(analytic.bar(q, 1, q.sigma * q.eps0)) / q.t_scale / (2 * math.pi)
    assert f_L == pytest.approx(68.66, abs=0.01)
    assert lim.omega_max_rad_s == pytest.approx(2 * math.pi * f_L)
    assert lim.dt_max_s == pytest.approx(stepsize.THETA_MAX / (2 * math.pi * f_L))
    assert "longitudinal" in lim.what


@pytest.mark.parametrize("dt_s", [2.5e-4, 5e-4, 1e-3, 2e-3])
def test_accepted(dt_s):
    assert stepsize.check(mobile(dt_s)).allows(dt_s)
    assert stepsize.check(mobile(dt_s), [0.5, 7.5, 15.0]) is not None


@pytest.mark.parametrize("dt_s", [5e-3, 1e-2])
def test_refused_names_the_key_the_limit_and_why(dt_s):
    with pytest.raises(SceneError) as err:
        stepsize.check(mobile(dt_s))
    e = err.value
    assert e.key == "time.dt_s" and e.path == "mobile_end"
    lim = stepsize.limit(mobile(dt_s))
    assert f"dt <= {lim.dt_max_s:.3g} s" in e.allowed
    assert "longitudinal mode (68.7 Hz" in e.allowed and f"{dt_s:g} s" in e.allowed


def test_a_fast_forcing_sets_the_limit():
    """Above omega_L the forcing itself sets the limit: f1 = 200 Hz at 1 ms is
    2 pi 0.2 = 1.26 rad per step."""
    p = mobile(1e-3)
    assert "forcing f1 = 200 Hz" in stepsize.limit(p, 200.0).what
    with pytest.raises(SceneError, match="forcing f1 = 200 Hz"):
        stepsize.check(p, [10.0, 200.0])
    stepsize.check(p.replace(time={"dt_s": 5e-4}), [10.0, 200.0])


def test_not_checked_without_fixed_steps():
    """A fixed upper end (Sec. 5.2: adaptive steps, dt_s is the first one), an
    adaptive run asked for, and the spline scheme (its own integrator)."""
    nominal = scene.load("nominal_operation", elements=2, overrides={"time.dt_s": 0.1})
    assert stepsize.check(nominal) is None
    assert stepsize.check(mobile(1e-2), fixed_steps=False) is None
    spline = scene.load("mobile_end", scheme="spline", elements=2, overrides={"time.dt_s": 1e-2})
    assert stepsize.check(spline, [7.5]) is None


def test_simulate_and_sweep_refuse_before_running(tmp_path):
    p = mobile(1e-2)
    with pytest.raises(SceneError, match="time.dt_s"):
        simulate.compute(p, until_s=0.1, comm=MPI.COMM_SELF, progress=False)
    with pytest.raises(SceneError, match="time.dt_s"):
        sweep.compute(p, [7.5], comm=MPI.COMM_SELF, checkpoint=tmp_path / "sw")
    assert not (tmp_path / "sw").exists()  # refused before the checkpoint is made
