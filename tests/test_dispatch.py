"""No choice is made by testing a name where a registered object owns it (issue 42):
outside ``parameters/`` (where a scene's names are checked), the product's modules
test no ``scheme ==`` / ``scheme !=``, no orbit method by name (``== "hb"``,
``== "shooting"``, ``method ==`` / ``in``) and probe no interface with ``hasattr(``.
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
    # the orbit method (studies/orbit_method.py's registry): its names compared, or a
    # method (method, self.method, s["method"]) compared or looked up in a tuple
    "orbit method by name": re.compile(
        r"(==|!=)\s*[\"'](hb|shooting)[\"']|[\"'](hb|shooting)[\"']\s*(==|!=)"
        r"|\bmethod(\b|[\"']\])\s*(==|!=|not\s+in\b|in\b)"),
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


def test_the_orbit_method_check_catches_each_form(tmp_path):
    """Each way of choosing the orbit method by name is found; the registry's look-up
    and a mention in a comment are not."""
    (tmp_path / "probe.py").write_text(
        'if method == "hb":\n    pass\n'
        'if "shooting" != self.method:\n    pass\n'
        'if s["method"] != x:\n    pass\n'
        'if method in ("hb", "auto"):\n    pass\n'
        'm = orbit_method.get(method).problem(params)  # not method == "hb"\n'
        'if result.method == "hb":  # dispatch-ok: a justified survivor\n    pass\n')
    found = survivors(PATTERNS["orbit method by name"], tmp_path, [Path("probe.py")])
    assert sorted(int(f.split(":")[1]) for f in found) == [1, 3, 5, 7], found


def test_the_orbit_methods_registry_owns_the_command_lines_choices():
    """``--method``'s choices and each command's default are the registry's; an
    unknown name is refused once, naming every method."""
    from rawehelix.cli.main import _parser
    from rawehelix.errors import SceneError
    from rawehelix.studies import orbit_method

    parser = _parser()
    for command in orbit_method.DEFAULTS:
        args = parser.parse_args([command, "mobile_end", "--f1", "10:9",
                                  *(["--vary", "helix.EI_Nm2=1:2"] if command == "envelope" else [])])
        assert args.method == orbit_method.default_for(command)
    assert set(orbit_method.METHODS) == {"shooting", "hb", "auto"}
    with pytest.raises(SceneError) as err:
        orbit_method.get("fourier")
    assert all(name in str(err.value) for name in orbit_method.METHODS)


def test_the_orbit_problems_interface_carries_no_methods_knob():
    """``PeriodicOrbitProblem.orbit`` takes what every method takes; shooting's lead-in
    and linear chord are the period map's own keywords, reached through the
    interface's ``first_orbit`` and ``predicted_orbit`` (harmonic balance has neither)."""
    import inspect

    from rawehelix.periodic_orbits.floquet import PeriodMap
    from rawehelix.periodic_orbits.problem import PeriodicOrbitProblem
    from rawehelix.solvers.harmonic_balance.problem import HarmonicBalance

    def knobs(cls):
        return set(inspect.signature(cls.orbit).parameters)

    shared = knobs(PeriodicOrbitProblem)
    assert not shared & {"lead_in", "linear"}
    assert knobs(HarmonicBalance) == shared
    assert knobs(PeriodMap) >= shared | {"lead_in", "linear"}
    for name in ("first_orbit", "predicted_orbit"):
        assert getattr(PeriodMap, name) is not getattr(PeriodicOrbitProblem, name)
    for name in ("X_stationary", "q_base", "q"):  # declared, with their words
        assert name in PeriodicOrbitProblem.__annotations__


def test_the_forced_backends_declare_the_interface():
    """solvers/periodic.py asks a backend for its parts through its declared interface
    (no getattr probe): both schemes' backends have every method of it."""
    from rawehelix.references.spline_galerkin.forced import SplineBackend
    from rawehelix.solvers.forced import FEBackend
    from rawehelix.solvers.periodic import Backend
    methods = [n for n, v in vars(Backend).items() if callable(v) and not n.startswith("_")]
    assert "parts" in methods
    for cls in (FEBackend, SplineBackend):
        assert [n for n in methods if not callable(getattr(cls, n, None))] == [], cls
    assert SplineBackend.parts(None) is None
