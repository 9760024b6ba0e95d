"""The time and count keys that multiply a run's work or output (issue 41): each is
counted before anything is allocated, and a value past this machine's memory, the
wall limit or the output folder's free space is refused with one line naming the key
and the estimate against what the machine has (exit 2, nothing written); every
registered command has its rows in the estimate tables."""

import pytest

from rawehelix.cli.commands import COMMANDS
from rawehelix.studies.store import outdir
from rawehelix.studies import needs, resources, scene
from tests.test_refusals import assert_refused

SIM = ["simulate", "nominal_operation", "--elements", "4"]


@pytest.mark.parametrize("args, words", [
    # the probe: 2.56 GB in 5 s, now refused before the rod is built
    ([*SIM, "--until", "1e9"], ("--until", "2e+10 output steps", "GB this machine has")),
    ([*SIM, "--set", "time.output_every_s=1e-9"], ("time.until_s", "time.output_every_s")),
    ([*SIM, "--set", "time.fields_every_s=1e-8"], ("time.until_s", "frames", "time.fields_every_s")),
    ([*SIM, "--until", "1e8", "--set", "time.output_every_s=1e6", "--set",
      "time.fields_every_s=1e6"], ("--until", "time steps of time.dt_s", "days")),
    (["sweep", "mobile_end", "--set", "sweep.samples_per_period=1000000000"],
     ("sweep.samples_per_period", "30 points", "GB this machine has")),
    # the key that grew is named, not its partner in the product (the tester's D8)
    (["sweep", "mobile_end", "--set", "sweep.record_periods=100000000", "--set",
      "sweep.max_periods=400000000"], ("sweep.record_periods: 1e+08", "GB this machine has")),
    (["sweep", "mobile_end", "--set", "sweep.max_periods=1000000000000"],
     ("sweep.max_periods", "GB this machine has")),
    (["sweep", "mobile_end", "--f1", "15:15:1", "--set", "sweep.min_periods=30000000",
      "--set", "sweep.max_periods=30000000"], ("sweep.min_periods", "days")),
    (["envelope", "mobile_end", "--vary", "helix.EI_Nm2=1:2:100000000", "--f1", "1:2"],
     ("--vary", "1e+08 points")),
    (["envelope", "mobile_end", "--elements", "200", "--vary", "helix.EI_Nm2=4000:5000:5",
      "--f1", "1:15"], ("-o", "MB free", "'envelope' writes")),
])
def test_a_key_that_multiplies_the_work_is_refused_before_work(tmp_path, args, words):
    assert_refused(tmp_path, [*args, "-o", str(tmp_path / "o")], *words)


def test_the_simulate_estimate_counts_the_outputs():
    """Twice the outputs, about twice what they keep; the issue's probe is past any
    machine of today (2e10 outputs: 10 TB)."""
    p = scene.load("nominal_operation", elements=4)
    with pytest.raises(resources.SceneError, match="--until"):
        resources.check_simulate(p, 1e9)
    resources.check_simulate(p, None)  # the scene's own 30 s pass
    assert resources.BYTES_PER_OUTPUT * 2e10 > 1e12


def test_the_branch_store_estimate_bounds_the_measured_points():
    """orbits_store's point at N = 4 (p = 3, HB, H = 3) measured 1.10 MB, at N = 2
    0.47 MB: the estimate is above each and within 1.6 times."""
    for n, measured in ((4, 1_097_856), (2, 470_880)):
        p = scene.load("mobile_end", elements=n, degree=3)
        est = resources.store_bytes_per_point(p, "hb")
        assert measured < est < 1.6 * measured, (n, est)


def test_every_registered_command_names_its_estimates():
    """Each command of the registry names its own entry of studies/needs.py (a memory
    step and an output estimate), and every entry is a command's: a new command without
    one cannot be built (its ``needs`` is required and checked against its name)."""
    assert all(c.needs is needs.get(name) for name, c in COMMANDS.items())
    assert needs.NEEDS.names() == tuple(COMMANDS)
    from rawehelix.cli.commands.base import Command
    with pytest.raises(TypeError, match="needs"):
        Command("new", "a new command", print, print)
    with pytest.raises(ValueError, match="studies/needs.py's entry of its name"):
        Command("new", "a new command", print, print, needs.get("modes"))


