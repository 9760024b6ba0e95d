"""The architecture is checked, not only described (issue 28; docs/explanation/architecture.md).

* the import contracts of .importlinter hold (``lint-imports``): the layers run
  one way, and the paper's references import no FE code;
* no two modules import each other, directly or round a longer loop, not even
  inside a function (import-linter has no such contract: grimp's graph, the one
  it reads, searched here for strongly connected components);
* no product module is longer than MAX_LINES unless it is listed in LONG with
  the one job it does.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("importlinter.cli")
grimp = pytest.importorskip("grimp")

ROOT = Path(__file__).resolve().parents[1]
MAX_LINES = 400  # "no product module over about 400 lines holds more than one job"
#: the longer modules and their one job
LONG: dict[str, str] = {
    "studies/present/render.py": "off-screen pyvista pictures of the helix; one file because, once "
                         "DOLFINx is loaded, each picture is drawn in a fresh interpreter that "
                         "loads this file alone (a VTK/DOLFINx library clash)",
    "solvers/dynamics.py": "the PETSc TS driver (options, stepping, output times, failures); "
                           "the states it takes and returns and what it reports of them are "
                           "dynamics_states.py and dynamics_outputs.py, the time data it "
                           "installs (the wind, a release) solvers/weather.py, the lifted "
                           "top's terms solvers/lifted_top.py",
    "solvers/harmonic_balance/problem.py": "HarmonicBalance, the periodic-orbit problem by "
                                           "harmonic balance (its residual, Jacobian, Newton, "
                                           "and where the guarded stability step hooks in); "
                                           "the Fourier algebra is harmonics.py, Hill's method "
                                           "hill.py, the guard's rules stability.py",
    "solvers/ts_forms.py": "the rod equations (30)-(31) as PETSc TS residuals, second and first "
                           "order, with the terms the ends add to them (Eq. 40's controller, "
                           "the machine's torques, the lifted top): the terms themselves are "
                           "forms/end_torques.py, forms/lifter.py and solvers/lifted_top.py",
}


def test_import_contracts_hold():
    """``lint-imports``, in a child process: it reconfigures logging (the loggers of
    the tests that follow would be silenced)."""
    code = ("import sys; from importlinter.cli import lint_imports; "
            f"sys.exit(lint_imports(config_filename={str(ROOT / '.importlinter')!r}, "
            "no_cache=True))")
    run = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True)
    assert run.returncode == 0, run.stdout + run.stderr


def _cycles(edges: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components with more than one module (Tarjan)."""
    index, low, stack, on, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in edges.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                out.append(sorted(component))

    for v in sorted(edges):
        if v not in index:
            visit(v)
    return out


def test_cycle_search_finds_a_loop():
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert _cycles({"a": {"b"}, "b": set()}) == []


def test_no_import_cycles():
    graph = grimp.build_graph("rawehelix", include_external_packages=False)
    edges = {m: set(graph.find_modules_directly_imported_by(m)) for m in graph.modules}
    # a package's __init__ that re-exports its own modules is not a loop of jobs
    for m, targets in edges.items():
        edges[m] = {t for t in targets if not m.startswith(t + ".")}
    assert _cycles(edges) == []


#: the subfolders of studies/ (the .importlinter contract places the flat ones: present,
#: analysis, store), and the driver-level modules one of them may still import, each
#: with its reason; any other arrow from a subfolder up to a driver is refused
STUDIES_SUBFOLDERS = ("converge", "extremes", "present", "analysis", "store")
UP_ARROWS = {
    ("rawehelix.studies.converge.methods", "rawehelix.studies.schemes"):
        "the scheme registry gives each method its scheme's runs",
    ("rawehelix.studies.converge.methods", "rawehelix.studies.reference_check"):
        "the independent shooting reference of the tension at s = 0",
}


def test_no_studies_subfolder_imports_a_driver_but_the_named_ones():
    """A module inside a subfolder of studies/ imports no driver-level module of
    studies/ (the quantities' registry gives converge its quantity), but UP_ARROWS."""
    graph = grimp.build_graph("rawehelix", include_external_packages=False)
    found = set()
    for m in graph.modules:
        parts = m.split(".")
        if len(parts) < 4 or parts[1] != "studies" or parts[2] not in STUDIES_SUBFOLDERS:
            continue
        for t in graph.find_modules_directly_imported_by(m):
            tp = t.split(".")
            if tp[:2] == ["rawehelix", "studies"] and len(tp) == 3 \
                    and tp[2] not in STUDIES_SUBFOLDERS:
                found.add((m, t))
    assert found - set(UP_ARROWS) == set()
    assert ("rawehelix.studies.converge.study", "rawehelix.studies.quantities") not in found


def _product_modules():
    skip = {"tests", "docs", "benchmarks", "scripts", ".venv", "build"}
    for path in sorted(ROOT.rglob("*.py")):
        rel = path.relative_to(ROOT)
        if rel.parts[0] in skip or rel.parts[0].startswith(".") or "egg-info" in rel.parts[0]:
            continue
        yield str(rel), len(path.read_text().splitlines())


def test_long_modules_each_do_one_named_job():
    long = {name: n for name, n in _product_modules() if n > MAX_LINES}
    unnamed = {name: n for name, n in long.items() if name not in LONG}
    assert not unnamed, f"over {MAX_LINES} lines: split them or name their one job in LONG"
    assert not set(LONG) - set(long), "LONG names a module that is short now: drop it"


def test_the_package_docstring_names_every_room():
    """rawehelix/__init__.py's docstring names each subpackage and top-level module."""
    import rawehelix
    rooms = {p.name for p in ROOT.iterdir() if (p / "__init__.py").exists()
             and p.name not in ("tests", "docs", "benchmarks", "scripts")}
    rooms |= {p.stem for p in ROOT.glob("*.py") if p.stem not in ("__init__", "setup")}
    missing = [r for r in sorted(rooms) if f"``{r}``" not in rawehelix.__doc__
               and f"``rawehelix.{r}``" not in rawehelix.__doc__]
    assert missing == []
