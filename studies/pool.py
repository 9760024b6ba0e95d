"""Scenes evaluated on MPI ranks with dynamic load balancing, kept in a directory.

:func:`run` is collective on ``comm``: every rank takes the next unfinished
task from a shared counter, evaluates it on MPI.COMM_SELF (one scene per
rank, :func:`rawehelix.studies.quantities.evaluate`) and stores its record,
until none is left.  The counter is one integer on rank 0, taken with an
atomic MPI one-sided ``Fetch_and_op``: a queue without a manager rank, so
that every rank computes (with 2 ranks a manager-worker loop would leave one
worker), and a slow point holds up no other.  With one rank it is a loop.

Resumable: a task's record is written atomically to ``DIR/points/<id>.json``
as soon as it is finished; a run started again (after SIGKILL too) skips
every task whose record exists and passes its checks (studies/store/checkpoints.py:
checksum, schema, the fingerprint of the study and of the PETSc options; a
record that fails is set aside into ``DIR/corrupt/`` and computed again),
and ``DIR/computed.log`` gets one line per task computed.  The directory is
locked by the run (studies/store/outdir_lock.py).  A failed task (the stage raised one of
``quantities.POINT_ERRORS``) is recorded with its reason and counts as
finished; so does one that ran past ``point_timeout`` (:func:`time_limit`),
unless a later run allows it more time.  Any other exception on a rank is a
failure of the machinery: the traceback is printed and the whole job aborted
(``comm.Abort``), since the other ranks would otherwise wait for ever at the
end.
"""

from __future__ import annotations

import os
import signal
import sys
import time
import traceback
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from mpi4py import MPI

from rawehelix.errors import SceneError
from rawehelix.studies.store import checkpoints, outdir_lock, writers

HEADER = "study.json"


@dataclass(frozen=True)
class Task:
    id: str  # the record's file name
    overrides: dict  # dotted scene keys of this point
    kind: str = "design"


#: what a stored task's record must hold (checkpoints.check_schema)
SCHEMA = {"id": str, "kind": str, "overrides": dict, "values": dict, "errors": dict,
          "status": str, "cpu_s": dict, "wall_s": dict}


class Store:
    """The finished tasks of one study in ``outdir`` (see the module docstring):
    the directory locked from :meth:`open` on (studies/store/outdir_lock.py), each
    record sealed with the header's and the PETSc options' fingerprint and
    checked when read (studies/store/checkpoints.py)."""

    def __init__(self, outdir, header: dict):
        self.outdir, self.header = Path(outdir), header
        self.points = self.outdir / "points"
        self.options = checkpoints.petsc_options()
        self.fingerprint = checkpoints.fingerprint(writers.digest(header), self.options)

    def open(self, comm):
        """Lock the directory, refuse one that holds another study, then create it
        (collective)."""
        self._lock = outdir_lock.hold(self.outdir, comm)
        path = self.outdir / HEADER
        if writers.claim_directory(path, self.header, comm) is not None:
            raise SceneError("-o", str(self.outdir),
                             f"holds another study ({path} differs: scene, discretisation, keys, "
                             f"sample or quantities); use another -o directory or delete it")
        if comm.rank == 0:  # (a point's record makes its directory too: write_json)
            self.points.mkdir(parents=True, exist_ok=True)
        return self

    def finished(self, task_id: str) -> dict | None:
        """The checked record of the task, or None: not stored, or set aside
        (corrupt, another run's, other PETSc options: computed again)."""
        path = self.points / f"{task_id}.json"
        if not path.exists():
            return None
        try:
            record, _ = checkpoints.read(path, self.fingerprint, self.options, SCHEMA)
            if record["id"] != task_id or record["status"] not in ("ok", "failed"):
                raise checkpoints.Corrupt(f"holds task {record['id']!r} with status "
                                          f"{record['status']!r}, not task {task_id!r}")
        except checkpoints.Corrupt as err:
            checkpoints.set_aside([path], self.outdir, str(err))
            return None
        return record

    def save(self, record: dict):
        writers.write_json(self.points / f"{record['id']}.json",
                           checkpoints.seal(record, self.fingerprint, self.options))
        writers.append_line(self.outdir / "computed.log",
                            f"{record['id']} rank {MPI.COMM_WORLD.rank} pid {os.getpid()}")


def computed(outdir) -> list[str]:
    """The ids of ``DIR/computed.log``: one per task computed, by any run."""
    path = Path(outdir) / "computed.log"
    return [line.split()[0] for line in path.read_text().splitlines()] if path.exists() else []


class _Counter:
    """The next task's index: an integer on rank 0 taken atomically by any rank."""

    def __init__(self, comm):
        self.comm = comm
        self.win = MPI.Win.Allocate(8 if comm.rank == 0 else 0, 8, comm=comm)
        if comm.rank == 0:
            self.win.Lock(0)
            self.win.Put(np.zeros(1, dtype="i8"), 0)
            self.win.Unlock(0)
        comm.Barrier()

    def next(self) -> int:
        got = np.zeros(1, dtype="i8")
        self.win.Lock(0)
        self.win.Fetch_and_op(np.ones(1, dtype="i8"), got, 0, 0, MPI.SUM)
        self.win.Unlock(0)
        return int(got[0])

    def free(self):
        idle_barrier(self.comm)
        self.win.Free()


