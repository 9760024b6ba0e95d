"""Issue 27: one writer per output folder, and stored points that are checked.

Most tests drive the stores (sweep_store, pool, orbits' WindowStore) with tiny
fakes instead of solvers: a fake evaluation, a fake periodic response whose
T max depends on the state it continued from, fake orbits.  One end-to-end
test starts two `rawehelix sweep` runs of different scenes together on one
folder.
"""

from __future__ import annotations

import errno
import json
import logging
import os
import shutil
import signal
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI

from rawehelix.studies.store import checkpoints, outdir_lock, writers

from rawehelix.studies import pool, quantities
from tests_util import world_folder

SELF = MPI.COMM_SELF
BROKEN = "rawehelix_test_broken_option"  # a PETSc option the fake evaluation fails under


def temps(folder: Path) -> list[Path]:
    return [p for p in Path(folder).rglob(".*") if p.name.endswith(writers.TEMP_SUFFIXES)]


def set_aside(folder: Path) -> list[str]:
    return sorted(p.name for p in (Path(folder) / checkpoints.CORRUPT).rglob("*") if p.is_file())


# -- the lock ---------------------------------------------------------------------------------
HOLDER = """
import sys, time
from rawehelix.studies.store import outdir_lock
held = outdir_lock.hold(sys.argv[1])
print("held", flush=True)
time.sleep(120)
"""


def start_holder(folder: Path) -> subprocess.Popen:
    proc = subprocess.Popen([sys.executable, "-c", HOLDER, str(folder)], stdout=subprocess.PIPE,
                            text=True)
    assert proc.stdout.readline().strip() == "held"
    return proc


def test_a_held_folder_is_refused_naming_the_holder_and_a_killed_holder_blocks_nothing(tmp_path):
    """The second run gets FolderBusy (a SceneError: exit 2) naming the folder
    and the holder's pid; after SIGKILL of the holder (its .lock file stays)
    the folder is taken at once; releasing removes .lock and the folder that
    the lock made, if nothing was written."""
    folder = tmp_path / "out"
    proc = start_holder(folder)
    try:
        with pytest.raises(outdir_lock.FolderBusy) as info:
            outdir_lock.hold(folder, SELF)
        assert f"pid {proc.pid} on host" in str(info.value)
        assert str(folder) in str(info.value) and str(info.value).startswith("-o: ")
        assert isinstance(info.value, outdir_lock.SceneError)
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.wait()
    assert (folder / outdir_lock.LOCK).exists()  # stale: the kernel released the flock
    held = outdir_lock.hold(folder, SELF)
    assert f"pid {os.getpid()}" in (folder / outdir_lock.LOCK).read_text()
    again = outdir_lock.hold(folder, SELF)  # reentrant within a process
    again.release()
    assert (folder / outdir_lock.LOCK).exists()
    held.release()
    assert not (folder / outdir_lock.LOCK).exists()
    made = tmp_path / "new"
    with outdir_lock.hold(made, SELF):
        assert made.is_dir()
    assert not made.exists()  # made by the lock, nothing written: gone again


def test_taking_the_lock_removes_a_killed_runs_temporary_files(tmp_path):
    (tmp_path / "points").mkdir()
    stale = [tmp_path / ".sweep.json.k3j_x9ab.tmp", tmp_path / "points" / ".f1.json.abc.tmp",
             tmp_path / "points" / ".f1_0006.00000.1234.tmp.npz"]
    keep = [tmp_path / "points" / "f1.json", tmp_path / ".hidden"]
    for p in stale + keep:
        p.write_text("x")
    with outdir_lock.hold(tmp_path, SELF):
        assert [p for p in stale if p.exists()] == []
        assert all(p.exists() for p in keep)


