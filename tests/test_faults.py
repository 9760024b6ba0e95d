"""The command line's fault table (issue 27): every command, bad input refused
before any work with exit status 2, ONE line on stderr (no traceback) naming
the option and what is allowed, and nothing written (neither the -o folder
nor ./results); Ctrl-C during a sweep exits 130 with one line saying what was
kept, and the same command resumes."""

import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

# the command line as `python -m`, so that it runs wherever the package imports (the
# venv's `rawehelix` script does not exist under make test-debian13's PYTHONPATH)
RAWEHELIX = [sys.executable, "-m", "rawehelix.cli.main"]
OUT = "OUT"  # the -o folder, in the test's own working directory

# (command line, exit status, what the one line must say)
FAULTS = [
    # our options mistyped: never passed on to PETSc (which would ignore them)
    (["stationary", "stationary_table2", "--elemnts", "4"], 2, "did you mean --elements?"),
    (["stationary", "stationary_table2", "-O", OUT], 2, "did you mean -o?"),
    (["modes", "stationary_table2", "-output", OUT], 2, "did you mean --output?"),
    (["sweep", "mobile_end", "-Elements", "3"], 2, "did you mean --elements?"),
    (["stationary", "stationary_table2", "--count", "4"], 2, "--count: is not an option"),
    (["labtest", "axial", "--elemnts", "4"], 2, "did you mean --elements?"),
    (["stationary", "stationary_table2", "--elements", "x"], 2, "invalid int value: 'x'"),
    # PETSc options no solver reads, and values PETSc refuses
    (["stationary", "stationary_table2", "-rawehelix_snes_maxit", "5"], 2,
     "-rawehelix_snes_maxit (did you mean -rawehelix_snes_max_it"),
    (["stationary", "stationary_table2", "-elemnts", "4"], 2,
     "-elemnts (did you mean --elements?): no solver of rawehelix reads them"),
    (["stationary", "stationary_table2", "-rawehelix_snes_type", "nonexistent"], 2,
     "-rawehelix_snes_type nonexistent: Unable to find requested SNES type nonexistent"),
    (["simulate", "nominal_operation", "-rawehelix_ts_type", "nonexistent"], 2,
     "Unknown TS type: nonexistent"),
    # the compiled steps (issue 46) on a scene of adaptive steps: refused when the
    # dynamics solver is built (after the stationary solve), nothing written
    (["simulate", "nominal_operation", "--elements", "2", "-rawehelix_ts_compiled", "1"], 2,
     "-rawehelix_ts_compiled: the compiled steps take fixed steps"),
    (["response", "mobile_end", "-rawehelix_ksp_rtol", "abc"], 2,
     "-rawehelix_ksp_rtol abc: Input string abc has no numeric value"),
    (["labtest", "bending", "-rawehelix_labtest_snes_type", "nonexistent"], 2,
     "Unable to find requested SNES type nonexistent"),
    (["extremes", "-rawehelix_pep_type", "nonexistent"], 2, "nonexistent"),
    # each command's own checks
    (["labtest", "axial", "--degree", "9"], 2, "discretisation.degree: 9 must be an integer from 2 to 8"),
    (["labtest", "axial", "--elements", "0"], 2, "discretisation.elements: 0 must be an integer >= 1"),
    (["response", "mobile_end", "--degree", "9"], 2, "must be an integer from 2 to 8"),
    (["orbits", "mobile_end", "--f1", "11:11"], 2, "START != STOP"),
    (["stationary", "stationary_table2", "--elements", "8", "--set", 'discretisation.mesh="graded"',
      "--set", "discretisation.grading=1e9"], 2,
     "discretisation.grading: gmsh cannot grade 8 elements by 1e+09"),
    (["sweep", "mobile_end", "--f1", "1:2"], 2, "is not START:STOP:STEP"),
    # issue 41: both ends.elongation and ends.tension_N; a helix its controller spins up
    (["stationary", "stationary_table2", "--set", "ends.tension_N=200"], 2,
     "ends.elongation, ends.tension_N: give exactly one of"),
    (["modes", "stationary_table2", "--set", "ends.tension_N=200"], 2, "the scene gives both"),
    (["stationary", "nominal_operation", "--elements", "2"], 2,
     "controller.target_rpm: 120 rpm with controller.k1 = 0.5 > 0"),
    # issue 43: a lifter too weak to hold the helix up
    (["stationary", "stationary_table2", "--elements", "2", "--set", 'lifter.top="lifted"',
      "--set", "lifter.force_N=3"], 2, "lifter.force_N: the lifter cannot hold the helix up"),
    (["modes", "stationary_table2", "--elements", "2", "--set", 'lifter.top="lifted"',
      "--set", "lifter.force_N=200"], 2,
     "lifter.top: 'lifted' holds the top end by the lifter's force, which `rawehelix stationary`"),
    (["converge", "stationary_table2", "--quantity", "nothing"], 2, "--quantity: nothing"),
    # the network reference (references/network): its rings, and the commands it runs
    (["modes", "stationary_table2", "--scheme", "network"], 2,
     "section.rings: --scheme network needs the rings"),
    (["stationary", "stationary_table2", "--scheme", "network", "--set", "section.rings=2"], 2,
     "section.rings: 2 --scheme network needs 3 to 1000 rings"),
    (["modes", "stationary_table2", "--scheme", "network", "--set", "section.rings=5", "--set",
      "section.lay_angle_deg=16.8"], 2, "past Tulloch's collapse angle"),
    (["orbits", "mobile_end", "--scheme", "network", "--set", "section.rings=5", "--f1", "3"], 2,
     "'network' runs 'stationary', 'modes', 'section', 'simulate', 'sweep' only, not 'orbits'"),
    # the network's rotor (references/network/machine.py): a generator the rotor cannot
    # meet inside its table at the scene's wind
    (["simulate", "rotor_example", "--scheme", "network", "--set", "section.rings=5",
      "--set", "generator.mppt_gain_Nms2=50", "--until", "0.01"], 2,
     "wind.speed_m_s: 6.6131: the rotor has no stable operating point"),
    (["extremes", "nosuchcase"], 2, "unknown case(s)"),
    (["study", "stationary_table2", "--vary", "helix.EI_Nm2=1:2:3", "--quantity", "tension"], 2,
     "--quantity: tension: unknown quantity"),
    (["calibrate", "stationary_table2", "--fit", "helix.EI_Nm2", "--target", "nosuch=1"], 2,
     "--target: nosuch: unknown quantity"),
    # issue 43: simulate with a rotor starts at a stable rigid-shaft operating point
    (["simulate", "rotor_example", "--elements", "2", "--set", 'generator.law="torque"',
      "--set", "generator.torque_Nm=500", "--set", "generator.mppt_gain_Nms2=0"], 2,
     "wind.speed_m_s: 6.6131 m/s (V_n = 4.676 m/s along the rotor's axis) gives the rotor no "
     "stable operating point"),
    # issue 44: a start-up from rest needs a table from tsr 0; its release speed >= 0
    (["simulate", "rotor_example", "--elements", "2", "--set", "generator.release_rpm=60"], 2,
     "rotor.table: starts at tsr 1 with cp 0.034861: a start-up from rest"),
    (["simulate", "startup", "--elements", "2", "--set", "generator.release_rpm=-1"], 2,
     "generator.release_rpm: -1.0 must be a finite number of rpm >= 0"),
    # issue 44: simulate's lifted top starts at the rotor's operating point, on alpha2
    (["simulate", "stationary_table2", "--elements", "2", "--set", 'lifter.top="lifted"',
      "--set", "lifter.force_N=300"], 2,
     "lifter.top: 'lifted' in simulate starts from the lifted state at the rotor's operating"),
    (["simulate", "rotor_example", "--elements", "2", "--set", 'lifter.top="lifted"',
      "--set", "lifter.force_N=300", "-rawehelix_ts_type", "beuler"], 2,
     "lifter.top: 'lifted' runs with the second-order time stepper only, not "
     "-rawehelix_ts_type beuler"),
    # issue 43: operate's wind speeds and a scene without a rotor
    (["operate", "rotor_example", "--wind", "4:16"], 2, "--wind: 4:16: must be LO:HI:STEP"),
    (["operate", "stationary_table2", "--wind", "4:16:1"], 2,
     "rotor: 'operate' needs a [rotor] section"),
    (["operate", "rotor_example", "--elements", "2", "--wind", "4:6:1", "--set",
      'lifter.top="lifted"', "--set", "lifter.force_N=10"], 2,
     "lifter.force_N: the lifter cannot hold the helix up"),
    # the Campbell diagram: its wind list, its envelope folder, a scene with no rotor
    (["campbell", "rotor_example", "--wind", "6:3:1"], 2, "--wind: 6:3:1: must be LO:HI:STEP"),
    (["campbell", "rotor_example", "--wind", "3:6:1", "--envelope", "nowhere"], 2,
     "--envelope: nowhere: must be the output folder of a finished 'rawehelix envelope' run"),
    (["campbell", "stationary_table2", "--elements", "2", "--wind", "3:6:1"], 2,
     "stationary_table2: rotor: 'operate' needs a [rotor] section"),
    (["campbell", "rotor_example", "--elements", "2", "--wind", "3:6:1", "--set",
      'lifter.top="lifted"', "--set", "lifter.force_N=100"], 2,
     "rotor_example: lifter: 'campbell' linearises about a fixed top end"),
    # issue 44: the wind in time (tests/test_wind_series.py has every key and file fault)
    (["stationary", "gust_rated", "--set", "wind.speed_m_s=45"], 2,
     "not below V_e1 = 42 m/s of wind.wind_class = 'III'"),
    (["stationary", "gust_rated", "--set", 'wind.turbulence_class="D"'], 2,
     'wind.turbulence_class: "D" must be one of'),
    (["simulate", "turbulent_rated", "--until", "700"], 2,
     "wind.duration_s: 600.0: is shorter than the run, --until = 700.0"),
    # a seed study past the memory (its disk: tests/test_weather_faults.py)
    (["study", "turbulent_rated", "--elements", "2", "--set", "time.output_every_s=1e-6",
      "--vary", "wind.seed=1:2:2", "--quantity", "power_mean_W"], 2,
     "time.until_s: 600 s: 6e+08 output steps of 1e-06 s need about 300 GB, more than the"),
]


