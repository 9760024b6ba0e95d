"""The documentation: the site builds with warnings as errors, every page's
local references exist, the README's links exist, the generated reference
pages cover every command and scene key, and every summary.json field the
stored results and a few cheap runs produce is documented."""

from __future__ import annotations

import dataclasses
import importlib.util
import json
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from rawehelix.cli import main as cli
from rawehelix.studies import scene

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
SUMMARY_PAGE = DOCS / "reference" / "summary.md"


def _load(path: Path, name: str):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


check_page = _load(ROOT / "scripts" / "check_page.py", "check_page")
reference = _load(DOCS / "_ext" / "rawehelix_reference.py", "rawehelix_reference")


# -- the site -------------------------------------------------------------------

@pytest.fixture(scope="module")
def site(tmp_path_factory):
    """The site built as `make docs` builds it, with warnings as errors."""
    pytest.importorskip("sphinx", reason="sphinx is not installed (scripts/install.sh brings "
                                         "python3-sphinx, python3-myst-parser and furo)")
    pytest.importorskip("myst_parser", reason="myst-parser is not installed")
    out = tmp_path_factory.mktemp("site")
    run = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html",
                          "-d", str(out / "doctrees"), str(DOCS), str(out / "html")],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr + run.stdout
    return out / "html"


def test_site_builds_and_every_local_reference_exists(site):
    pages = sorted(site.rglob("*.html"))
    assert len(pages) >= 8
    missing = {str(p.relative_to(site)): [str(m) for m in check_page.missing_references(p)]
               for p in pages}
    assert not {k: v for k, v in missing.items() if v}


