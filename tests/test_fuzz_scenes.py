"""Property-based fuzzing of scene values (issue 27): arbitrary TOML values for
every key give a loaded, valid scene or one line of bad input naming the key,
never a traceback.

The keys come from the loader's own schema (``scene.SECTIONS``, ``scene.NESTED``,
``scene.TOP_LEVEL`` and the dataclass fields behind them), so a new key is fuzzed
without editing this file.  Each example writes a shipped scene with one key (or
several) changed to a TOML value Hypothesis draws, and loads it the way a command
does (``rawehelix.load_scene``; ``--set KEY=VALUE`` through the CLI's own parser).
The property:

- the scene loads, and then it is valid: its normalised groups, Eqs. (25)-(29),
  are finite numbers (a solve can start from them); or
- it raises :class:`SceneError` whose message is one line and names the key;
- anything else (an uncaught exception) is a failure.

A few examples run the real CLI (``rawehelix modes SCENE --elements 2 --count 1``)
in a subprocess: exit 0; or exit 2 with one stderr line and nothing written; or exit
1 with one line of the solver's advice, for a valid scene no range can rule out (a
helix made slack by a combination of keys); never a traceback.

The counts (examples tried, refused, loaded) are printed at the end of a ``-s``
run.  The default run gives each key 12 examples (about 30 s); ``-m long`` runs
the bigger campaign whose figures the docs quote (150 a key; several minutes, so
marked ``long``: ``slow`` tests are part of ``make test``).
"""

from __future__ import annotations

import collections
import dataclasses
import datetime
import math
import os
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import rawehelix
from rawehelix import parameters
from rawehelix.cli import main as cli
from rawehelix.cli.commands import base as cli_base
from rawehelix.studies import scene

SHIPPED = sorted(p.stem for p in scene.SCENE_DIR.glob("*.toml"))


def schema() -> dict[str, str]:
    """Every scene key the loader validates, dotted, with its declared type name."""
    keys = {name: t.__name__ for name, t in scene.TOP_LEVEL.items()}
    for section, cls in scene.SECTIONS.items():
        for f in dataclasses.fields(cls):
            if f.name not in scene.NESTED:
                keys[f"{section}.{f.name}"] = f.type
    return keys


KEYS = schema()
#: the words a string key may take: every tuple of strings parameters.py checks against
CHOICES = sorted({word for value in vars(parameters).values() if isinstance(value, tuple)
                  for word in value if isinstance(word, str)} | {"auto", "off"})
LAW_KEYS = [f.name for f in dataclasses.fields(parameters.EILaw)]

COUNTS = collections.Counter()  # (way in, outcome) -> examples, over the whole module


@pytest.fixture(scope="module", autouse=True)
def report_counts():
    yield
    ways = sorted({way for way, _ in COUNTS})
    print("\nfuzz counts:")
    for way in ways:
        outcomes = ("exit 0", "exit 1", "exit 2") if way == "cli" else (
            "tried", "loaded", "refused", "traceback")
        print(f"  {way}: " + ", ".join(f"{o} {COUNTS[way, o]}" for o in outcomes))


# -- TOML values ------------------------------------------------------------------

# the edges Hypothesis would reach only by luck: 64-bit and float limits, ints past
# the largest float, and past Python's 4300-digit int <-> str limit
EDGE_INTS = [0, -1, 1, 2, 8, 9, 2**31, 2**63 - 1, 2**63, -2**63, 2**64, 10**18,
             10**309, -10**309, 10**4299 - 1]


class Digits(str):
    """An integer literal too long for Python's int <-> str conversion (4300
    digits): kept as its text, as the TOML file holds it."""


HUGE = [Digits("1" + "0" * 4300), Digits("-" + "9" * 5000)]
EDGE_FLOATS = [math.nan, -math.nan, math.inf, -math.inf, 0.0, -0.0, 5e-324, 2.2250738585072014e-308,
               1e-300, 1e-30, 1e-12, 0.5, 1.0, 1.5, 90.0, 90.0000001, 1e30, 1e300,
               1.7976931348623157e308]

