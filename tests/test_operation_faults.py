"""Bad input of the machine's sections (issue 43: [rotor], [generator], [lifter], [wind]):
refused before any work with exit status 2, one line on stderr naming the key (and the
table's row and line), nothing written.  Each table fault and one bad key run as
subprocesses (the real command line); the other keys through the same entry point
in-process (cli.main), as tests/test_scenes.py does."""

from __future__ import annotations

import subprocess
import sys
import tomllib

import pytest

from rawehelix.cli import main as cli
from rawehelix.studies import scene
from tests_util import write_scene

RAWEHELIX = [sys.executable, "-m", "rawehelix.cli.main"]
HEADER = "# a rotor table\ntsr,cp,ct\n"
GOOD_ROWS = ["1.0,0.1,0.2", "3.0,0.3,0.5", "5.0,0.4,0.7", "7.0,0.2,0.8"]


def rows(**change) -> str:
    """The good table with row i (1-based) replaced: rows(r2="3.0,0.61,0.5")."""
    out = list(GOOD_ROWS)
    for key, line in change.items():
        index = int(key[1:]) - 1
        if line is None:
            del out[index:]
        else:
            out[index] = line
    return HEADER + "\n".join(out) + "\n"


# (the CSV, words of the one line): each table fault names its row and the file's line
TABLE_FAULTS = [
    (rows(r2="3.0,0.61,0.5"), 'rotor.table: "rotor.csv" line 4 (row 2): cp = 0.61 is above the Betz limit 16/27'),
    (rows(r3="2.0,0.4,0.7"), "line 5 (row 3): tsr = 2.0 does not increase: the table must be sorted in tsr"),
    (rows(r4="7.0,0.2,-0.1"), "line 6 (row 4): ct = -0.1 is negative"),
    (rows(r3=None), "has 2 rows: at least 3 are needed"),
    (rows(r2="3.0,nan,0.5"), "line 4: cp = nan is not a finite number"),
    (rows(r2="3.0,x,0.5"), "line 4: cp = 'x' is not a number"),
    ("tsr,cp\n1,0.1\n", "lacks the column 'ct'"),
]


def rotor_scene(tmp_path, csv: str | None = None):
    """rotor_example.toml with its table replaced by ``csv`` (rotor.csv beside it;
    None: rotor_example.csv's)."""
    data = tomllib.loads(scene.resolve("rotor_example").read_text())
    if csv is None:
        csv = (scene.SCENE_DIR / "rotor_example.csv").read_text()
    (tmp_path / "rotor.csv").write_text(csv)
    data["rotor"]["table"] = "rotor.csv"
    return write_scene(tmp_path / "bad.toml", {}, base=data)


def refused(argv, tmp_path, capsys) -> str:
    out = tmp_path / "out"
    assert cli.main([*argv, "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and not out.exists()
    return err


def refused_by_the_command_line(argv, tmp_path) -> str:
    """The real command line (a subprocess): exit 2, one line, no traceback, nothing
    written (neither -o nor ./results)."""
    run = subprocess.run([*RAWEHELIX, *argv, "-o", str(tmp_path / "out")], cwd=tmp_path,
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 2, run.stderr
    assert len(run.stderr.strip().splitlines()) == 1 and "Traceback" not in run.stderr
    assert not (tmp_path / "out").exists() and not (tmp_path / "results").exists()
    return run.stderr


@pytest.mark.parametrize("csv, words", TABLE_FAULTS, ids=[w.split(":")[-1][:30] for _, w in TABLE_FAULTS])
def test_each_table_fault_names_its_row(tmp_path, csv, words):
    """Each fault class of a rotor table, through the real command line."""
    path = rotor_scene(tmp_path, csv)
    err = refused_by_the_command_line(["stationary", str(path)], tmp_path)
    assert str(path) in err and words in err, err


SCENE_FAULTS = [
    # (overrides of rotor_example, words)
    ({"rotor.axis": "up"}, "rotor.axis: \"up\" must be one of ('tangent', 'wind')"),
    ({"rotor.tsr": [1.0, 2.0, 3.0]}, "rotor.tsr: and rotor.table both give the table: keep one"),
    ({"rotor.table": "nosuch.csv"}, 'rotor.table: "nosuch.csv" no such file in'),
    ({"rotor.radius_m": 0.0}, "rotor.radius_m: 0.0 must be a finite number > 0"),
    ({"rotor.table": "rotor.txt"}, "must be a CSV file's name (*.csv)"),
    ({"generator.law": "pid"}, "generator.law: \"pid\" must be one of ('paper', 'mppt', 'torque')"),
    ({"generator.law": "torque"}, "generator.mppt_gain_Nms2: 0.158314349441 is read only with generator.law = 'mppt'"),
    ({"controller.k1": 0.5}, "generator.law: \"mppt\" and [controller] (Eq. 40) both set the ground torque"),
    ({"torque.top_Nm": 25.0}, "torque.top_Nm: 25.0 and [rotor] both put a torque on the top end"),
    ({"lifter.top": "kite"}, "lifter.top: \"kite\" must be one of ('fixed', 'lifted', 'circle')"),
    ({"lifter.top": "lifted", "lifter.force_N": 300.0, "lifter.elevation_deg": 0.0},
     "lifter.elevation_deg: 0.0 must lie in (0, 90]"),
    ({"lifter.force_N": 300.0}, "lifter.force_N: 300.0 is read only with lifter.top = 'lifted'"),
    ({"wind.profile": "exp"}, "wind.profile: \"exp\" must be one of ('uniform', 'power', 'log')"),
    ({"environment.wind_speed_m_s": 10.0},
     "wind.speed_m_s: 6.6131 and environment.wind_speed_m_s = 10.0 both give the wind"),
    ({"environment.air_density_kg_m3": 1.1, "wind.air_density_kg_m3": 1.2},
     "wind.air_density_kg_m3: 1.2 and environment.air_density_kg_m3 = 1.1 differ"),
    ({"wind.profile": "power", "discretisation.scheme": "spline", "discretisation.elements": 4},
     "wind.profile: \"power\" is implemented by the FE scheme only"),
]


@pytest.mark.parametrize("changes, words", SCENE_FAULTS, ids=[str(list(c)) for c, _ in SCENE_FAULTS])
def test_each_bad_key_is_named(tmp_path, capsys, changes, words):
    path = rotor_scene(tmp_path)
    sets = [f"--set={k}={scene.toml_value(list(v) if isinstance(v, list) else v)}"
            for k, v in changes.items()]
    err = refused(["stationary", str(path), *sets], tmp_path, capsys)
    assert words in err, err


def test_the_command_line_refuses_a_bad_key_in_one_line(tmp_path):
    """A key of the machine's sections, through the real command line (modes)."""
    path = rotor_scene(tmp_path)
    err = refused_by_the_command_line(["modes", str(path), "--set",
                                       "environment.wind_speed_m_s=10"], tmp_path)
    assert ("wind.speed_m_s: 6.6131 and environment.wind_speed_m_s = 10.0 both give the wind"
            in err), err
