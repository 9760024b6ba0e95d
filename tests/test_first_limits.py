"""The first limit of each kind over a run's points (issue 41): each criterion's own
first point in the run's order, never hidden by another met from the start; printed
at the end of a sweep (f1 and place, or "not reached in f1 = LO..HI Hz", or "not
checked") and listed in summary.json's ``limits_first_by_kind``."""

import json
import subprocess
import sys

import numpy as np
import pytest

from rawehelix.members import CRITERIA, Members
from rawehelix.studies.analysis import branch_limits, structure_limits


def block(firsts: dict, off=("breaking",)) -> dict:
    """A point's recorded block whose first of each kind is ``firsts`` (kind -> s_m);
    its ``first_limit`` the earliest of them in t, as the Tracker keeps it."""
    by = dict.fromkeys(CRITERIA)
    for kind, (s, t) in firsts.items():
        by[kind] = {"value": 1.0, "s_m": s, "t_s": t, "quantity": "moment_ratio",
                    "threshold": 1.0}
    first = min(((x["t_s"], k) for k, x in by.items() if x), default=None)
    return {"status": "recorded", "moment_ratio_max": {"value": 0.1, "s_m": 0.0, "t_s": 0.0},
            "slack_fraction_max": 0.0, "first_by_kind": by,
            "first_limit": None if first is None else {"kind": first[1], **by[first[1]]},
            "criteria": {k: (None if k in off else 1.0) for k in CRITERIA}}


def point(f1, firsts, **kw) -> dict:
    return branch_limits.with_block({"f1_Hz": f1}, block(firsts, **kw))


def test_a_collapse_met_at_every_point_does_not_hide_the_first_slack():
    """The fault of issue 41: torsional collapse already at the first point (the static
    twist) and slack from 1.44 Hz on; the slack's first is its own point."""
    points = [point(f1, {"torsional_collapse": (0.0, 0.0),
                         **({"slack": (3.0, 0.5)} if f1 >= 1.44 else {})})
              for f1 in (1.0, 1.2, 1.44, 1.6)]
    firsts = branch_limits.first_by_kind(points)
    assert firsts["slack"]["f1_Hz"] == 1.44 and firsts["slack"]["s_m"] == 3.0
    assert not firsts["slack"]["already_at_first_point"] and firsts["slack"]["point"] == 2
    assert firsts["torsional_collapse"]["f1_Hz"] == 1.0
    assert firsts["torsional_collapse"]["already_at_first_point"]
    assert firsts["moment_saturation"] is None and firsts["breaking"] is None
    over = branch_limits.over_points(points)
    assert over["first_limit"]["f1_Hz"] == 1.0 and over["first_limit"]["already_at_first_point"]
    assert over["criteria_off"] == {"breaking": branch_limits.OFF["breaking"]}
    lines = branch_limits.first_lines(firsts, over)
    text = "\n".join(lines)
    assert "slack: f1 = 1.44 Hz, s = 3.000 m" in text
    assert "torsional collapse: already at the first point, f1 = 1 Hz" in text
    assert "moment saturation: not reached in f1 = 1..1.6 Hz" in text
    assert "breaking force: not checked (section.breaking_force_N not set)" in text
    assert "already at the first point, f1 = 1 Hz: the run starts past it" in text
    # a limit met at rest is no matter of the f1 window (the tester's D4): the line says
    # how to tell (the stationary state of the same scene) and what moves it then
    text = "\n".join(branch_limits.first_lines(firsts, over, scene="my_helix"))
    assert ("unless the helix meets it at rest: if 'rawehelix stationary my_helix' reports it "
            "too, more rings, less torque or more tension move it") in text