ints = (st.integers() | st.sampled_from(EDGE_INTS) | st.sampled_from(EDGE_INTS).map(lambda i: -i)
        | st.sampled_from(HUGE))
floats = st.floats() | st.sampled_from(EDGE_FLOATS) | st.sampled_from(EDGE_FLOATS).map(lambda x: -x)
strings = st.text(max_size=12) | st.sampled_from(CHOICES)
dates = (st.datetimes(max_value=datetime.datetime(9999, 12, 31)) | st.dates() | st.times())
leaves = ints | floats | strings | st.booleans() | dates
#: numbers of every size: where a key's range and the scales of Eqs. (25)-(29) meet
magnitudes = (st.floats(min_value=5e-324, max_value=sys.float_info.max)
              | st.integers(min_value=1, max_value=10**6))
magnitudes = magnitudes | magnitudes.map(lambda x: -x)
toml_values = st.recursive(
    leaves, lambda inner: st.lists(inner, max_size=3)
    | st.dictionaries(st.text(max_size=6), inner, max_size=3), max_leaves=6)


def _string(s: str) -> str:
    """A TOML basic string: the control characters, ``"`` and ``\\`` escaped."""
    return '"' + "".join(f"\\u{ord(c):04x}" if ord(c) < 0x20 or c in '"\\\x7f' else c
                         for c in s) + '"'


def literal(v) -> str:
    """``v`` in TOML syntax (inline), as a user would write it."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, Digits):
        return str.__str__(v)
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return _string(v)
    if isinstance(v, (datetime.datetime, datetime.date, datetime.time)):
        return v.isoformat()
    if isinstance(v, list):
        return "[" + ", ".join(literal(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{_string(k)} = {literal(x)}" for k, x in v.items()) + "}"
    raise TypeError(v)


def dump(data: dict) -> str:
    """A scene's TOML text: top-level values, then one [section] per table."""
    lines = [f"{_string(k)} = {literal(v)}" for k, v in data.items() if not isinstance(v, dict)]
    for section, table in data.items():
        if isinstance(table, dict):
            lines.append(f"[{_string(section)}]")
            lines += [f"{_string(k)} = {literal(v)}" for k, v in table.items()]
    return "\n".join(lines) + "\n"


def test_literal_round_trips():
    """The TOML writer is exact: the fuzz writes what it means to write."""
    for v in [*EDGE_INTS, *EDGE_FLOATS[2:], "a\"b\\c\n\x7f\u2028", True,
              [1, "x", [2.5, {}]], {"k k": {"a": -0.0}}, datetime.time(1, 2, 3, 4),
              datetime.datetime(2000, 1, 1, 0, 0, 1, 5), datetime.date(1, 1, 1)]:
        got = tomllib.loads(f"v = {literal(v)}")["v"]
        assert got == v and repr(got) == repr(v), v
    assert math.isnan(tomllib.loads(f"v = {literal(math.nan)}")["v"])


# -- the edits Hypothesis draws ------------------------------------------------------

law_tables = st.dictionaries(st.sampled_from(LAW_KEYS) | st.text(max_size=6),
                             leaves, max_size=3)
#: besides the known keys: where a user's key may be wrong
UNKNOWN = ("<unknown key of a section>", "<unknown section>", "<unknown top-level key>",
           "<a section as a value>")
names = st.text(min_size=1, max_size=8)


@st.composite
def edits(draw, key: str | None = None):
    """(dotted key, value): ``key``, or one drawn from KEYS and UNKNOWN, with an
    arbitrary TOML value; a known key gets a number of any size half the time, and
    helix.EI_law also gets inline tables with its own keys."""
    key = key or draw(st.sampled_from([*sorted(KEYS), *UNKNOWN]))
    if key == UNKNOWN[0]:
        key = f"{draw(st.sampled_from(sorted(scene.SECTIONS)))}.{draw(names)}"
    elif key == UNKNOWN[1]:
        key = f"{draw(names)}.{draw(names)}"
    elif key == UNKNOWN[2]:
        key = draw(names.filter(lambda k: "." not in k))
    elif key == UNKNOWN[3]:
        key = draw(st.sampled_from(sorted(scene.SECTIONS)))
    elif key == "helix.EI_law" and draw(st.booleans()):
        return key, draw(law_tables)
    elif draw(st.booleans()):
        return key, draw(magnitudes)
    return key, draw(toml_values)


