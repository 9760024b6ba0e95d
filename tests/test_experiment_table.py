"""scripts/experiment_table.py, the table against the experiment (issue 29), on
hand-made sweeps and branches whose answers are known."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

spec = importlib.util.spec_from_file_location(
    "experiment_table", Path(__file__).resolve().parents[1] / "scripts" / "experiment_table.py")
table = importlib.util.module_from_spec(spec)
spec.loader.exec_module(table)


def point(f1, T, periodic=True, slack=0.0, force=10.0, dT=2.0):
    return {"f1_Hz": f1, "tension_max_N": T, "tension_min_N": T - dT, "periodic": periodic,
            "limits": {"status": "recorded", "slack_fraction_max": slack,
                       "max_member_force_N": {"value": force}}}


def test_a_sweep_column():
    sweep = {"points": [point(1.0, 100.0, periodic=False, dT=0.1), point(2.0, 105.0),
                        point(3.0, 115.0, slack=1 / 6, force=60.0), point(4.0, 400.0, force=150.0),
                        point(5.0, 120.0, periodic=False)]}
    col = table.column(sweep, [50.0, 500.0])
    assert col["rise"] == "2.50 [2, 3]"  # 110 N halfway from 105 to 115
    assert col["slack"] == "(2, 3]"  # an indicator: its bracket only
    assert col["x3"] == "3.65 [3, 4]"  # 300 N on the way from 115 to 400
    assert col["break50"] == "2.80 [2, 3]" and col["break500"] == "-"
    # the first not-periodic point (1 Hz, oscillating 0.1 N: settling, starred) comes first
    assert col["stability"] == "not periodic at 1*, 5"


def test_a_jump_down_is_the_followed_branchs_fold():
    sweep = {"points": [point(1.0, 100.0), point(2.0, 300.0), point(3.0, 110.0)]}
    assert table.column(sweep, [])["stability"] == "(2, 3] (jump down: a fold)"


def test_an_orbit_branch_is_walked_up_from_its_low_end_to_its_fold():
    """A hardening resonance computed downward from 4 Hz: the lower branch to its
    fold at 2.6 Hz, the unstable one up to 3.2 Hz, the upper one down to 1 Hz.
    Rising f1 follows the upper branch to the fold at 3.2 Hz."""
    branch = [(4.0, 100.0), (3.0, 110.0), (2.6, 130.0), (2.9, 250.0), (3.2, 400.0),
              (2.9, 420.0), (2.0, 200.0), (1.0, 100.0)]
    orbits = {"branch": [{"f1_Hz": f, "tension_max_N": T} for f, T in branch],
              "folds": [{"f1_Hz": 2.6}, {"f1_Hz": 3.2}], "bifurcations": []}
    col = table.column(orbits, [100.0])
    assert col["x3"] == "2.41 [2, 2.9]"  # 300 N between 200 (2 Hz) and 420 N (2.9 Hz)
    assert col["stability"] == "3.20 (fold)"
    assert col["slack"] == "n/r" and col["break100"] == "n/r"  # not recorded: said so
