"""`rawehelix calibrate` says when it fails (issue 27, part 3): success only when
every target is met within the stated tolerance; a missed target is named with
its residual and any active bound, and exits 3; bounds outside a key's allowed
range and targets outside a quantity's physical range are refused (exit 2)
before the first evaluation."""

import json
import math

import pytest
from mpi4py import MPI

from rawehelix.errors import SceneError
from rawehelix.cli import main as cli
from rawehelix.studies import calibrate, pool, quantities, study

N = 4
TARGET = {"tension_s0_N": 250.0}


def independent(source, over: dict) -> float:
    """T(0) of the scene at ``over``, solved afresh (not the calibration's record)."""
    return quantities.evaluate(source.load(over), ["tension_s0_N"])["values"]["tension_s0_N"]


def test_a_met_target_is_success_within_the_tolerance(tmp_path):
    source = study.Source("stationary_table2", elements=N)
    result = calibrate.compute(source, ["ends.elongation"], TARGET, tmp_path,
                               comm=MPI.COMM_SELF)
    s = result.summary
    assert s["status"] == "targets met" and s["success"] and result.exit_status == 0
    assert s["tolerance"] == calibrate.TOLERANCE and s["missed"] == {} and s["active_bounds"] == {}
    # the fitted key gives the target when solved again, within the stated tolerance
    got = independent(source, s["fitted"])
    assert abs(got / TARGET["tension_s0_N"] - 1) <= s["tolerance"]


def test_a_missed_target_is_named_with_its_residual_and_active_bound(tmp_path):
    """The elongation held at most 0.002 cannot give T(0) = 250 N: the fit ends
    on the upper bound, the residual is T(0) at 0.002 (solved afresh) / 250 - 1,
    the status is 'targets missed', exit status 3; a tolerance past that
    residual turns the same fit into success (the tolerance decides)."""
    source = study.Source("stationary_table2", elements=N)
    bounds = calibrate.parse_bounds(["ends.elongation=0.001:0.002"], ["ends.elongation"])
    result = calibrate.compute(source, ["ends.elongation"], TARGET, tmp_path, bounds=bounds,
                               comm=MPI.COMM_SELF)
    s = result.summary
    assert s["status"] == "targets missed" and not s["success"]
    assert result.exit_status == study.EXIT_UNMET == 3
    assert s["active_bounds"] == {"ends.elongation": "upper"}
    expected = independent(source, {"ends.elongation": 0.002}) / 250.0 - 1
    assert s["missed"]["tension_s0_N"]["relative"] == pytest.approx(expected, rel=1e-6)
    text = calibrate.report(result)
    assert "missed: tension_s0_N" in text and "bound active: ends.elongation" in text
    loose = calibrate.compute(source, ["ends.elongation"], TARGET, tmp_path, bounds=bounds,
                              comm=MPI.COMM_SELF, tolerance=abs(expected) * 1.01).summary
    assert loose["status"] == "targets met" and loose["active_bounds"]


def test_the_command_line_exits_3_on_a_missed_target_and_writes_its_summary(tmp_path):
    out = tmp_path / "o"
    code = cli.main(["calibrate", "stationary_table2", "--elements", str(N), "--fit",
                     "ends.elongation", "--bounds", "ends.elongation=0.001:0.002", "--target",
                     "tension_s0_N=250", "--tolerance", "1e-4", "-o", str(out)])
    assert code == 3
    s = json.loads((out / "summary.json").read_text())
    assert s["tolerance"] == 1e-4 and list(s["missed"]) == ["tension_s0_N"]


@pytest.mark.parametrize("bound, end", [("helix.EI_Nm2=-100:200", "LO"),
                                        ("ends.elevation_deg=10:100", "HI")])
@pytest.mark.parametrize("target", [5.0, 1.0])
def test_bounds_outside_the_allowed_range_are_refused_before_any_evaluation(
        tmp_path, bound, end, target):
    key = bound.partition("=")[0]
    with pytest.raises(SceneError, match=f"--bounds: {bound}: {end} is outside"):
        calibrate.compute(study.Source("stationary_table2", elements=N), [key],
                          {"lateral_frequency_Hz": target}, tmp_path, comm=MPI.COMM_SELF,
                          bounds=calibrate.parse_bounds([bound], [key]))
    assert pool.computed(tmp_path) == [] and list(tmp_path.iterdir()) == []


def test_default_bounds_stay_in_the_allowed_range():
    """ends.elevation_deg lies in [-90, 90] (parameters.Ends): from 25 deg the
    default [25 / 1000, 25000] is cut to [0.025, 90] (the bisection's end
    within 1e-9 of the closed range); helix.EI_Nm2 (> 0) keeps its default."""
    source = study.Source("stationary_table2")
    lo, hi = calibrate.default_bounds(source, "ends.elevation_deg", 25.0)
    assert lo == pytest.approx(0.025) and hi <= 90.0 and hi == pytest.approx(90.0, rel=1e-9)
    assert calibrate.default_bounds(source, "helix.EI_Nm2", 4000.0) == (4.0, 4e6)


@pytest.mark.parametrize("text", ["lateral_frequency_Hz=-5", "sag_m=-0.1",
                                  "settling_time_s=-3"])
def test_a_target_outside_the_physical_range_is_refused(text):
    with pytest.raises(SceneError, match="must be > 0"):
        calibrate.parse_targets(text)


def test_the_tolerance_is_checked(tmp_path):
    for bad in (0.0, -1e-3, 1.0, math.nan):
        with pytest.raises(SceneError, match="--tolerance"):
            calibrate.compute(study.Source("stationary_table2", elements=N),
                              ["ends.elongation"], TARGET, tmp_path, comm=MPI.COMM_SELF,
                              tolerance=bad)
