"""The ``limits`` block in stationary and simulate results and the API's (issue 29):
present with its keys, and its member forces those of statics, f = N/n - 2 M/(n R)
for the innermost member of a ring of n tethers at radius R (beta = 0, no
self-stress: the default [section]), checked on the run's own tension and moment
ratio; slack where and when that force first falls to zero."""

from __future__ import annotations

import h5py
import numpy as np
import pytest

import rawehelix as rh
from rawehelix.solvers.snes import SolverError
from rawehelix.studies import simulate as simulate_study
from rawehelix.studies.analysis.structure_limits import Tracker

KEYS = {"law", "members", "min_member_force_N", "max_member_force_N", "slack_fraction_max",
        "moment_ratio_max", "moment_without_tension", "twist_per_length_max", "first_limit",
        "first_by_kind", "criteria", "sampled_every_s"}


def _statics_min(tension_N, ratio, members):
    """The innermost member's force of statics: N/n - 2 M/(n R), M = ratio N R."""
    return tension_N / members["tethers"] * (1 - 2 * ratio)


def test_stationary_block_is_statics_of_its_state():
    # (mobile_end's controller spins it up: 'stationary' refuses it; without torque it
    # is the torque-free state off the x-z plane its runs start from)
    st = rh.stationary(rh.load_scene("mobile_end", elements=4, overrides={
        "controller.target_rpm": 0.0, "torque.top_Nm": 0.0}))
    b = st.summary["limits"]
    assert set(b) == KEYS and b["law"] == "solid"
    ratio = b["moment_ratio_max"]
    assert ratio["t_s"] is None and 0 < ratio["value"] < 0.5
    assert 0.3 * st.s_m[-1] < ratio["s_m"] < 0.7 * st.s_m[-1]  # mid-span (the sag's largest bend)
    assert b["first_limit"] is None and b["slack_fraction_max"] == 0
    # at the section of the largest ratio the smallest force is the inner member's
    T = np.interp(ratio["s_m"], st.s_tension_m, st.tension_N)
    fmin = b["min_member_force_N"]
    assert fmin["s_m"] == ratio["s_m"]
    assert fmin["value"] == pytest.approx(_statics_min(T, ratio["value"], b["members"]), rel=1e-6)


@pytest.fixture(scope="module")
def jolted():
    """mobile_end's start (the end's circle switched on at once, Eq. 70) bends the
    coarse rod past the slack of the inner member within milliseconds: a frame at
    every output step."""
    scene = rh.load_scene("mobile_end", elements=4, overrides={"time.fields_every_s": 0.002})
    every, simulate_study.LIMITS_EVERY = simulate_study.LIMITS_EVERY, 1  # every output step
    try:
        return rh.simulate(scene, until_s=0.01, progress=False)
    finally:
        simulate_study.LIMITS_EVERY = every


def test_simulate_reports_slack_where_and_when_statics_says(jolted, tmp_path):
    ts = jolted
    b = ts.summary["limits"]
    assert set(b) == KEYS and b["sampled_every_s"] is None
    assert len(ts.limits_history) == len(ts.t_s)  # every output step
    members = b["members"]
    first = None
    for f in ts.frames:  # statics on the frame's own arrays
        fmin = _statics_min(f.tension_N, f.moment_ratio, members)
        np.testing.assert_allclose(f.member_force_min_N, fmin, rtol=1e-9, atol=1e-9)
        if first is None and (fmin <= 0).any():
            first = {"kind": "slack", "s_m": float(f.s_m[np.argmax(fmin <= 0)]), "t_s": f.t_s}
    assert first is not None, "the jolt must slacken a member for this test to mean anything"
    assert b["first_limit"] == pytest.approx(first)
    assert b["slack_fraction_max"] > 0
    assert b["min_member_force_N"]["value"] == pytest.approx(
        min(f.member_force_min_N.min() for f in ts.frames))
    # the XDMF carries the members' fields per frame
    ts.write(tmp_path, pictures=True, gif=False)
    with h5py.File(tmp_path / "centre_line.h5") as h5:
        for k, f in enumerate(ts.frames):
            np.testing.assert_allclose(h5[f"step{k}/member_force_min_N"][()], f.member_force_min_N)
            np.testing.assert_allclose(h5[f"step{k}/moment_ratio"][()], f.moment_ratio)
            assert f"step{k}/member_force_max_N" in h5
    assert "member_force_max_N" in (tmp_path / "centre_line.xdmf").read_text()
    assert (tmp_path / "members.png").stat().st_size > 0


def test_the_block_is_the_trackers_of_the_frames(jolted):
    """The same block from the frames' arrays through a fresh Tracker (every output
    step is a frame here)."""
    ts = jolted
    members = ts.params.model.section.members(ts.params.helix)
    tr = Tracker(members)
    R, n = members.R, members.n
    for f in ts.frames:
        tr.add(f.s_m, f.tension_N, f.moment_ratio * f.tension_N * R, np.zeros_like(f.s_m),
               f.twist_rad_per_m, t_s=f.t_s)
    b, ref = ts.summary["limits"], tr.block()
    for key in ("min_member_force_N", "max_member_force_N", "moment_ratio_max", "first_limit"):
        assert b[key] == pytest.approx(ref[key], rel=1e-9), key
    assert b["slack_fraction_max"] == pytest.approx(ref["slack_fraction_max"])
    assert n == b["members"]["tethers"]


def test_a_failed_run_carries_the_block_up_to_its_last_good_state(monkeypatch):
    from rawehelix.solvers.dynamics import DynamicsSolver
    advance = DynamicsSolver.advance

    def failing(self, until, on_output=None, output_every=None, on_step=None):
        advance(self, 0.004 / self.q.t_scale, on_output=on_output, output_every=output_every,
                on_step=on_step)
        raise SolverError("a test's failure")

    monkeypatch.setattr(DynamicsSolver, "advance", failing)
    with pytest.raises(simulate_study.SimulationError) as err:
        rh.simulate(rh.load_scene("mobile_end", elements=4), until_s=0.01, progress=False)
    partial = err.value.partial
    b = partial.summary["limits"]
    assert set(b) == KEYS and not partial.summary["complete"]
    np.testing.assert_allclose(partial.limits_history[:, 0],
                               partial.t_s[::simulate_study.LIMITS_EVERY])
    assert len(partial.t_s) > 1
    assert b["max_member_force_N"]["t_s"] <= partial.t_s[-1] + 1e-12


def test_the_block_samples_every_kth_output_step_and_says_so(monkeypatch):
    monkeypatch.setattr(simulate_study, "LIMITS_EVERY", 3)
    ts = rh.simulate(rh.load_scene("mobile_end", elements=4), until_s=0.01, progress=False)
    dt_out = ts.params.time.output_every_s
    assert ts.summary["limits"]["sampled_every_s"] == pytest.approx(3 * dt_out)
    np.testing.assert_allclose(ts.limits_history[:, 0], ts.t_s[::3])