def apply(data: dict, key: str, value) -> dict:
    if key in scene.TOP_LEVEL or key in scene.SECTIONS or "." not in key:
        data[key] = value
        return data
    section, _, name = key.partition(".")
    table = data.get(section)
    if isinstance(table, dict):
        table[name] = value
    else:
        data[section] = {name: value}
    return data


def base(name: str) -> dict:
    return tomllib.loads(scene.resolve(name).read_text())


def check(way: str, load, changed: list[str]):
    """The property: ``load()`` gives a valid scene, or SceneError in one line naming
    one of the keys ``changed`` ("file" when it is not TOML that Python can read);
    returns "loaded" or "refused"."""
    COUNTS[way, "tried"] += 1
    try:
        params = load()
    except Exception as err:
        if not isinstance(err, scene.SceneError):
            COUNTS[way, "traceback"] += 1  # what a command would have shown
            raise
        message = str(err)
        assert len(message.splitlines()) == 1 and "\n" not in message, repr(message)
        # the key itself, its section (unknown sections, checks across a section) or a
        # key of it (a section replaced: a required key missing), or
        # the key in the explanation (checks across keys: f1_stop_Hz >= f1_start_Hz)
        assert any(err.key == c or c.startswith(err.key + ".") or err.key.startswith(c + ".")
                   or c in err.allowed
                   for c in changed), f"{message!r} names none of {changed}"
        COUNTS[way, "refused"] += 1
        return "refused"
    if not params.ends.resolved:  # ends.tension_N: the search starts from T / EA
        params = params.replace(ends={"elongation": params.ends.tension_N / params.helix.EA_N})
    q = params.normalised()  # valid: the groups a solve starts from are numbers
    numbers = {f.name: getattr(q, f.name) for f in dataclasses.fields(q)
               if not isinstance(getattr(q, f.name), str)}  # (section_law: a name)
    bad = {k: v for k, v in numbers.items() if not math.isfinite(v)}
    assert not bad, f"loaded with {changed}, but the normalised groups {bad} are not finite"
    assert q.L0 > 0 and q.t_scale > 0 and q.force_scale > 0 and q.sigma > 0 and q.mu > 0
    assert q.beta > 0 and q.delta > 0 and q.torque_scale > 0
    COUNTS[way, "loaded"] += 1
    return "loaded"


def beside(tmp_dir: Path) -> None:
    """The shipped scenes' tables (the rotor's CSV) beside a scene written to ``tmp_dir``:
    a table's path is relative to its scene."""
    for table in scene.SCENE_DIR.glob("*.csv"):
        (tmp_dir / table.name).write_bytes(table.read_bytes())


def check_file(tmp_dir: Path, scene_name: str, changes: list[tuple[str, object]]):
    data = base(scene_name)
    for key, value in changes:
        data = apply(data, key, value)
    beside(tmp_dir)
    path = tmp_dir / f"{scene_name}.toml"
    path.write_text(dump(data))
    way = "file, one key" if len(changes) == 1 else "file, several keys"
    try:
        tomllib.loads(path.read_text())
    except ValueError:  # an integer past Python's 4300 digits: the file is named
        return check(way, lambda: rawehelix.load_scene(path), ["file"])
    return check(way, lambda: rawehelix.load_scene(path), [k for k, _ in changes])


def check_set(scene_name: str, key: str, value):
    """``--set KEY=VALUE`` through the CLI's own parser and override path."""
    item = f"{key}={literal(value)}"
    # --set=ITEM: an ITEM that starts with "-" would be an option to argparse
    args = cli._parser().parse_args(["modes", scene_name, f"--set={item}"])
    typed = item.partition("=")[0]  # what --set takes for the key (a key may hold "=")
    return check("--set", lambda: rawehelix.load_scene(args.scene, overrides=cli_base.overrides(args)),
                 [typed, typed.strip()])


