"""Scenes: the shipped files, their normalisation, and every kind of bad input.

Bad input exits with status 2, one message naming file, key and what is
allowed, and no output directory."""

import dataclasses
import math
import re
import tomllib
from pathlib import Path

import pytest

from rawehelix import parameters
from rawehelix.cli import main as cli
from rawehelix.studies import scene
from tests_util import write_scene

SHIPPED = ("stationary_table2", "nominal_operation", "mobile_end", "example", "rotor_example")


@pytest.mark.parametrize("name", SHIPPED)
def test_shipped_scenes_load(name):
    p = scene.load(name)
    assert p.discretisation.scheme == "fe"
    assert p.normalised().chord_tension() > 0


def test_table2_normalisation_matches_paper():
    """Sec. 5.2: m_N0 = 2.88 and t0 = 2 correspond to 25 Nm and 2.6 s; Sec. 5.1:
    the torsional period 2 sqrt(L0/(delta g)) is about 0.4 s."""
    q = scene.load("nominal_operation").normalised()
    assert q.mN0 == pytest.approx(2.88, abs=0.005)
    assert q.t0 == pytest.approx(2.0, abs=0.01)
    assert 2 * math.sqrt(16.12 / (q.delta * 9.81)) == pytest.approx(0.4, abs=0.01)
    assert q.tension_N(q.chord_tension()) == pytest.approx(200.2, abs=0.1)  # EA eps0


def test_mobile_end_top_follows_eq70():
    q = scene.load("mobile_end").normalised()
    r0 = q.top_position(0.0)
    assert r0[1] == pytest.approx(0.1 / 7.9)  # r1 cos(0) j_E
    # the circle has radius R1 about the chord end
    centre = q.top_position(0.0) - q.r1 * (q.top_position(0.0) - q.top_position(math.pi / q.omega1)) / (2 * q.r1)
    for t in (0.1, 0.37, 1.2):
        assert abs(abs(sum((q.top_position(t) - centre) ** 2)) ** 0.5 - q.r1) < 1e-12


# The keys of example.toml that do not show their default, on purpose: the
# required ones have none (their values there are Table 2's).
EXAMPLE_NOT_DEFAULT = {"helix.length_m", "helix.mass_kg", "helix.EA_N", "helix.EI_Nm2",
                       "helix.GJ_Nm2", "ends.elevation_deg"}
# Keys of a pair a scene gives exactly one of: example.toml shows the first with a
# value (not its default, None), the second commented out
EXAMPLE_ONE_OF = {"ends.elongation": "ends.tension_N"}


def test_example_documents_every_key_with_its_default():
    """example.toml names every section and key of the parameter dataclasses,
    shows each default, and comments every key line."""
    path = scene.resolve("example")
    data = tomllib.loads(path.read_text())
    required = set()
    # the sections of Parameters, and those held by another section ([damping] in the model)
    sections = [s.name for s in dataclasses.fields(parameters.Parameters)
                if s.name in scene.SECTIONS] + list(scene.NESTED)
    assert set(sections) == set(scene.SECTIONS)
    for name in sections:  # (not the labels name and title: file name, title line)
        table = data.get(name)
        assert isinstance(table, dict), f"[{name}] is missing"
        fields = [f for f in dataclasses.fields(scene.SECTIONS[name])
                  if f.name not in scene.NESTED]
        # a key whose default is None (absent: TOML has no null) is shown commented out,
        # unless another key makes it required (helix.EA_N, EI_Nm2, GJ_Nm2: required
        # unless helix.stiffness = "from_section") or it is one of two alternatives
        given = {f"helix.{k}" for k in parameters.sections.STIFFNESS_KEYS}
        absent = {f.name for f in fields if f.default is None
                  and f"{name}.{f.name}" not in given and f"{name}.{f.name}" not in EXAMPLE_ONE_OF}
        assert set(table) == {f.name for f in fields} - absent, f"[{name}]: keys differ"
        for f in fields:
            key = f"{name}.{f.name}"
            if f.name in absent:
                assert re.search(rf"^# {f.name} = ", path.read_text(), re.M), f"{key} not shown"
                continue
            if key in EXAMPLE_ONE_OF:
                assert table[f.name] is not None and EXAMPLE_ONE_OF[key].split(".")[1] \
                    not in table, f"{key}: shown, and its alternative commented out"
            elif f.default is dataclasses.MISSING or key in given:
                required.add(key)
            elif key not in EXAMPLE_NOT_DEFAULT:
                assert table[f.name] == f.default and type(table[f.name]) is type(f.default), \
                    f"{key} = {table[f.name]!r}, default {f.default!r}"
    assert required == EXAMPLE_NOT_DEFAULT
    for line in path.read_text().splitlines():
        if re.match(r"\s*\w+\s*=", line):
            assert "#" in line, f"example.toml: {line!r} has no comment"


