"""No choice is made by testing a name where a registered object owns it (issue 42):
outside ``parameters/`` (where a scene's names are checked), the product's modules
test no ``scheme ==`` / ``scheme !=`` and probe no interface with ``hasattr(``.
A survivor is allowed only on a line (or the line above it) that says why with the
marker ``# dispatch-ok: <why>`` (the marker is shared: other name tests use it)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
#: the folders outside the product's dispatch (a scene's own checks, tests, tools)
OUTSIDE = {"parameters", "tests", "docs", "scripts", "benchmarks", ".venv", "build"}
#: the marker that justifies a survivor, with its reason
MARKER = re.compile(r"#\s*dispatch-ok:\s*\S")
#: the patterns of a choice made by name or by probing
PATTERNS = {
    "scheme by name": re.compile(r"\bscheme(\b|[\"']\])\s*(==|!=)"),  # also info["scheme"] ==
    "hasattr probe": re.compile(r"\bhasattr\("),
}


def product_files():
    for path in sorted(ROOT.rglob("*.py")):
        rel = path.relative_to(ROOT)
        if rel.parts[0] in OUTSIDE or any(p.startswith(".") for p in rel.parts):
            continue
        yield rel


def survivors(pattern, root: Path = ROOT, files=None) -> list[str]:
    """``path:line: text`` of each unjustified match of ``pattern`` (comments aside)."""
    out = []
    for rel in files if files is not None else product_files():
        lines = (root / rel).read_text().splitlines()
        for i, line in enumerate(lines):
            code = line.split("#", 1)[0]
            if not pattern.search(code):
                continue
            if MARKER.search(line) or (i > 0 and MARKER.search(lines[i - 1])):
                continue
            out.append(f"{rel}:{i + 1}: {line.strip()}")
    return out


def test_the_product_files_are_found():
    files = [str(f) for f in product_files()]
    assert "studies/schemes.py" in files and "solvers/discrete.py" in files
    assert not any(f.startswith(("parameters/", "tests/")) for f in files)


@pytest.mark.parametrize("what", PATTERNS)
def test_no_choice_by_name_or_probe(what):
    """Each decision is the registered object's (studies/schemes.py,
    parameters/schemes.py) or a declared attribute of its interface."""
    assert survivors(PATTERNS[what]) == []


def test_the_check_catches_a_name_test_and_accepts_a_justified_one(tmp_path):
    """The grep is not vacuous: an unjustified test is found, a justified one (on
    its line or the line above) is not, nor a mention in a comment."""
    (tmp_path / "probe.py").write_text(
        'if params.discretisation.scheme == "fe":\n    pass\n'
        'if hasattr(x, "y"):  # dispatch-ok: a version probe\n    pass\n'
        '# dispatch-ok: the line below, justified above it\n'
        'if scheme != "spline":\n    pass\n'
        'x = 1  # a comment: scheme == "fe" is not code\n'
        'if hasattr(rod, "model"):\n    pass\n'
        'if info["scheme"] == "fe":\n    pass\n')
    found = [s for p in PATTERNS.values() for s in survivors(p, tmp_path, [Path("probe.py")])]
    assert sorted(int(f.split(":")[1]) for f in found) == [1, 9, 11], found
