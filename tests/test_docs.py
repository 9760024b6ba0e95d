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


def test_scene_tables_and_code_fit_the_page(site):
    """The scene-key tables sit in the container the site's CSS fits to the
    page's width (their long cells wrap), and code blocks wrap long lines."""
    page = (site / "reference" / "scene.html").read_text()
    tables = page.count("<table")
    assert tables >= len(scene.SECTIONS)
    assert page.count('class="scene-keys docutils container"') == tables
    css = (site / "_static" / "custom.css").read_text()
    assert re.search(r"\.scene-keys table\.docutils \{[^}]*width: 100%", css)
    assert re.search(r"\.scene-keys td:nth-child\(n\+5\) \{ overflow-wrap: anywhere", css)
    assert re.search(r"div\.highlight pre \{ white-space: pre-wrap", css)


def test_api_page_has_every_function(site):
    import rawehelix.api
    page = (site / "reference" / "api.html").read_text()
    for name in rawehelix.api.__all__:
        if name[0].islower():
            assert f'id="rawehelix.api.{name}"' in page, name


def test_api_page_example_is_code_and_every_parameter_has_words(site):
    """The module example renders as a code block, and no parameter's entry is
    only its name and type (autodoc's typehints with no description)."""
    page = (site / "reference" / "api.html").read_text()
    blocks = [re.sub(r"<[^>]+>", "", b) for b in re.findall(r"<pre>(.*?)</pre>", page, re.S)]
    assert any("rh.load_scene(" in b and "rh.simulate(" in b for b in blocks)
    assert not re.search(r"<strong>\w+</strong> \([^)]*\)</p>", page)  # a parameter, no words
    assert "<strong>scene</strong>" in page


#: user-facing pages: every page of the site but the fault table (its rows cite
#: the issues their faults were filed in) and the README
USER_PAGES = [p for p in DOCS.rglob("*.md") if "_build" not in p.parts
              and p.name != "faults.md"] + [ROOT / "README.md"]


def test_user_pages_name_what_a_feature_is_not_its_issue():
    for page in USER_PAGES:
        found = re.search(r"\bissues? \d+", page.read_text(), re.I)
        assert not found, f"{page.relative_to(ROOT)}: {found.group(0)}"


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


def test_allowed_is_short_and_names_no_probe_value():
    """A bound computed from other keys (EI <= EA L0^2, Wen's |gamma| <= beta) is
    stated once, as the rule, not once per probe value of the other keys; no
    cell quotes the generator's probes (1e-300, 1e300) or grows to a wall of text."""
    rows = {f"{r['section']}.{r['key']}": r for r in reference.scene_key_rows()}
    for r in rows.values():
        assert "e-300" not in r["allowed"] and "e+300" not in r["allowed"], r
        assert len(r["allowed"]) < 250, r
    ei = rows["helix.EI_Nm2"]["allowed"]
    assert "must be at most helix.EA_N x helix.length_m^2 (a slender rod" in ei
    assert ei.count("at most") == 1
    gamma = rows["torsion_hysteresis.gamma_m_n"]["allowed"]
    assert "rho < 1" in gamma and gamma.count("needs") == 1


def test_a_switch_rule_names_the_value_it_is_about():
    """`model.twist = false` needs a torque-free scene, not `model.twist`: the
    reference and the loader's message spell the value as the scene file does."""
    rules = dict(reference._cross_section_rules())
    assert "model.twist = false" in rules and "model.twist" not in rules
    assert 'model.kinematics = "extensible"' in rules
    with pytest.raises(scene.SceneError) as err:
        scene.load("nominal_operation", overrides={"model.twist": False})
    assert "model.twist: false needs a torque-free scene" in str(err.value)
    assert "False" not in str(err.value)


@pytest.mark.parametrize("value", [False, True, "ip", 'a "quoted" word', 1e-05, 3, -2.5, 1e300])
def test_messages_spell_values_as_a_scene_file_does(value):
    """What a message quotes can be pasted into a scene file (or --set) as is."""
    assert tomllib.loads(f"v = {scene.toml_value(value)}")["v"] == value


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
