"""The tutorials (docs/tutorials/*.py) run as they stand, at small N.

Each script is executed in a fresh interpreter with RAWEHELIX_TUTORIAL_SMALL=1
(small N, short runs) and RAWEHELIX_TUTORIAL_OUT in a temporary folder; a
script fails on its own checks (asserts against the paper's table, closed
forms or another method), on any error of the API it uses, or when it writes
nothing.  Every tutorial page (docs/tutorials/*.md) includes its script, and
every script has its page.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

TUTORIALS = Path(__file__).resolve().parents[1] / "docs" / "tutorials"
SCRIPTS = sorted(TUTORIALS.glob("*.py"))
# the scripts' small-run CPU times (s) measured on the shared 2-core machine:
# stationary_table2 17, nominal_operation 9, mobile_end 20, frequency_response 48,
# parameter_study 6
SLOW = {"frequency_response"}  # can exceed a minute of wall time on a busy machine


def run(script: Path, out: Path) -> subprocess.CompletedProcess:
    env = {**os.environ, "RAWEHELIX_TUTORIAL_SMALL": "1", "RAWEHELIX_TUTORIAL_OUT": str(out)}
    return subprocess.run([sys.executable, str(script)], env=env, capture_output=True,
                          text=True, timeout=600)


def test_there_are_the_five_tutorials():
    assert {s.stem for s in SCRIPTS} == {"stationary_table2", "nominal_operation", "mobile_end",
                                        "frequency_response", "parameter_study"}


#: the two longest (50 and 24 s): make test's 12-minute budget (2026-12-04); make test-long
LONG = {"frequency_response", "mobile_end"}


@pytest.mark.parametrize("script", [pytest.param(s, id=s.stem, marks=[pytest.mark.long]
                                                 if s.stem in LONG else
                                                 [pytest.mark.slow] if s.stem in SLOW else [])
                                    for s in SCRIPTS])
def test_tutorial_runs_at_small_size(script, tmp_path):
    proc = run(script, tmp_path)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert "Traceback" not in proc.stderr
    written = tmp_path / script.stem
    assert written.is_dir() and any(p.is_file() for p in written.rglob("*")), \
        f"{script.name} wrote nothing into {written}"
    assert f"written: {written}" in proc.stdout


@pytest.mark.parametrize("script", SCRIPTS, ids=[s.stem for s in SCRIPTS])
def test_tutorial_is_a_percent_script_with_its_page(script):
    """jupytext's percent format (prose in `# %% [markdown]` cells, code in
    `# %%` cells), the small-run switch read, and a page that includes it."""
    text = script.read_text()
    assert text.count("# %% [markdown]") >= 2
    assert re.search(r"^# %%$", text, re.M)
    assert "RAWEHELIX_TUTORIAL_SMALL" in text and "RAWEHELIX_TUTORIAL_OUT" in text
    page = script.with_suffix(".md")
    assert page.is_file(), f"{page.name} missing"
    assert re.search(r"```\{literalinclude\} " + re.escape(script.name), page.read_text())
    assert script.stem in (TUTORIALS / "index.md").read_text()