@pytest.mark.mpi
def test_under_mpi_rank_0_holds_the_lock_and_every_rank_gets_the_verdict(tmp_path_factory):
    comm, folder = world_folder(tmp_path_factory, "lock", "run under mpirun -n 2")
    proc = start_holder(folder / "out") if comm.rank == 0 else None
    comm.Barrier()
    try:
        with pytest.raises(outdir_lock.FolderBusy, match="is in use by another run"):
            outdir_lock.hold(folder / "out", comm)
    finally:
        if proc:
            proc.send_signal(signal.SIGKILL)
            proc.wait()
    comm.Barrier()
    pid = comm.bcast(os.getpid(), root=0)
    with outdir_lock.hold(folder / "out", comm) as held:
        text = (folder / "out" / outdir_lock.LOCK).read_text()
        comm.Barrier()  # read on both ranks before rank 0 lets go
    assert text.startswith(f"pid {pid} ")
    assert (held._release is not None) == (comm.rank == 0)  # rank 0 alone held the flock


# -- writes that fail -------------------------------------------------------------------------
def test_a_failed_write_leaves_no_temporary_file_and_names_the_file(tmp_path, monkeypatch):
    """ENOSPC at the rename (write_text) or in the middle of np.savez
    (write_npz): an OutputFault naming the file, the old file intact, no
    temporary file left."""
    target = writers.write_json(tmp_path / "a.json", {"old": 1})

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")
    with monkeypatch.context() as m:
        m.setattr(writers.os, "replace", full)
        with pytest.raises(outdir_lock.OutputFault, match="a.json: not written: No space"):
            writers.write_json(target, {"new": 2})
    assert json.loads(target.read_text()) == {"old": 1}

    def half(f, **arrays):
        f.write(b"PK\x03\x04 half a zip")
        raise OSError(errno.ENOSPC, "No space left on device")
    with monkeypatch.context() as m:
        m.setattr(writers.np, "savez", half)
        with pytest.raises(outdir_lock.OutputFault, match="b.npz"):
            writers.write_npz(tmp_path / "b.npz", {"x": np.ones(3)})
    with monkeypatch.context() as m:
        m.setattr(writers.os, "write", full)
        with pytest.raises(outdir_lock.OutputFault, match="computed.log"):
            writers.append_line(tmp_path / "computed.log", "p00001 rank 0")
    assert temps(tmp_path) == [] and not (tmp_path / "b.npz").exists()


# -- pool (study, calibrate): a fake evaluation ------------------------------------------------
EVALUATED: list[str] = []


def fake_evaluate(params, wanted, timed_out=None):
    """Q = x^2; every point fails while the PETSc option BROKEN is set."""
    from petsc4py import PETSc
    EVALUATED.append(params["id"])
    if PETSc.Options().hasName(BROKEN):
        return {"values": dict.fromkeys(wanted), "errors": dict.fromkeys(wanted, "broken option"),
                "cpu_s": {}, "wall_s": {}}
    return {"values": {q: params["x"] ** 2 for q in wanted}, "errors": {}, "cpu_s": {"q": 0.0},
            "wall_s": {"q": 0.0}}


TASKS = [pool.Task(f"p{k:05d}", {"id": f"p{k:05d}", "x": float(k)}) for k in range(5)]


def run_pool(folder, header=None, tasks=TASKS):
    store = pool.Store(folder, header or {"study": "fake"}).open(SELF)
    out = pool.run(tasks, lambda over: over, ["q"], store, comm=SELF)
    return {k: (r["status"], r["values"]["q"]) for k, r in out["records"].items()}, out["computed"]


@pytest.fixture
def fake(monkeypatch):
    monkeypatch.setattr(quantities, "evaluate", fake_evaluate)
    EVALUATED.clear()
    return EVALUATED


REFERENCE = {t.id: ("ok", t.overrides["x"] ** 2) for t in TASKS}


def test_a_rerun_with_other_petsc_options_retries_the_failed_points(tmp_path, fake, caplog):
    """The PETSc options are part of a point's fingerprint: points that failed
    under a broken option are computed again by the corrected rerun (the issue's
    "0 computed now; 5 failed"), each set aside with a warning naming it."""
    from petsc4py import PETSc
    PETSc.Options()[BROKEN] = 1
    try:
        first, n = run_pool(tmp_path)
        assert n == 5 and all(s == "failed" for s, _ in first.values())
    finally:
        PETSc.Options().delValue(BROKEN)
    caplog.set_level(logging.WARNING, "rawehelix")
    second, n = run_pool(tmp_path)
    assert n == 5 and second == REFERENCE
    assert f"-{BROKEN} 1" in caplog.text and "p00003.json: computed with other PETSc options" \
        in caplog.text
    assert set_aside(tmp_path) == [f"{t.id}.json" for t in TASKS]
    fake.clear()
    third, n = run_pool(tmp_path)
    assert n == 0 and fake == [] and third == REFERENCE