def test_the_estimates_are_the_measured_ones():
    """The numbers moved unchanged from resources.HEAVIEST and outdir.OUTPUT_BYTES (the
    commands of then; a new command adds its own row)."""
    MB = 1e6
    table = {name: (n.memory_step, n.output_bytes) for name, n in needs.NEEDS.items()}
    measured = {
        "stationary": ("stationary", 5 * MB), "modes": ("modes", 20 * MB),
        "simulate": ("dynamics", 200 * MB), "sweep": ("dynamics", 20 * MB),
        "response": ("modes", 10 * MB), "orbits": ("modes", 50 * MB),
        "section": ("stationary", 0.1 * MB), "converge": ("modes", 20 * MB),
        "study": ("modes", 10 * MB), "envelope": ("modes", 10 * MB),
        "calibrate": ("modes", 5 * MB), "extremes": ("modes", 50 * MB),
        "labtest": ("stationary", 5 * MB)}
    assert {name: table[name] for name in measured} == measured
    with pytest.raises(ValueError, match="memory step 'disk'"):
        needs.Needs("new", "disk", MB)
    with pytest.raises(ValueError, match="output estimate"):
        needs.Needs("new", "modes", float("nan"))


@pytest.mark.parametrize("f1", [[0.0], ["x"], [float("nan")], [], [float("inf")]])
def test_a_bad_frequency_list_is_the_sweeps_own_refusal(f1):
    """The estimates read the list before the sweep checks it: a list they cannot
    count from still ends in the sweep's one-line refusal, never another error."""
    import rawehelix as rh
    with pytest.raises(rh.SceneError, match="f1_Hz"):
        rh.sweep(scene.load("mobile_end", elements=2), f1_Hz=f1)


@pytest.mark.parametrize("window", [(float("nan"), 9.0), (9.0, float("inf")), (9.0, 9.0)])
def test_a_bad_window_is_the_orbits_own_refusal(window):
    import rawehelix as rh
    with pytest.raises(rh.SolverError, match="two different finite frequencies"):
        rh.orbits(scene.load("mobile_end", elements=2), *window)


@pytest.mark.parametrize("argv, estimate_MB", [
    # 141 f1 of 4 x 50000 samples a point: 141 x 10 MB of series
    (["sweep", "mobile_end", "--f1", "1:15:0.1", "--set", "sweep.samples_per_period=50000"],
     1400),
    # a 14 Hz branch (351 points) at N = 8, HB: 12 (7 x 100)^2 B a point
    (["orbits", "mobile_end", "--elements", "8", "--f1", "1:15", "--method", "hb"], 2000),
])
def test_the_disk_estimate_counts_the_points(tmp_path, monkeypatch, capsys, argv, estimate_MB):
    """With 1 GB free (the filesystem's free space patched), a run whose points' stored
    series or states pass it is refused before work, and the estimate is counted from its
    keys (it was a fixed 20 or 50 MB)."""
    import collections

    from rawehelix.cli import main as cli
    usage = collections.namedtuple("usage", "total used free")
    monkeypatch.setattr(outdir.shutil, "disk_usage", lambda path: usage(2e9, 1e9, 1e9))
    assert cli.main([*argv, "-o", str(tmp_path / "o")]) == 2
    line, = capsys.readouterr().err.strip().splitlines()
    assert "-o" in line and "1e+03 MB free" in line and f"'{argv[0]}' writes" in line, line
    need = float(line.split("the about ")[1].split(" MB")[0])
    assert estimate_MB < need < 3 * estimate_MB, line
    assert not (tmp_path / "o").exists()


def test_every_study_stage_has_its_memory_step():
    """A study's or a calibration's point is checked stage by stage
    (resources.check_quantities): each stage of studies/quantities.py has its row."""
    from rawehelix.studies.quantities import STAGES
    for stage in STAGES:
        assert resources.heaviest(stage) in needs.STEPS


@pytest.mark.parametrize("lookup", [
    lambda: resources.estimate_bytes(scene.load("mobile_end", elements=2), "no_such_command"),
    lambda: resources.check(scene.load("mobile_end", scheme="spline", elements=2), "no_such_command"),
    lambda: needs.get("no_such_command"),
])
def test_an_unregistered_command_is_an_internal_error_not_a_default(lookup):
    """No silent fall-back: a command without its rows is an internal error naming
    the table and the command (it used to be estimated as 'modes' and 50 MB)."""
    with pytest.raises(KeyError, match=r"internal: command 'no_such_command' has no estimates "
                                       r"in studies/needs\.py NEEDS"):
        lookup()
