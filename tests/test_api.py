"""The README's Python example runs as it stands, and the API refuses bad input
with the command line's messages."""

import re
from pathlib import Path

import pytest

import rawehelix as rh

README = Path(__file__).resolve().parents[1] / "README.md"


def readme_example() -> str:
    text = README.read_text()
    section = text.split("## Python API", 1)[1]
    return re.search(r"```python\n(.*?)```", section, re.S).group(1)


@pytest.mark.long  # 47 s on an idle machine (2026-12-05): make test-long; make test keeps the
# API's pieces (test_bad_scene_values_raise_the_cli_message and the commands' own API tests)
def test_readme_example_runs(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    exec(compile(readme_example(), "README.md", "exec"), {})
    out = capsys.readouterr().out
    assert re.search(r"T\(0\) = 202\.\d\d N", out)  # Table 2: 202.9 N (shooting 202.885 N)
    assert "torsional" in out and "lateral_in_plane" in out
    assert re.search(r"f1 = 10\.0 Hz: T max \d+\.\d N", out)
    from rawehelix.cli.text import printable
    assert printable(out) == out, "the README's example prints a negative zero"
    assert (tmp_path / "results" / "api_example" / "summary.json").is_file()
    assert (tmp_path / "results" / "api_example" / "time_series.csv").is_file()


@pytest.mark.parametrize("kwargs,words", [
    ({"overrides": {"helix.EI_Nm2": -1.0}}, "helix.EI_Nm2"),
    ({"overrides": {"helix.stiffnes": 1.0}}, "unknown key"),  # (helix.stiffness is a key)
    ({"elements": 0}, "discretisation.elements"),
    ({"scheme": "hermite"}, "discretisation.scheme"),
])
def test_bad_scene_values_raise_the_cli_message(kwargs, words):
    with pytest.raises(rh.SceneError, match=words) as err:
        rh.load_scene("stationary_table2", **kwargs)
    assert "stationary_table2.toml" in str(err.value)


def test_refusals_live_in_the_library():
    spline = rh.load_scene("nominal_operation", scheme="spline", elements=2)
    with pytest.raises(rh.SceneError, match="FE scheme"):
        rh.stationary(spline)
    with pytest.raises(rh.SceneError, match="FE scheme"):
        rh.simulate(spline)
    with pytest.raises(rh.SceneError, match="until"):
        rh.simulate(rh.load_scene("nominal_operation", elements=2), until_s=-1.0)
    with pytest.raises(rh.SceneError, match="count"):
        rh.modes(rh.load_scene("stationary_table2", elements=2), count=0)
    with pytest.raises(rh.SceneError, match="f1"):
        rh.sweep(rh.load_scene("mobile_end", scheme="spline", elements=2), f1_Hz=[5.0, -1.0])


def test_import_is_light():
    """`import rawehelix` loads neither MPI nor FEniCSx (rendering subprocesses rely on it)."""
    import subprocess
    import sys
    code = ("import sys, rawehelix; heavy = [m for m in ('dolfinx', 'mpi4py', 'petsc4py', 'ufl')"
            " if m in sys.modules]; print(heavy)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


PUBLIC_FUNCTIONS = [name for name in rh.api.__all__ if callable(getattr(rh.api, name))
                    and not isinstance(getattr(rh.api, name), type)]


@pytest.mark.parametrize("name", PUBLIC_FUNCTIONS)
def test_every_parameter_of_the_api_is_described(name):
    """The API page (autodoc + napoleon) shows each parameter with its words:
    each one has an entry in its function's ``Args:`` section, with text."""
    import inspect
    func = getattr(rh.api, name)
    doc = inspect.getdoc(func)
    assert "Args:" in doc, name
    section = doc.split("Args:", 1)[1].split("\n\n", 1)[0]
    described = dict(re.findall(r"^    (\w+): (\S.*)$", section, re.M))
    assert set(described) == set(inspect.signature(func).parameters), name


def test_the_api_page_example_is_a_code_block():
    """The module docstring's example renders as a literal block, not a paragraph."""
    from docutils import nodes
    from docutils.core import publish_doctree
    tree = publish_doctree(rh.api.__doc__, settings_overrides={"report_level": 5})
    blocks = [n.astext() for n in tree.findall(nodes.literal_block)]
    assert any("rh.load_scene(" in b and "rh.simulate(" in b for b in blocks)


def test_user_facing_docstrings_name_no_issue_numbers():
    """The API's words say what a feature is, never the issue that brought it."""
    import inspect
    texts = [rh.api.__doc__] + [inspect.getdoc(getattr(rh.api, n)) for n in PUBLIC_FUNCTIONS]
    for text in texts:
        assert not re.search(r"\bissues? \d", text), text[:200]