def damage_empty(path):
    path.write_text("{}")


def damage_truncate(path):
    path.write_bytes(path.read_bytes()[: len(path.read_bytes()) // 2])


def damage_value(path):  # a changed number: the checksum differs
    data = json.loads(path.read_text())
    data["values"]["q"] = 123.0
    path.write_text(json.dumps(data))


def damage_schema(path):  # re-sealed, so only the schema catches it
    data = json.loads(path.read_text())
    del data["values"]
    stamp = data.pop(checkpoints.SEAL)
    path.write_text(json.dumps(checkpoints.seal(data, stamp["fingerprint"],
                                                stamp["petsc_options"])))


@pytest.mark.parametrize("damage, reason", [
    (damage_empty, "holds {}, not a point's record"),
    (damage_truncate, "not JSON, so not whole"),
    (damage_value, "its checksum differs"),
    (damage_schema, "has no key 'values'"),
    ("foreign", "of another scene, discretisation or design")])
def test_a_bad_stored_point_is_named_set_aside_and_computed_again(tmp_path, fake, caplog, damage,
                                                                 reason):
    run_pool(tmp_path)
    victim = tmp_path / "points" / "p00002.json"
    if damage == "foreign":  # the same task id of another study's folder
        run_pool(tmp_path / "other", {"study": "another"})
        shutil.copy(tmp_path / "other" / "points" / "p00002.json", victim)
    else:
        damage(victim)
    fake.clear()
    caplog.set_level(logging.WARNING, "rawehelix")
    got, n = run_pool(tmp_path)
    assert got == REFERENCE and n == 1 and fake == ["p00002"]
    assert f"{victim}: {reason}" in caplog.text and "computed again" in caplog.text
    assert set_aside(tmp_path) == ["p00002.json"]
    assert pool.computed(tmp_path).count("p00002") == 2


# -- a full disk: a tmpfs if it can be mounted, else a monkeypatched write ---------------------
@pytest.fixture
def small_disk(tmp_path):
    """A 256 KiB tmpfs (we are root in the CI container); skipped where mount is refused."""
    mnt = tmp_path / "disk"
    mnt.mkdir()
    mount = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=256k", "tmpfs", str(mnt)],
                           capture_output=True, text=True)
    if mount.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs: {mount.stderr.strip()}")
    try:
        yield mnt
    finally:
        subprocess.run(["umount", "-l", str(mnt)], check=False)


def fill(folder: Path, leave_bytes: int) -> Path:
    """A ballast file that leaves about ``leave_bytes`` free in ``folder``'s file system."""
    st = os.statvfs(folder)
    ballast = folder / "ballast"
    ballast.write_bytes(b"\0" * max(st.f_bavail * st.f_frsize - leave_bytes, 0))
    return ballast


def test_a_full_disk_ends_with_an_output_fault_and_the_rerun_resumes(small_disk, fake):
    """A study's store on a tmpfs that fills up after a few points: an
    OutputFault naming the file (exit 1 on the command line), no temporary
    file; after space is freed the rerun computes only the points not stored
    and ends with the uninterrupted run's results."""
    out = small_disk / "study"
    ballast = fill(small_disk, 6 * 4096)  # tmpfs counts pages: room for a few files
    tasks = [pool.Task(f"p{k:05d}", {"id": f"p{k:05d}", "x": float(k)}) for k in range(40)]
    with pytest.raises(outdir_lock.OutputFault, match="No space left on device") as info:
        run_pool(out, tasks=tasks)
    assert str(out) in str(info.value)
    assert temps(small_disk) == []
    stored = [t.id for t in tasks if (out / "points" / f"{t.id}.json").exists()]
    assert 0 < len(stored) < len(tasks)
    ballast.unlink()
    fake.clear()
    got, n = run_pool(out, tasks=tasks)
    assert got == {t.id: ("ok", t.overrides["x"] ** 2) for t in tasks}
    assert sorted(fake) == sorted(set(t.id for t in tasks) - set(stored))  # no stored point again
    assert temps(small_disk) == [] and not (out / checkpoints.CORRUPT).exists()


# -- the sweep's store: a fake periodic response that continues from its state -----------------
@dataclass
class FakeResponse:
    f1: float
    T: float
    periodic: bool = True
    slack: bool = False
    periods: int = 3
    wall_s: float = 0.0
    start: str = "continuation"
    period_maxima_N: tuple = ()
    period_minima_N: tuple = ()
    series_t_s: tuple = (0.0, 1.0)
    series_tension_N: tuple = (1.0, 2.0)
    sections: object = None  # no fields along s: the point's limits block says so
    unsettled: dict | None = None  # periodic: no reason to give (solvers/periodic.py)

    @property
    def tension_max_N(self):
        return self.T

    tension_min_N = tension_mean_N = tension_max_N

    def entry(self):
        return {"f1_Hz": self.f1, "tension_max_N": self.T, "tension_min_N": self.T,
                "tension_mean_N": self.T, "periods": self.periods, "periodic": True,
                "slack": False, "wall_s": 0.0, "start": self.start}


class FakeBackend:
    def stationary(self):
        return np.zeros(2)

    def pack(self, state):
        return {"y": state}

    def unpack(self, data):
        return np.asarray(data["y"])


def fake_response(backend, q, f1, state, t, sweep_params, lead_in, progress=None):
    """T max depends on the state continued from: a point continued from a wrong
    or missing state gives another T max."""
    new = state + np.array([f1, 1.0])
    return FakeResponse(f1, float(new @ [1.0, 10.0])), new, t + 1.0


F1 = [2.0, 3.0, 4.0, 5.0]


@pytest.fixture
def sweep_fake(monkeypatch):
    from rawehelix.studies import scene, sweep
    monkeypatch.setattr(sweep, "periodic_response", fake_response)
    return sweep, scene.load("mobile_end", scheme="spline", elements=2)


def run_sweep(sweep_fake, folder, fingerprint="scene-a"):
    from rawehelix.studies.store.sweep_store import DirectoryStore
    sweep, params = sweep_fake
    store = DirectoryStore(folder, {"scene": "fake", "fingerprint": fingerprint})
    store.open(SELF)
    n = sweep.run_chunk(params, store, F1, backend=FakeBackend(), log=lambda m: None)
    return [(r["entry"]["f1_Hz"], r["entry"]["tension_max_N"]) for r in store.all_records(SELF)], n


def sweep_points(folder):
    return [(p["f1_Hz"], p["tension_max_N"]) for p in
            json.loads((folder / "sweep.json").read_text())["points"]]


def truncate_npz(path):
    damage_truncate(path.with_suffix(".npz"))


def json_of_other_scene(path, other):
    shutil.copy(other / "points" / path.name, path)
    shutil.copy(other / "points" / path.with_suffix(".npz").name, path.with_suffix(".npz"))


@pytest.mark.parametrize("damage, reason", [
    (damage_empty, "holds {}, not a point's record"),
    (damage_truncate, "not JSON, so not whole"),
    (truncate_npz, "its state f1_0003.00000.npz differs from the one written with it"),
    ("foreign", "of another scene, discretisation or design")])
def test_a_bad_sweep_point_is_named_set_aside_and_computed_again(tmp_path, sweep_fake, caplog,
                                                                damage, reason):
    """The issue's `{}` point silently left out, the truncated point's traceback
    (JSONDecodeError, BadZipFile) and the point of another scene: each is named,
    moved into corrupt/ and computed again from its predecessor's state, so the
    results equal the uninterrupted run's; sweep.json holds them all."""
    reference, n = run_sweep(sweep_fake, tmp_path / "whole")
    assert n == 4 and len(reference) == 4
    folder = tmp_path / "cut"
    shutil.copytree(tmp_path / "whole", folder)
    victim = folder / "points" / "f1_0003.00000.json"
    if damage == "foreign":
        run_sweep(sweep_fake, tmp_path / "other", "scene-b")
        json_of_other_scene(victim, tmp_path / "other")
    else:
        damage(victim)
    caplog.set_level(logging.WARNING, "rawehelix")
    got, n = run_sweep(sweep_fake, folder)
    assert n == 1 and got == reference and sweep_points(folder) == reference
    assert f"{victim}: {reason}" in caplog.text
    assert "f1_0003.00000.json" in set_aside(folder)


def test_points_of_two_scenes_never_mix_in_sweep_json(tmp_path, sweep_fake):
    """A directory of another sweep is refused (SweepError: exit 2); without
    sweep.json, another scene's points are set aside, never merged."""
    from rawehelix.studies.store.sweep_store import SweepError
    a, _ = run_sweep(sweep_fake, tmp_path)
    with pytest.raises(SweepError, match="holds a sweep of another scene"):
        run_sweep(sweep_fake, tmp_path, "scene-b")
    (tmp_path / "sweep.json").unlink()
    b, n = run_sweep(sweep_fake, tmp_path, "scene-b")
    assert n == 4 and sweep_points(tmp_path) == b
    assert len(set_aside(tmp_path)) == 8  # a's four records and four states


def test_load_npz_names_a_truncated_file_without_a_checksum(tmp_path):
    path = writers.write_npz(tmp_path / "s.npz", {"t": np.ones(100)})
    damage_truncate(path)
    with pytest.raises(checkpoints.Corrupt, match="s.npz is not a readable .npz"):
        checkpoints.load_npz(path, None)


# -- orbits: the window's store ----------------------------------------------------------------
def orbit(k):
    from rawehelix.periodic_orbits.floquet import Orbit
    return Orbit(f1_Hz=9.0 + 0.1 * k, X=np.arange(4.0) + k, delta=0.5, tension_max_N=100.0 + k,
                 tension_min_N=90.0, multipliers=np.array([0.9 + 0.01j, 0.5]),
                 newton_iterations=3, residual=1e-9, steps=64, wall_s=1.0)


def state(k):
    from rawehelix.periodic_orbits.continuation import State
    return State(tau=np.full(5, k), A=np.eye(2) * k, gf=np.ones(4), w=np.ones(5), ds=0.1 * (k + 1))


def window(folder):
    from rawehelix.studies.orbits import WindowStore
    return WindowStore.open(folder, {"branch": "fake"}, SELF)


def test_an_orbit_point_is_stored_whole_or_not_at_all(tmp_path, monkeypatch):
    """A full disk at the record (the point is not stored: computed again) or
    after it, at computed.log (stored: the rerun continues after it, where the
    store before issue 27 dropped it for want of its state.npz); no temporary
    file either way."""
    store = window(tmp_path)
    for k in range(2):
        store.save(orbit(k), [], state(k))

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")
    with monkeypatch.context() as m:
        m.setattr(writers.os, "replace", full)
        with pytest.raises(outdir_lock.OutputFault):
            store.save(orbit(2), [], state(2))
    assert temps(tmp_path) == []
    points, last, *_ = store.load()
    assert [o.f1_Hz for o in points] == [9.0, 9.1] and last.ds == pytest.approx(0.2)
    assert not (store.dir / "p0002.npz").exists()
    with monkeypatch.context() as m:
        m.setattr(writers, "append_line", full)
        with pytest.raises(OSError):
            store.save(orbit(2), [], state(2))
    points, last, *_ = store.load()
    assert [o.tension_max_N for o in points] == [100.0, 101.0, 102.0]
    assert last.ds == pytest.approx(0.3) and np.array_equal(points[2].X, orbit(2).X)


def test_a_bad_orbit_point_and_those_continued_from_it_are_set_aside(tmp_path, caplog):
    store = window(tmp_path)
    for k in range(4):
        store.save(orbit(k), [], state(k))
    damage_truncate(store.dir / "p0001.npz")
    caplog.set_level(logging.WARNING, "rawehelix")
    points, last, *_ = window(tmp_path).load()
    assert [o.f1_Hz for o in points] == [9.0] and last.ds == pytest.approx(0.1)
    assert "p0001.json: its state p0001.npz differs" in caplog.text
    assert "continued from p0001, set aside" in caplog.text
    assert set_aside(tmp_path) == sorted(f"p000{k}.{x}" for k in (1, 2, 3) for x in ("json", "npz"))


# -- end to end: two sweeps of different scenes started together on one folder ----------------
TINY = ["--elements", "2", "--degree", "2", "--f1", "6:8:2", "--set", "time.dt_s=2e-3",
        "--set", "sweep.lead_in_s=0.2", "--set", "sweep.min_periods=2",
        "--set", "sweep.max_periods=3", "--set", "sweep.record_periods=1",
        "--set", "sweep.periodic_tolerance=5e-2"]


def test_two_sweeps_started_together_on_one_folder(tmp_path):
    """The issue's race: `--set helix.EI_Nm2=4381` and `=6000` into one -o,
    started at once.  One exits 0, the other 2 naming the folder and the
    holder, having written nothing; the folder holds one scene's points, and
    the T max the winner printed is the one stored."""
    out = tmp_path / "out"
    runs = [subprocess.Popen([sys.executable, "-m", "rawehelix.cli.main", "sweep",
                              "mobile_end", "--scheme", "fe", *TINY, "--set",
                              f"helix.EI_Nm2={ei}", "-o", str(out)],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            for ei in (4381, 6000)]
    results = [(*p.communicate(timeout=600), p.returncode) for p in runs]
    results = [(code, out_, err) for out_, err, code in results]
    codes = sorted(r[0] for r in results)
    assert codes == [0, 2], results
    winner = next(r for r in results if r[0] == 0)
    loser = next(r for r in results if r[0] == 2)
    winner_pid = runs[[r[0] for r in results].index(0)].pid
    assert f"rawehelix: error: -o: {out}: is in use by another run (pid {winner_pid} on host" \
        in loser[2]
    assert len(loser[2].strip().splitlines()) == 1
    data = json.loads((out / "sweep.json").read_text())
    assert [p["f1_Hz"] for p in data["points"]] == [6.0, 8.0]
    fingerprints = {json.loads(p.read_text())[checkpoints.SEAL]["fingerprint"]
                    for p in (out / "points").glob("*.json")}
    assert len(fingerprints) == 1
    peak = json.loads((out / "summary.json").read_text())["peak_tension_N"]
    assert f"{peak:.1f} N" in winner[1]
    assert not (out / outdir_lock.LOCK).exists() and temps(out) == []
    # the loser run again on the finished folder is refused saying what changed, the
    # key with its two values (the tester's D5: it named the scene only)
    winner_ei = (4381, 6000)[[r[0] for r in results].index(0)]
    loser_ei = 10381 - winner_ei
    again = subprocess.run([sys.executable, "-m", "rawehelix.cli.main", "sweep", "mobile_end",
                            "--scheme", "fe", *TINY, "--set", f"helix.EI_Nm2={loser_ei}",
                            "-o", str(out)], capture_output=True, text=True, timeout=300)
    assert again.returncode == 2 and len(again.stderr.strip().splitlines()) == 1, again.stderr
    assert "changed: the scene's keys (--set" in again.stderr
    assert f"helix.EI_Nm2 {winner_ei}.0 -> {loser_ei}.0" in again.stderr


def test_the_command_line_ends_a_full_disk_with_one_line_and_status_1(tmp_path, monkeypatch,
                                                                       capsys):
    """An OSError of the disk inside a command (here raised by the command
    itself, as matplotlib's savefig would) is one line naming the file, exit 1,
    and the folder's lock is let go."""
    from rawehelix.cli import main as cli
    from rawehelix.cli.commands import COMMANDS

    def full(rh, params, args, outdir, comm):
        raise OSError(errno.ENOSPC, "No space left on device", str(outdir / "sweep.png"))
    monkeypatch.setattr(COMMANDS["stationary"], "run", full)
    out = tmp_path / "out"
    assert cli.main(["stationary", "mobile_end", "--elements", "2", "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert err == (f"rawehelix: error: {out}/sweep.png: not written: No space left on device "
                   f"(errno 28); free space or use another -o directory, then run the same "
                   f"command again (every point stored so far is kept)\n")
    assert not out.exists()  # the lock made it, nothing was written: removed again