def test_first_is_in_the_runs_own_order_not_the_lowest_f1():
    """A branch traced downwards (or through a fold, f1 turning back): the first point
    along it, not the lowest f1; points without a block are skipped."""
    down = [point(9.0, {}), branch_limits.loaded({"f1_Hz": 8.5, "failed": "x"}),
            point(8.0, {"slack": (1.0, 0.1)}), point(7.0, {"slack": (2.0, 0.1)}),
            point(7.5, {"moment_saturation": (0.5, 0.2), "slack": (2.0, 0.1)})]
    firsts = branch_limits.first_by_kind(down)
    assert firsts["slack"]["f1_Hz"] == 8.0 and firsts["moment_saturation"]["f1_Hz"] == 7.5
    assert not firsts["slack"]["already_at_first_point"]
    over = branch_limits.over_points(down, order="along the branch")
    assert over["first_limit"]["f1_Hz"] == 8.0 and over["first_limit"]["kinds"] == ["slack"]
    assert over["f1_range_Hz"] == [9.0, 7.5] and over["points_without"] == 1


def test_a_block_stored_before_first_by_kind_gives_its_first_limit_only():
    old = point(2.0, {"slack": (1.0, 0.3), "torsional_collapse": (0.0, 0.0)})
    del old["limits"]["first_by_kind"]
    firsts = branch_limits.first_by_kind([old])
    assert firsts["torsional_collapse"]["f1_Hz"] == 2.0 and firsts["slack"] is None


def test_no_recorded_point_says_so():
    points = [branch_limits.loaded({"f1_Hz": 1.0, "failed": "x"})]
    over = branch_limits.over_points(points)
    assert branch_limits.first_by_kind(points) == dict.fromkeys(CRITERIA)
    assert branch_limits.first_lines({}, over) == ["  limits: not recorded at any point (1 without)"]


def test_the_tracker_keeps_each_kinds_first_in_time_then_s():
    """A stationary twist past the collapse criterion from t = 0 and a member that
    slackens at t = 2 at s = 3: first_limit stays the collapse, first_by_kind has both,
    the slack with its member (the inner side, phi = 0) and its force."""
    m = Members(n=6, R=0.5, beta=0.0, k=1e5, ring_spacing_m=2.0)
    tracker = structure_limits.Tracker(m)
    s = np.array([0.0, 3.0, 6.0])
    twist = np.ones(3)  # l tau = 2 rad > delta_crit = 1.64 rad (2 m tethers, 0.5 m rings)
    assert abs(m.ring_twist(twist[0])) >= m.critical_twist()
    tracker.add(s, N=np.full(3, 100.0), M=np.zeros(3), Q=np.zeros(3), tau=twist, t_s=0.0)
    tracker.add(s, N=np.full(3, 100.0), M=np.array([0.0, 60.0, 0.0]), Q=np.zeros(3),
                tau=twist, t_s=2.0)
    b = tracker.block()
    assert b["first_limit"]["kind"] == "torsional_collapse" and b["first_limit"]["t_s"] == 0.0
    slack = b["first_by_kind"]["slack"]
    assert (slack["s_m"], slack["t_s"], slack["member"]) == (3.0, 2.0, 0)
    assert slack["value"] <= 0 and slack["member_angle_deg"] == 0.0
    assert b["first_by_kind"]["moment_saturation"]["t_s"] == 2.0
    assert b["first_by_kind"]["breaking"] is None


SWEEP = ["sweep", "mobile_end", "--scheme", "fe", "--elements", "2", "--degree", "2",
         "--f1", "8:9:1", "--set", "sweep.lead_in_s=0.2", "--set", "sweep.min_periods=2",
         "--set", "sweep.max_periods=3", "--set", "sweep.record_periods=1", "--set",
         "sweep.periodic_tolerance=0.1", "--set", "time.dt_s=2e-3"]


@pytest.mark.parametrize("extra, kinds", [
    ([], {"slack", "moment_saturation"}),
    (["--set", "section.breaking_force_N=100"], {"slack", "moment_saturation", "breaking"})])