PER_KEY = settings(max_examples=12, derandomize=True, deadline=None, database=None,
                   suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                          HealthCheck.function_scoped_fixture])
MIXED = settings(PER_KEY, max_examples=300)
#: the campaign whose figures the docs quote (make test-long; -m long)
PER_KEY_BIG = settings(PER_KEY, max_examples=150)
MIXED_BIG = settings(PER_KEY, max_examples=3000)
scenes = st.sampled_from(SHIPPED)
every_key = pytest.mark.parametrize("key", [*sorted(KEYS), *UNKNOWN])


@every_key
@PER_KEY
@given(data=st.data())
def test_each_key_in_the_file(tmp_path, key, data):
    check_file(tmp_path, data.draw(scenes), [data.draw(edits(key))])


@every_key
@PER_KEY
@given(data=st.data())
def test_each_key_by_set(key, data):
    check_set(data.draw(scenes), *data.draw(edits(key)))


@MIXED
@given(scene_name=scenes, changes=st.lists(edits(), min_size=2, max_size=5))
def test_several_keys_in_the_file(tmp_path_factory, scene_name, changes):
    check_file(tmp_path_factory.mktemp("fuzz"), scene_name, changes)


@pytest.mark.long
@every_key
@PER_KEY_BIG
@given(data=st.data())
def test_each_key_in_the_file_big(tmp_path, key, data):
    check_file(tmp_path, data.draw(scenes), [data.draw(edits(key))])


@pytest.mark.long
@every_key
@PER_KEY_BIG
@given(data=st.data())
def test_each_key_by_set_big(key, data):
    check_set(data.draw(scenes), *data.draw(edits(key)))


@pytest.mark.long
@MIXED_BIG
@given(scene_name=scenes, changes=st.lists(edits(), min_size=2, max_size=5))
def test_several_keys_in_the_file_big(tmp_path_factory, scene_name, changes):
    check_file(tmp_path_factory.mktemp("fuzz"), scene_name, changes)


def test_every_shipped_key_is_in_the_schema():
    """The fuzzed keys are the loader's: every key of a shipped scene is one of them."""
    for name in SHIPPED:
        for section, table in base(name).items():
            keys = [section] if not isinstance(table, dict) else [f"{section}.{k}" for k in table]
            assert set(keys) <= set(KEYS), (name, keys)
    assert {k.partition(".")[0] for k in KEYS} == {*scene.SECTIONS, *scene.TOP_LEVEL}


# -- the real command line ------------------------------------------------------------

# `python -m`: make test-debian13 runs the package from PYTHONPATH, with no script
RAWEHELIX = [sys.executable, "-m", "rawehelix.cli.main"]


def run_cli(tmp_dir: Path, scene_name: str, changes) -> subprocess.CompletedProcess:
    """``rawehelix modes SCENE --elements 2 --count 1`` on the changed scene: the
    cheapest command that validates, solves and stops."""
    data = base(scene_name)
    for key, value in changes:
        data = apply(data, key, value)
    beside(tmp_dir)
    path = tmp_dir / f"{scene_name}.toml"
    path.write_text(dump(data))
    out = tmp_dir / "out"
    proc = subprocess.run([*RAWEHELIX, "modes", str(path), "--elements", "2", "--count", "1",
                           "-o", str(out)], capture_output=True, text=True, timeout=300,
                          cwd=tmp_dir, env={**os.environ, "OMP_NUM_THREADS": "1"})
    COUNTS["cli", f"exit {proc.returncode}"] += 1
    if proc.returncode == 1:
        print(f"\n  exit 1 with {changes}: {proc.stderr.strip()}")
    assert "Traceback" not in proc.stderr, proc.stderr
    if proc.returncode == 0:
        assert (out / "summary.json").is_file()
        return proc
    # 2: bad input; 1: a valid scene whose solve fails (a slack helix: a combination
    # of keys no range can decide), with the solver's advice; both in one line
    assert proc.returncode in (1, 2), (proc.returncode, proc.stderr)
    assert len(proc.stderr.strip().splitlines()) == 1, proc.stderr
    assert proc.stderr.startswith("rawehelix: "), proc.stderr
    if proc.returncode == 2:
        assert not out.exists()
    return proc


