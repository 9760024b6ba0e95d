"""Refusals before any work (issue 27, part 3): bad input, a run past this
machine's memory and an output folder that cannot take the results exit with
status 2 and ONE line on stderr, within seconds, at a small peak RSS, with
nothing written; a study with failed points exits 3 ("done with failures");
``stationary`` runs every shipped scene, without the shooting reference where
it does not apply."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from rawehelix.errors import SceneError
from rawehelix.studies import needs
from rawehelix.studies.store import outdir
from rawehelix.studies import resources

CLI = [sys.executable, "-m", "rawehelix.cli.main"]
HUGE = ["--elements", "100000000", "--set", 'discretisation.bending="mixed"']
FAST_S = 10.0  # a refusal: the imports (~2 s) and no work, on a loaded 2-core machine
SMALL_RSS_KB = 400_000  # a refusal's peak RSS: the interpreter and its imports


# The command runs under a small launcher that reports its child's peak RSS:
# Linux carries a process's high-water mark across fork and exec (getrusage's
# ru_maxrss), so a child forked straight from this test process (1 GB deep into
# the suite) would report this process's peak, not its own.
LAUNCHER = ("import os, subprocess, sys; p = subprocess.Popen(sys.argv[2:]); "
            "_, status, usage = os.wait4(p.pid, 0); "
            "open(sys.argv[1], 'w').write(str(usage.ru_maxrss)); "
            "sys.exit(os.waitstatus_to_exitcode(status))")


def run(args, cwd, timeout=120.0):
    """(exit status, stdout, stderr, wall s, peak RSS kB) of the command line,
    the RSS of the command alone (measured by LAUNCHER)."""
    out, err, rss = (Path(cwd) / name for name in (".stdout", ".stderr", ".rss"))
    with open(out, "w") as fo, open(err, "w") as fe:
        t0 = time.perf_counter()
        proc = subprocess.Popen([sys.executable, "-c", LAUNCHER, str(rss), *CLI, *args],
                                cwd=cwd, stdout=fo, stderr=fe, start_new_session=True)
        try:
            proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
            pytest.fail(f"still running after {timeout} s: {args}")
        wall = time.perf_counter() - t0
    texts = out.read_text(), err.read_text()
    peak = int(rss.read_text())
    for path in (out, err, rss):
        path.unlink()
    return proc.returncode, *texts, wall, peak


def assert_refused(tmp_path, args, *words, written=("o",)):
    code, out, err, wall, rss = run(args, tmp_path)
    lines = err.strip().splitlines()
    assert code == 2, (code, err)
    assert len(lines) == 1 and lines[0].startswith("rawehelix: error: "), err
    assert "Traceback" not in err + out
    for word in words:
        assert word in lines[0], lines[0]
    assert wall < FAST_S, f"refused after {wall:.1f} s"
    assert rss < SMALL_RSS_KB, f"peak RSS {rss / 1e3:.0f} MB before the refusal"
    for name in written:
        assert not (tmp_path / name).exists(), f"{name} was written"
    return lines[0]


# -- resources: one estimate, every command ---------------------------------------------
@pytest.mark.parametrize("command, extra", [
    ("stationary", []), ("modes", []), ("simulate", []), ("sweep", []), ("response", []),
    ("orbits", ["--f1", "9:9.5"]), ("study", ["--vary", "helix.EI_Nm2=3000:6000:2",
                                              "--quantity", "tension_s0_N"]),
    ("calibrate", ["--fit", "helix.EI_Nm2", "--target", "lateral_frequency_Hz=5"])])
def test_a_discretisation_past_the_memory_is_refused_before_allocating(tmp_path, command, extra):
    scene = "mobile_end" if command in ("sweep", "response", "orbits") else "stationary_table2"
    line = assert_refused(tmp_path, [command, scene, *HUGE, *extra, "-o", str(tmp_path / "o")],
                          "discretisation.elements", "100000000", "GB this machine has")
    # the estimate the message states is the module's
    assert "needs about" in line and "TB" in line


def test_labtest_past_the_memory_is_refused(tmp_path):
    assert_refused(tmp_path, ["labtest", "axial", "--elements", "100000000", "-o",
                              str(tmp_path / "o")], "discretisation.elements", "labtest")


def test_orbits_dense_state_is_refused_from_the_discretisation(tmp_path):
    """3n = 3 * 4 * (3 * 300 + 1) = 10812 > MAX_STATE, within the memory: refused
    before the rod is built (solvers/orbits.py checked after allocating)."""
    assert_refused(tmp_path, ["orbits", "mobile_end", "--elements", "300", "--f1", "9:9.5",
                              "-o", str(tmp_path / "o")], "3n = 10812", "3000")


def test_a_frequency_list_past_the_limits_is_refused(tmp_path):
    """1.5e10 frequencies: their records alone pass the memory (the list is not built)."""
    assert_refused(tmp_path, ["sweep", "mobile_end", "--f1", "0.001:15:1e-9", "-o",
                              str(tmp_path / "o")], "--f1", "points")


def test_a_design_past_the_limits_is_refused(tmp_path):
    """A 10^5 x 10^5 grid: 10^10 points, refused before the design is built."""
    assert_refused(tmp_path, ["study", "stationary_table2", "--vary", "helix.EI_Nm2=1:2:100000",
                              "--vary", "helix.mass_kg=0.1:1:100000", "--quantity",
                              "tension_s0_N", "-o", str(tmp_path / "o")], "--vary/--points")


def test_the_estimate_bounds_a_measured_peak(tmp_path):
    """Independent: the peak RSS of a real run (stationary, mixed form, N = 3000)
    is below the estimate, which is not more than 3 times it."""
    from rawehelix.studies import scene
    p = scene.load("stationary_table2", elements=3000,
                   overrides={"discretisation.bending": "mixed"})
    code, out, err, wall, rss = run(["stationary", "stationary_table2", "--elements", "3000",
                                     "--set", 'discretisation.bending="mixed"', "-o",
                                     str(tmp_path / "o")], tmp_path)
    assert code == 0, err
    estimate_kb = resources.estimate_bytes(p, "stationary") / 1e3
    assert rss < estimate_kb < 3 * rss, (rss, estimate_kb)


@pytest.mark.parametrize("name", ["stationary_table2", "nominal_operation", "mobile_end"])
@pytest.mark.parametrize("command", ["stationary", "modes", "simulate", "sweep", "response",
                                     "orbits", "labtest"])
def test_the_shipped_scenes_pass_the_check(name, command):
    """The check refuses nothing that runs: every shipped scene at its own resolution."""
    from rawehelix.studies import scene
    resources.check_run(scene.load(name), command)


# -- calibrate's bad input -------------------------------------------------------------
@pytest.mark.parametrize("args, words", [
    (["--target", "lateral_frequency_Hz=-5"], ("--target", "must be > 0")),
    (["--bounds", "helix.EI_Nm2=-100:200", "--target", "lateral_frequency_Hz=5"],
     ("--bounds", "LO is outside the key's allowed range")),
    (["--bounds", "helix.EI_Nm2=-100:200", "--target", "lateral_frequency_Hz=1"],
     ("--bounds", "LO is outside the key's allowed range"))])
def test_calibrate_bad_input_is_refused_before_any_evaluation(tmp_path, args, words):
    assert_refused(tmp_path, ["calibrate", "stationary_table2", "--elements", "4", "--fit",
                              "helix.EI_Nm2", *args, "-o", str(tmp_path / "o")], *words)


# -- the output folder -----------------------------------------------------------------
def test_an_output_that_is_a_file_is_refused(tmp_path):
    (tmp_path / "o").write_text("mine")
    assert_refused(tmp_path, ["stationary", "stationary_table2", "--elements", "4", "-o",
                              str(tmp_path / "o")], "-o", "is a file", written=())
    assert (tmp_path / "o").read_text() == "mine"
    assert_refused(tmp_path, ["study", "stationary_table2", "--elements", "4", "--vary",
                              "helix.EI_Nm2=3000:6000:2", "--quantity", "tension_s0_N",
                              "-o", str(tmp_path / "o" / "deeper")], "is a file", written=())


def test_an_output_that_cannot_be_written_is_refused(tmp_path):
    """/proc takes no new files, whoever runs (root too)."""
    assert_refused(tmp_path, ["stationary", "stationary_table2", "--elements", "4", "-o",
                              "/proc/rawehelix_out"], "-o", "cannot write")


def test_a_full_filesystem_is_refused(tmp_path, monkeypatch):
    import shutil
    usage = shutil.disk_usage(tmp_path)
    monkeypatch.setattr(shutil, "disk_usage", lambda p: usage._replace(free=10**6))
    with pytest.raises(SceneError, match="1 MB free, less than the about 200 MB"):
        outdir.check(tmp_path / "o", needs.get("simulate"))
    monkeypatch.setattr(shutil, "disk_usage", lambda p: usage._replace(free=10**9))
    outdir.check(tmp_path / "o", needs.get("simulate"))  # 1 GB is room enough
    assert list(tmp_path.iterdir()) == []  # the writable check left nothing


# -- the orbits' --sweep ---------------------------------------------------------------
def test_orbits_sweep_folder_is_checked_before_work(tmp_path):
    assert_refused(tmp_path, ["orbits", "mobile_end", "--elements", "4", "--f1", "9:9.5",
                              "--sweep", str(tmp_path / "missing"), "-o", str(tmp_path / "o")],
                   "--sweep", "no such file")
    (tmp_path / "notasweep").mkdir()
    (tmp_path / "notasweep" / "summary.json").write_text('{"branch": []}')
    assert_refused(tmp_path, ["orbits", "mobile_end", "--elements", "4", "--f1", "9:9.5",
                              "--sweep", str(tmp_path / "notasweep"), "-o",
                              str(tmp_path / "o")], "--sweep", "not a sweep's summary")


# -- study: done with failures ---------------------------------------------------------
def test_a_study_with_failed_points_exits_3_and_says_so(tmp_path):
    """A PETSc option that stops every Newton solve at once: every point fails;
    the outputs are written, the status is 'done with failures', exit 3."""
    code, out, err, wall, rss = run(["study", "stationary_table2", "--elements", "4", "--vary",
                                     "helix.EI_Nm2=3000:6000:2", "--quantity", "tension_s0_N",
                                     "--fd-step", "0", "-o", str(tmp_path / "o"),
                                     "-rawehelix_snes_max_it", "0"], tmp_path)
    assert code == 3, err
    s = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert s["status"] == "done with failures"
    assert sorted(s["failed"]) == ["p00000", "p00001"]
    assert "DIVERGED_MAX_IT" in s["failed"]["p00000"]["tension_s0_N"]
    assert "done with failures" in out
    code, out, err, wall, rss = run(["study", "stationary_table2", "--elements", "4", "--vary",
                                     "helix.EI_Nm2=3000:6000:2", "--quantity", "tension_s0_N",
                                     "--fd-step", "0", "-o", str(tmp_path / "ok")], tmp_path)
    assert code == 0, err
    s = json.loads((tmp_path / "ok" / "summary.json").read_text())
    assert s["status"] == "all done" and s["failed"] == {}


# -- stationary on every shipped scene -------------------------------------------------
def test_stationary_runs_a_scene_off_the_plane(tmp_path):
    """mobile_end's upper end is on the circle of Eq. (70), off the x-z plane:
    the summary says the shooting reference does not apply, exit 0."""
    code, out, err, wall, rss = run(["stationary", "mobile_end", "--elements", "4",
                                     "--set", "controller.target_rpm=0", "--set",
                                     "torque.top_Nm=0", "-o", str(tmp_path / "o")], tmp_path)
    assert code == 0, err
    s = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert s["shooting"].startswith("not applicable: the scene is not planar")
    assert "shooting_max_diff_m" not in s
    assert (tmp_path / "o" / "stationary.png").exists()


def test_the_shooting_reference_applies_to_the_planar_scenes():
    from rawehelix.references import shooting
    from rawehelix.studies import scene
    for name in ("stationary_table2", "nominal_operation"):
        assert shooting.not_applicable(scene.load(name).normalised()) is None
    assert "r1 > 0" in shooting.not_applicable(scene.load("mobile_end").normalised())