def test_a_sweep_prints_and_lists_each_kinds_first(tmp_path, extra, kinds):
    """A real FE sweep (N = 2, two f1, ~3 s): the end of its report has one line per
    kind, the same as summary.json's limits_first_by_kind; the figure is written."""
    from tests.test_docs import undocumented
    done = subprocess.run([sys.executable, "-m", "rawehelix.cli.main", *SWEEP, *extra, "-o",
                           "out"], cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    firsts = summary["limits_first_by_kind"]
    assert {k for k, x in firsts.items() if x} == kinds
    assert undocumented(summary) == []
    out = done.stdout
    assert "first limit of each kind (f1 rising, the sweep's order; 2 points, f1 = 8..9 Hz):" in out
    for kind in CRITERIA:
        name = branch_limits.NAMES[kind]
        x = firsts[kind]
        if x is None:
            assert (f"    {name}: not checked" in out) != (f"    {name}: not reached in f1 = 8..9 Hz"
                                                          in out)
        else:
            assert f"    {name}: " + ("already at the first point, " if
                                      x["already_at_first_point"] else "") + \
                f"f1 = {x['f1_Hz']:g} Hz, s = {x['s_m']:.3f} m" in out
    assert "breaking force: not checked" in out if "breaking" not in kinds else \
        "limit 100 N" in out
    assert (tmp_path / "out" / "sweep.png").stat().st_size > 0


def test_orbits_traced_downwards_prints_its_firsts_along_the_branch(tmp_path):
    """A real branch (FE shooting, N = 4, --f1 9.1:9.0, ~4 s): the order is the
    branch's (its first point at 9.1 Hz), each kind's first names its branch point,
    and the report's lines say so."""
    from rawehelix.studies import orbits
    done = subprocess.run([sys.executable, "-m", "rawehelix.cli.main", "orbits", "mobile_end",
                           "--elements", "4", "--f1", "9.1:9.0", "--superharmonics", "none",
                           "--set", "time.dt_s=1e-3", "-o", "out"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    s = json.loads((tmp_path / "out" / "summary.json").read_text())
    branch, firsts = s["branch"], s["limits_first_by_kind"]
    assert branch[0]["f1_Hz"] == 9.1 and s["limits"]["f1_range_Hz"][0] == 9.1
    assert f"first limit of each kind ({orbits.ALONG}; {len(branch)} points, f1 = 9.1.." \
        in done.stdout
    reached = [k for k, x in firsts.items() if x]
    assert reached  # this scene's solid section slackens its inner tether near 9 Hz
    for kind in reached:
        x = firsts[kind]
        assert branch[x["point"]]["f1_Hz"] == x["f1_Hz"]
        assert not any(branch_limits.kinds_of(p["limits"]).get(kind) for p in branch[:x["point"]])
        assert f"    {branch_limits.NAMES[kind]}: " in done.stdout


def test_the_figures_mark_each_kinds_first():
    """A vertical line a kind at its f1 on every panel (sweep, orbits), labelled once with
    its f1; on an envelope's rows a marker a kind, inside the window, labelled once."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    firsts = {"slack": {"f1_Hz": 1.44, "already_at_first_point": False},
              "torsional_collapse": {"f1_Hz": 1.0, "already_at_first_point": True},
              "breaking": None, "moment_saturation": None}
    fig, (a, b) = plt.subplots(2)
    branch_limits.mark_firsts((a, b), firsts)
    for ax in (a, b):
        assert sorted(line.get_xdata()[0] for line in ax.get_lines()) == [1.0, 1.44]
    labels = [line.get_label() for line in a.get_lines()]
    assert "first slack: 1.44 Hz" in labels
    assert "first torsional collapse: 1 Hz (already at the first point)" in labels
    assert not any(line.get_label().startswith("first") for line in b.get_lines())
    seen = set()
    fig2, ax = plt.subplots()
    for row in (1.0, 2.0):
        branch_limits.mark_firsts((ax,), firsts, row, seen, window=(1.2, 3.0))
    xs = sorted((line.get_xdata()[0], line.get_ydata()[0]) for line in ax.get_lines())
    assert xs == [(1.2, 1.0), (1.2, 2.0), (1.44, 1.0), (1.44, 2.0)]  # 1.0 Hz on the edge
    assert sum(line.get_label().startswith("first") for line in ax.get_lines()) == 2
    plt.close(fig)
    plt.close(fig2)