def _ids(case):
    return "-".join(case[0][:1] + [t for t in case[0][1:] if t.startswith("-")])


@pytest.mark.parametrize("argv,status,message", FAULTS, ids=[_ids(c) for c in FAULTS])
def test_refused_before_work(tmp_path, argv, status, message):
    argv = [t if t != OUT else str(tmp_path / OUT) for t in argv]
    if "-o" not in argv and "-O" not in argv and "-output" not in argv:
        argv += ["-o", str(tmp_path / OUT)]
    run = subprocess.run([*RAWEHELIX, *argv], cwd=tmp_path, capture_output=True, text=True,
                         timeout=300)
    lines = run.stderr.splitlines()
    assert run.returncode == status, run.stderr
    assert len(lines) == 1 and "Traceback" not in run.stderr, run.stderr
    assert message in lines[0]
    assert run.stdout == ""
    assert list(tmp_path.iterdir()) == []  # no -o folder, no ./results


# refusals found after the lock of the default folder results/<scene>/<command> was taken
DEFAULT_FOLDER_FAULTS = [
    (["orbits", "mobile_end", "--elements", "2", "--f1", "1:1.5", "--max-points", "0"],
     "--max-points: 0"),
    (["simulate", "nominal_operation", "--elements", "4", "--until", "1e9"], "--until"),
    (["labtest", "bending", "--fit", "--tension", "100"], "cannot determine the fit's law"),
]