def idle_barrier(comm, poll_s: float = 0.01):
    """A barrier that sleeps while it waits: Open MPI's blocking one spins, and
    on a machine with as many cores as ranks it would take the core of the rank
    still computing its last point."""
    request = comm.Ibarrier()
    while not request.Test():
        time.sleep(poll_s)


def time_limit(seconds: float | None, call):
    """``call(timed_out)`` with an alarm after ``seconds`` (None: no limit): SIGALRM
    raises quantities.PointTimeout once, in the main thread, at the next Python
    instruction (a PETSc or SLEPc call in C ends first); ``timed_out()`` gives
    the reason from then on.  Returns ``(call's result or None if the exception
    escaped it, reason or None)``."""
    from rawehelix.studies import quantities
    if not seconds:
        return call(lambda: None), None
    reason = []

    def alarm(signum, frame):
        if not reason:  # raises once: the handlers below cannot be hit again
            reason.append(f"timed out after {seconds:g} s (--point-timeout)")
            raise quantities.PointTimeout(reason[0])

    def timed_out():
        return reason[0] if reason else None

    old = signal.signal(signal.SIGALRM, alarm)
    try:
        signal.setitimer(signal.ITIMER_REAL, seconds)
        try:
            return call(timed_out), timed_out()
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0)
    except quantities.PointTimeout:  # outside a stage (loading the scene, between stages)
        return None, timed_out()
    finally:
        signal.signal(signal.SIGALRM, old)


def _evaluate(task: Task, load, wanted: list[str], point_timeout: float | None = None) -> dict:
    from rawehelix.studies import quantities
    c0, w0 = time.process_time(), time.perf_counter()
    record = {"id": task.id, "kind": task.kind, "overrides": task.overrides}

    def failed(reason):
        return {"values": dict.fromkeys(wanted), "errors": dict.fromkeys(wanted, reason),
                "cpu_s": {}, "wall_s": {}}

    def point(timed_out):
        try:
            params = load(task.overrides)
        except quantities.POINT_ERRORS as err:  # validated before the run: not expected
            return failed(timed_out() or str(err))
        return quantities.evaluate(params, wanted, timed_out)

    out, late = time_limit(point_timeout, point)
    out = out or failed(late)
    if late:
        record["timed_out_s"] = point_timeout
    record.update(out)
    record["status"] = "failed" if out["errors"] else "ok"
    record["point_cpu_s"] = time.process_time() - c0
    record["point_wall_s"] = time.perf_counter() - w0
    record["rank"] = MPI.COMM_WORLD.rank
    return record


def _retry(record: dict, point_timeout: float | None) -> bool:
    """A record that timed out under a shorter limit than this run's."""
    limit = record.get("timed_out_s")
    return limit is not None and (point_timeout is None or point_timeout > limit)


def run(tasks: list[Task], load, wanted: list[str], store: Store, comm=MPI.COMM_WORLD,
        log=None, point_timeout: float | None = None) -> dict:
    """Evaluate the unfinished ``tasks`` on the ranks of ``comm`` (collective);
    ``load(overrides) -> Parameters`` builds a task's scene.  A point still
    running after ``point_timeout`` seconds (wall) fails with that reason
    (:func:`time_limit`); a record that timed out after fewer seconds than
    ``point_timeout`` (or None) is not finished, and is computed again.  Returns
    ``{"records": {id: record} (every task in order, on every rank), "computed": n,
    "loop_wall_s", "loop_cpu_s", "loop_start_unix", "loop_end_unix", "loop_points"
    (this rank)}``."""
    done = None
    if comm.rank == 0:
        done = {t.id: r for t in tasks if (r := store.finished(t.id)) is not None
                and not _retry(r, point_timeout)}
    done = comm.bcast(done, root=0)
    todo = [k for k, t in enumerate(tasks) if t.id not in done]
    mine = []
    c0, w0, t0 = time.process_time(), time.perf_counter(), time.time()
    try:
        counter = _Counter(comm) if comm.size > 1 else None
        k = 0
        while True:
            k = counter.next() if counter else k
            if k >= len(todo):
                break
            task = tasks[todo[k]]
            record = _evaluate(task, load, wanted, point_timeout)
            store.save(record)
            mine.append(record)
            if log:
                shown = ", ".join(f"{q} = {v:.6g}" for q, v in record["values"].items()
                                  if v is not None)
                log(f"[rank {comm.rank}] {task.id} ({k + 1}/{len(todo)}): "
                    f"{shown or record['status']} ({record['point_wall_s']:.1f} s)")
            k += 0 if counter else 1
        loop = {"loop_wall_s": time.perf_counter() - w0, "loop_cpu_s": time.process_time() - c0,
                "loop_start_unix": t0, "loop_end_unix": time.time(), "loop_points": len(mine)}
        if counter:
            counter.free()
    except Exception as err:  # the machinery failed on this rank: stop every rank
        if comm.size == 1:
            raise
        if isinstance(err, outdir_lock.OutputFault):  # a full disk: one line, not a traceback
            print(f"rawehelix: error: {err}", file=sys.stderr)
        else:
            traceback.print_exc()
        sys.stderr.flush()
        comm.Abort(1)
    idle_barrier(comm)
    new = [r for part in comm.allgather(mine) for r in part]
    records = {**done, **{r["id"]: r for r in new}}
    return {"records": {t.id: records[t.id] for t in tasks}, "computed": len(new), **loop}
