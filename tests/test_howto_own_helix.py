"""The how-to "your own helix" (docs/howto/own_helix.md) as a new user runs it: its
scene, taken from the page, and its commands at small N.  The answers the page
quotes are the ones printed: the tension asked for is met, the 8-ring helix
collapses under its torque and the 31-ring one does not, and the forced run ends
with each limit's first f1 (or says it was not reached)."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

PAGE = Path(__file__).resolve().parents[1] / "docs" / "howto" / "own_helix.md"


def _scene(tmp_path: Path) -> Path:
    text = PAGE.read_text()
    toml = re.search(r"```toml\n(.*?)```", text, re.S).group(1)
    path = tmp_path / "my_helix.toml"
    path.write_text(toml)
    return path


def _run(*args, cwd):
    run = subprocess.run([sys.executable, "-m", "rawehelix.cli", *args], cwd=cwd,
                         capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr
    return run.stdout


def test_the_pages_commands_are_the_ones_it_runs():
    """Every command of the page is one of the commands below (a renamed option fails)."""
    text = PAGE.read_text()
    commands = re.findall(r"^    \.venv/bin/rawehelix (\w+) my_helix\.toml", text, re.M)
    assert commands == ["section", "stationary", "stationary", "modes", "orbits"]


def test_own_helix_section_and_stationary(tmp_path):
    scene = _scene(tmp_path)
    out = _run("section", str(scene), "-o", "sec", cwd=tmp_path)
    assert "8 rings, spacing 4.28571 m" in out and "EA = " in out
    summary = json.loads((tmp_path / "sec" / "summary.json").read_text())
    assert summary  # written
    out = _run("stationary", str(scene), "--elements", "4", "-o", "st8", cwd=tmp_path)
    mean = float(re.search(r"mean tension under the torque ([\d.]+) N", out).group(1))
    assert mean == pytest.approx(500.0, rel=1e-3)  # ends.tension_N, under the torque
    assert "first limit: torsional_collapse" in out  # 8 rings: 1.89 rad a bay > 1.585
    limits = json.loads((tmp_path / "st8" / "summary.json").read_text())["limits"]
    bay = 30.0 / 7
    assert limits["twist_per_length_max"]["value"] * bay > limits["criteria"]["torsional_collapse"]
    out = _run("stationary", str(scene), "--elements", "4", "--set", "section.rings=31",
               "-o", "st31", cwd=tmp_path)
    assert "first limit: none" in out


@pytest.mark.slow
def test_own_helix_forced_run_prints_each_limits_first(tmp_path):
    """The page's step 5 over a short window at N = 2: the report ends with each kind."""
    scene = _scene(tmp_path)
    out = _run("orbits", str(scene), "--elements", "2", "--f1", "0.5:0.8", "--method", "hb",
               "--set", "section.rings=31", "-o", "orb", cwd=tmp_path)
    assert "first limit of each kind" in out
    for kind in ("slack", "breaking force", "moment saturation", "torsional collapse"):
        assert re.search(rf"^    {kind}: ", out, re.M), kind
    summary = json.loads((tmp_path / "orb" / "summary.json").read_text())
    assert set(summary["limits_first_by_kind"]) == {"slack", "breaking", "moment_saturation",
                                                    "torsional_collapse"}