CLI = settings(PER_KEY, max_examples=6)


@CLI
@given(scene_name=scenes, edit=edits())
def test_cli_one_line_no_traceback(tmp_path_factory, scene_name, edit):
    run_cli(tmp_path_factory.mktemp("cli"), scene_name, [edit])


@pytest.mark.long
@settings(CLI, max_examples=100)
@given(scene_name=scenes, edit=edits())
def test_cli_one_line_no_traceback_big(tmp_path_factory, scene_name, edit):
    run_cli(tmp_path_factory.mktemp("cli"), scene_name, [edit])


# -- the gaps the fuzzing found, each pinned ----------------------------------------------

GAPS = [
    # (changes, words of the one-line message); each gave a traceback before its fix
    ([("helix.length_m", 10**309)], "helix.length_m: must be a finite number"),  # OverflowError
    ([("helix.EI_law", {"a_Nm2_per_N": -10**309, "b_Nm2": 1})],
     "helix.EI_law.a_Nm2_per_N"),  # OverflowError in float()
    ([("helix.length_m", HUGE[0])], "file: line"),  # tomllib's bare ValueError
    ([("helix.col\nour", 1)], "'helix.col\\nour': unknown key"),  # two lines
    ([("environment.g_m_s2", 1e-323)], "t_scale = sqrt(L0/g) = inf"),  # ZeroDivisionError
    ([("helix.mass_kg", 1.7976931348623157e308)], "force_scale = M g = inf"),
    ([("ends.circle_frequency_Hz", 1.7e308)], "omega1 = 2 pi f1 sqrt(L0/g) = inf"),
    ([("helix.length_m", 2.2e-311)], "helix.EI_Nm2: 12800.0 must be at most"),  # ZeroDivision
    ([("environment.air_density_kg_m3", 1.7e308)], "nu = rho0 l_a L0^2 C_D/(2 M) = inf"),
    ([("torsion_hysteresis.rho", 0.5), ("torsion_hysteresis.beta_m_n", 1.0),
      ("torsion_hysteresis.n", 564033)], "bw_beta = beta/L0^n = 0.0"),  # OverflowError in **
    ([("torsion_hysteresis.rho", 1e-110)], "with torsion_hysteresis.rho = 1e-110"),  # named gamma
    ([("torsion_hysteresis.gamma_m_n", math.nan)], "torsion_hysteresis.gamma_m_n: nan must"),
    # exit 1 with the C compiler's traceback ("inf" in the form's code); 1e8: wrong modes
    ([("discretisation.penalty", 1.78e308)], "discretisation.penalty: 1.78e+308 must be"),
    ([("discretisation.penalty", 1e8)], "discretisation.penalty: 100000000.0 must be"),
    # exit 1, a singular Jacobian: no rod is that stiff in bending for its stretch
    ([("helix.EI_Nm2", 5.2e67)], "helix.EI_Nm2: 5.2e+67 must be at most helix.EA_N x"),
]


@pytest.mark.parametrize("changes,words", GAPS)
def test_found_gaps_are_refused_in_one_line(tmp_path, capsys, changes, words):
    """Each gap as the command line meets it: exit 2, one line naming the key, nothing written."""
    data = base("example")
    for key, value in changes:
        data = apply(data, key, value)
    path = tmp_path / "gap.toml"
    path.write_text(dump(data))
    out = tmp_path / "out"
    assert cli.main(["modes", str(path), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and words in err, err
    assert not out.exists()


def test_scene_not_utf8_and_set_past_the_digit_limit(tmp_path, capsys):
    path = tmp_path / "latin1.toml"
    path.write_bytes(scene.resolve("example").read_bytes().replace(b"Example", b"Exempl\xe9"))
    assert cli.main(["modes", str(path), "-o", str(tmp_path / "o")]) == 2
    assert "file: is not UTF-8 text" in capsys.readouterr().err
    assert cli.main(["modes", "example", f"--set=helix.length_m={HUGE[0]}",
                     "-o", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and "helix.length_m: must be a number" in err
    assert not (tmp_path / "o").exists()