def test_myst_plugins_work_with_the_docs_configuration(tmp_path):
    """Footnotes and definition lists parse under docs/conf.py, whatever
    markdown-it-py the venv holds (conf.py takes the one beside myst-parser)."""
    pytest.importorskip("myst_parser", reason="myst-parser is not installed")
    (tmp_path / "conf.py").write_text(
        "import runpy\n"
        f"globals().update(runpy.run_path({str(DOCS / 'conf.py')!r}))\n"
        "extensions = ['myst_parser']\nexclude_patterns = []\nhtml_static_path = []\n")
    (tmp_path / "index.md").write_text("# Page\n\nA claim[^1].\n\n[^1]: its source\n\n"
                                       "term\n: its definition\n")
    run = subprocess.run([sys.executable, "-m", "sphinx", "-W", "-q", "-b", "html",
                          str(tmp_path), str(tmp_path / "html")],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    page = (tmp_path / "html" / "index.html").read_text()
    assert "footnote" in page and "<dl" in page


def test_site_has_the_four_parts(site):
    index = (site / "index.html").read_text()
    for part in ("tutorials/index.html", "howto/index.html", "explanation/index.html",
                 "reference/index.html"):
        assert f'href="{part}"' in index, part


def test_command_page_has_every_command_and_option(site):
    page = (site / "reference" / "commands.html").read_text()
    for name, _, sub in reference._subparsers(cli._parser()):
        assert f'id="rawehelix-{name}"' in page, name
        for action in sub._actions:
            for flag in action.option_strings:
                assert flag in page, f"{name} {flag}"


def test_scene_page_has_every_key(site):
    page = (site / "reference" / "scene.html").read_text()
    for section, cls in scene.SECTIONS.items():
        for f in dataclasses.fields(cls):
            if f.name not in scene.NESTED:
                assert f"{section}.{f.name}" in page


def test_api_page_has_every_function(site):
    import rawehelix.api
    page = (site / "reference" / "api.html").read_text()
    for name in rawehelix.api.__all__:
        if name[0].islower():
            assert f'id="rawehelix.api.{name}"' in page, name


# -- the README -----------------------------------------------------------------

LINK = re.compile(r"\]\(([^)\s]+)\)")


def test_readme_links_exist():
    text = (ROOT / "README.md").read_text()
    targets = [t for t in LINK.findall(text) if not re.match(r"[a-z]+:", t) and not
               t.startswith("#")]
    assert targets, "the README links to no file"
    missing = [t for t in targets if not (ROOT / t.split("#")[0]).exists()]
    assert not missing


def test_readme_is_a_front_page():
    text = (ROOT / "README.md").read_text()
    assert len(text.splitlines()) <= 250
    for command in ("make demo", "make test", "make docs"):
        assert command in text


def test_readme_commands_are_the_parsers():
    """Each command line of the README names a real command and only its options."""
    text = (ROOT / "README.md").read_text().split("## Commands", 1)[1]
    lines = re.findall(r"^    rawehelix (\S+)(.*)$", text, re.M)
    subs = {name: sub for name, _, sub in reference._subparsers(cli._parser())}
    assert sorted(name for name, _ in lines) == sorted(subs)
    for name, rest in lines:
        known = {flag for action in subs[name]._actions for flag in action.option_strings}
        for flag in re.findall(r"(?<![\w-])(--?[a-z][\w-]*)", rest):
            assert flag in known, f"rawehelix {name} {flag}"


# -- the scene keys generator ---------------------------------------------------

def test_scene_key_rows_cover_every_key_with_range_and_unit():
    rows = reference.scene_key_rows()
    keys = {f"{r['section']}.{r['key']}" for r in rows}
    expected = {f"{s}.{f.name}" for s, cls in scene.SECTIONS.items()
                for f in dataclasses.fields(cls) if f.name not in scene.NESTED}
    assert keys == expected
    for r in rows:
        assert r["allowed"] != "not checked", r
        assert r["meaning"], r
        if r["key"].endswith("_Hz"):
            assert r["unit"] == "Hz"


def test_scene_key_defaults_agree_with_example_toml():
    """example.toml (written by hand, checked against the dataclasses by
    test_scenes.py) shows each optional key at its default: the generated
    table must say the same defaults."""
    example = tomllib.loads(scene.resolve("example").read_text())
    for r in reference.scene_key_rows():
        if r["default"] in ("required", "absent"):
            continue
        shown = example[r["section"]][r["key"]]
        if isinstance(shown, bool):
            assert r["default"] == ("true" if shown else "false"), r
        elif isinstance(shown, str):
            assert r["default"] == f'"{shown}"', r
        else:
            assert float(r["default"]) == pytest.approx(shown), r


def test_allowed_comes_from_the_validation():
    """A range the generator reports is the loader's message for a value outside it."""
    rows = {f"{r['section']}.{r['key']}": r for r in reference.scene_key_rows()}
    for key, bad in (("discretisation.degree", 9), ("ends.elevation_deg", 91.0),
                     ("sweep.samples_per_period", 4), ("torsion_hysteresis.rho", 0.0)):
        with pytest.raises(scene.SceneError) as err:
            scene.load("stationary_table2", overrides={key: bad})
        assert rows[key]["allowed"].split("; ")[0] in str(err.value)


# -- summary.json fields --------------------------------------------------------

PLACEHOLDERS = {"<KEY>": r"[a-z_]+\.[A-Za-z0-9_]+", "<Q>": r"[A-Za-z0-9_@.]+",
                "<ID>": r"p\d+", "*": r".+"}


def documented_fields(page: Path = SUMMARY_PAGE) -> list[tuple[str, str]]:
    """(key, unit) of every table row of the summary page."""
    rows = re.findall(r"^\| `([^`]+)` \| ([^|]*) \|", page.read_text(), re.M)
    return [(key, unit.strip()) for key, unit in rows]


def _pattern(key: str) -> re.Pattern:
    """A documented key as a regex: its placeholders (PLACEHOLDERS) matched by pattern."""
    pieces = re.split(r"(<KEY>|<Q>|<ID>|\*)", key)
    return re.compile("".join(PLACEHOLDERS.get(p, re.escape(p)) for p in pieces) + r"\Z")


def field_paths(obj, prefix: str = "") -> set[str]:
    """Every key of a summary as a path: ``a.b`` inside objects, ``a[].b`` in lists."""
    out = set()
    if isinstance(obj, dict):
        for k, v in obj.items():
            path = f"{prefix}.{k}" if prefix else str(k)
            out |= {path} | field_paths(v, path)
    elif isinstance(obj, list):
        for v in obj:
            out |= field_paths(v, prefix + "[]")
    return out


def undocumented(summary: dict) -> list[str]:
    patterns = [_pattern(key) for key, _ in documented_fields()]
    return sorted(p for p in field_paths(summary) if not any(r.match(p) for r in patterns))


def test_summary_page_rows_have_a_unit():
    rows = documented_fields()
    assert len(rows) > 150
    assert all(unit for _, unit in rows)


def test_the_field_check_can_fail():
    assert undocumented({"points": [{"f1_Hz": 1.0, "no_such_field_N": 2.0}]}) == \
        ["points[].no_such_field_N"]
    assert undocumented({"sensitivities": {"tension_s0_N": {"helix.EI_Nm2": 0.1}}}) == []
    assert undocumented({"failed": {"x1": {}}}) == ["failed.x1"]


def test_stored_summaries_are_documented():
    stored = [p for p in DOCS.rglob("summary.json") if "_build" not in p.parts]
    assert stored, "no summary.json under docs/"
    missing = {str(p.relative_to(DOCS)): undocumented(json.loads(p.read_text()))
               for p in stored}
    assert not {k: v for k, v in missing.items() if v}


def test_cheap_runs_summaries_are_documented():
    """The commands without a stored result, each at its cheapest."""
    import rawehelix as rh
    runs = {
        "stationary": rh.stationary(rh.load_scene("stationary_table2", elements=4)),
        # ends.tension_N and a balanced end torque (the ends and torque blocks)
        "stationary (tension, torque)": rh.stationary(rh.load_scene(
            Path(__file__).parent / "data" / "own_helix.toml", elements=4)),
        "modes (spline)": rh.modes(rh.load_scene("stationary_table2", elements=2,
                                                 scheme="spline")),
        "modes (fe)": rh.modes(rh.load_scene("stationary_table2", elements=4)),
        "simulate": rh.simulate(rh.load_scene("nominal_operation", elements=4), until_s=0.05),
        "response": rh.response(rh.load_scene("mobile_end", elements=4), f1_Hz=[5.0, 9.0]),
    }
    missing = {name: undocumented(r.summary) for name, r in runs.items()}
    assert not {k: v for k, v in missing.items() if v}