@pytest.mark.parametrize("argv,message", DEFAULT_FOLDER_FAULTS,
                         ids=[c[0][0] for c in DEFAULT_FOLDER_FAULTS])
def test_refused_without_o_leaves_no_results_folder(tmp_path, argv, message):
    """Without -o, a refusal leaves neither results/<scene>/<command> nor the parents
    the lock made for it (results/<scene>, results/)."""
    run = subprocess.run([*RAWEHELIX, *argv], cwd=tmp_path, capture_output=True, text=True,
                         timeout=300)
    assert run.returncode == 2 and message in run.stderr, run.stderr
    assert list(tmp_path.iterdir()) == []  # no empty results/<scene>/

@pytest.mark.slow
@pytest.mark.long  # 18 s; make test's budget (make test-long runs it)
def test_ctrl_c_keeps_points_and_resumes(tmp_path):
    """SIGINT after the first of two points: exit 130, one line saying that 1 point
    was kept and how to resume; the rerun computes only the other point."""
    # 9 and 10 Hz settle in ~40 periods each (5 and 6 Hz need 130-215): ~10 s + 3 s
    argv = [*RAWEHELIX, "sweep", "mobile_end", "--elements", "2", "--f1", "9:10:1",
            "-o", str(tmp_path / OUT)]
    proc = subprocess.Popen(argv, cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)
    points = tmp_path / OUT / "points"
    deadline = time.monotonic() + 900
    while not list(points.glob("f1_*.json")) and time.monotonic() < deadline:
        assert proc.poll() is None, proc.communicate()
        time.sleep(0.2)  # the second point takes ~3 s: interrupt well inside it
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    assert "Traceback" not in err and "KeyboardInterrupt" not in err
    said = [ln for ln in err.splitlines() if "interrupted" in ln]
    assert said == [f"rawehelix: interrupted: 1 finished point kept in {tmp_path / OUT}/; "
                    "run the same command again to resume"], err
    assert len(list(points.glob("f1_*.json"))) == 1
    again = subprocess.run(argv, cwd=tmp_path, capture_output=True, text=True, timeout=900)
    assert again.returncode == 0, again.stderr
    assert "2 points (1 computed now)" in again.stdout
