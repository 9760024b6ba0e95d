"""Output-folder faults of the multi-point commands (issue 41): an envelope rerun into
its own folder with any argument changed, two --vary given to envelope, and a command
run into another command's folder are refused with one line and exit status 2, the
folder unchanged; a write that fails mid-file leaves no ``Exception ignored`` behind."""

import hashlib
import subprocess
import sys
from pathlib import Path

import pytest

CLI = [sys.executable, "-m", "rawehelix.cli.main"]
ENVELOPE = ["envelope", "mobile_end", "--elements", "2", "--degree", "3"]
VARY, F1 = ["--vary", "helix.EI_Nm2=4381:4600:2"], ["--f1", "12.3:12.5"]


def run(args, cwd):
    return subprocess.run([*CLI, *args], cwd=cwd, capture_output=True, text=True, timeout=300)


def snapshot(folder: Path) -> dict:
    """Every file's path, size, mtime and content hash under ``folder``."""
    return {str(p.relative_to(folder)): (p.stat().st_size, p.stat().st_mtime_ns,
                                         hashlib.sha256(p.read_bytes()).hexdigest())
            for p in sorted(folder.rglob("*")) if p.is_file()}


def assert_one_line(done, *words):
    lines = done.stderr.strip().splitlines()
    assert done.returncode == 2, done.stderr
    assert len(lines) == 1 and lines[0].startswith("rawehelix: error: "), done.stderr
    assert "Traceback" not in done.stderr + done.stdout
    for word in words:
        assert word in lines[0], lines[0]


@pytest.fixture(scope="module")
def envelope_dir(tmp_path_factory):
    """A finished envelope (N = 2, two values, ~12 s)."""
    cwd = tmp_path_factory.mktemp("envelope")
    done = run([*ENVELOPE, *VARY, *F1, "-o", "out"], cwd)
    assert done.returncode == 0, done.stderr
    return cwd, cwd / "out"


@pytest.mark.parametrize("change, option", [
    (["--vary", "helix.EI_Nm2=4381:4600:3", *F1], "--vary LO:HI:COUNT"),
    (["--vary", "helix.mass_kg=0.5:1:2", *F1], "--vary KEY"),
    ([*VARY, "--f1", "12.3:12.6"], "--f1"),
    ([*VARY, *F1, "--method", "shooting"], "--method"),
    ([*VARY, *F1, "--set", "ends.elongation=0.004"], "--set"),
])
def test_an_envelope_rerun_with_an_argument_changed_is_refused(envelope_dir, change, option):
    cwd, out = envelope_dir
    before = snapshot(out)
    done = run([*ENVELOPE, *change, "-o", "out"], cwd)
    assert_one_line(done, "-o", "holds another envelope", option, "use another -o")
    if option == "--set":  # the key and its two values are named
        assert "ends.elongation 0.002 -> 0.004" in done.stderr
    assert snapshot(out) == before


def test_two_vary_are_refused(tmp_path):
    done = run([*ENVELOPE, *VARY, "--vary", "helix.mass_kg=0.5:1:2", *F1, "-o", "out"], tmp_path)
    assert_one_line(done, "--vary", "more than once", "rawehelix study")
    assert list(tmp_path.iterdir()) == []


# a process whose files may not grow past a few kB (RLIMIT_FSIZE: a write past it fails
# with EFBIG, a disk's error, as a full disk's ENOSPC): the .npz of a state fails mid-file
SMALL_FILES = """
import resource, signal, sys
import numpy as np
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
resource.setrlimit(resource.RLIMIT_FSIZE, (4096, 4096))
from rawehelix.studies.store import outdir_lock, writers
try:
    writers.write_npz(sys.argv[1], {"X": np.ones(100000), "state_ds": np.ones(3)})
except outdir_lock.OutputFault as err:
    print(f"rawehelix: error: {err}", file=sys.stderr)
    sys.exit(1)
"""


@pytest.mark.parametrize("name", ["points/f1_00009.00000.npz", "window0/p0003.npz",
                                  "tick1/window0/p0000.npz"])
def test_a_failed_npz_write_leaves_one_line_and_no_temporary(tmp_path, name):
    """The stores of sweep, orbits and envelope write their states by write_npz: a
    write that fails mid-file ends with the one-line fault and nothing after it (no
    ``Exception ignored in ZipFile.__del__``), and no file left."""
    path = tmp_path / name
    path.parent.mkdir(parents=True)
    done = subprocess.run([sys.executable, "-c", SMALL_FILES, str(path)], capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 1, done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and path.name in lines[0] and "File too large" in lines[0], done.stderr
    assert list(path.parent.iterdir()) == []


def test_another_command_into_an_envelopes_folder_is_refused(envelope_dir):
    cwd, out = envelope_dir
    before = snapshot(out)
    assert (out / ".rawehelix-command").read_text().strip() == "envelope"
    for argv in (["sweep", "mobile_end", "--f1", "9:10:1"], ["orbits", "mobile_end", "--f1", "9:10"],
                 ["stationary", "mobile_end"]):
        done = run([*argv, "-o", "out"], cwd)
        assert_one_line(done, "-o", "holds the output of 'rawehelix envelope'",
                        f"use another -o directory for '{argv[0]}'")
        assert snapshot(out) == before


@pytest.mark.long  # 10 s; make test's budget (test_faults keeps a case of the same refusal)
def test_each_command_keeps_its_own_folder(tmp_path):
    """stationary's folder: stationary again runs (its own), modes is refused; a folder
    of an older rawehelix (no marker) is known by its store's header file (sweep.json);
    a refused command writes no marker into a new folder."""
    st = ["stationary_table2", "--elements", "4", "-o", "st"]
    assert run(["stationary", *st], tmp_path).returncode == 0
    assert run(["stationary", *st], tmp_path).returncode == 0
    before = snapshot(tmp_path / "st")
    assert_one_line(run(["modes", *st], tmp_path), "'rawehelix stationary'", "'modes'")
    assert snapshot(tmp_path / "st") == before
    old = tmp_path / "old"
    old.mkdir()
    (old / "sweep.json").write_text("{}")
    assert_one_line(run(["orbits", "mobile_end", "--f1", "9:10", "-o", "old"], tmp_path),
                    "'rawehelix sweep'", "'orbits'")
    assert sorted(p.name for p in old.iterdir()) == ["sweep.json"]
    assert_one_line(run(["modes", "stationary_table2", "--elements", "0", "-o", "new"], tmp_path),
                    "discretisation.elements")
    assert not (tmp_path / "new").exists()