BAD = [
    # (section, key, value, words expected in the message)
    ("helix", "colour", "red", "unknown key"),
    ("helix", "length_m", "long", "must be a number"),
    ("discretisation", "elements", 2.5, "must be an integer"),
    ("model", "gravity", 1, "true or false"),
    ("helix", "length_m", 0.0, "> 0"),
    ("helix", "mass_kg", -1.0, "> 0"),
    ("helix", "EA_N", 0.0, "> 0"),
    ("helix", "EI_Nm2", -5.0, "> 0"),
    ("helix", "GJ_Nm2", 0.0, "> 0"),
    ("ends", "elongation", 0.0, "tension"),
    ("ends", "elongation", -0.01, "tension"),
    ("discretisation", "elements", 0, ">= 1"),
    ("discretisation", "degree", 1, "2 to 8"),
    ("discretisation", "scheme", "hermite", "one of"),
]


@pytest.mark.parametrize("section,key,value,words", BAD)
def test_bad_input_exits_2_and_writes_nothing(tmp_path, capsys, section, key, value, words):
    path = write_scene(tmp_path / "bad.toml", {section: {key: value}})
    out = tmp_path / "out"
    assert cli.main(["stationary", str(path), "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert str(path) in err and f"{section}.{key}" in err and words in err
    assert not out.exists()


@pytest.mark.parametrize("flag,value,key", [("--elements", "0", "discretisation.elements"),
                                            ("--degree", "1", "discretisation.degree")])
def test_bad_override_exits_2(tmp_path, capsys, flag, value, key):
    out = tmp_path / "out"
    assert cli.main(["stationary", "stationary_table2", flag, value, "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert key in err and "stationary_table2.toml" in err
    assert not out.exists()


def test_missing_file(tmp_path, capsys):
    out = tmp_path / "out"
    missing = tmp_path / "nowhere.toml"
    assert cli.main(["stationary", str(missing), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert str(missing) in err and "no such scene file" in err
    assert not out.exists()


def test_unknown_section_and_missing_section(tmp_path, capsys):
    path = write_scene(tmp_path / "s.toml", {"weather": {"rain": True}})
    assert cli.main(["stationary", str(path), "-o", str(tmp_path / "o")]) == 2
    assert "weather" in capsys.readouterr().err
    data = tomllib.loads(scene.resolve("stationary_table2").read_text())
    del data["ends"]
    path = write_scene(tmp_path / "t.toml", {}, base=data)
    assert cli.main(["stationary", str(path), "-o", str(tmp_path / "o")]) == 2
    assert "[ends]" in capsys.readouterr().err


def test_a_runs_advice_names_a_scene_file_that_loads_as_printed(tmp_path, monkeypatch):
    """The advice of a run (sweep's 'rawehelix orbits NAME ...', stationary's 'rawehelix
    simulate NAME ...') names the scene by ``params.name``, the file's stem: beside the
    file that name loads the file (the tester's D1: it failed 'no such scene file');
    a shipped scene's name still loads the shipped scene."""
    shipped = scene.resolve("stationary_table2")
    (tmp_path / "my_helix.toml").write_text(shipped.read_text())
    monkeypatch.chdir(tmp_path)
    params = scene.load("my_helix.toml")
    assert params.name == "my_helix"
    assert scene.resolve(params.name) == Path("my_helix.toml")
    assert scene.load(params.name) == params
    assert scene.resolve("stationary_table2") == shipped
    with pytest.raises(scene.SceneError, match="no such scene file"):
        scene.load("not_my_helix")
