"""Where a sweep keeps its finished points: in memory, or in a checkpoint
directory that makes it resumable (see :mod:`rawehelix.studies.sweep`).

A store holds, per f1, the record (the summary entry, the per-period maxima and
the tension series) and the final state as plain arrays; it reads and writes
only its own files.  The directory is locked by the run (one writer,
studies/store/outdir_lock.py) and every record is sealed and checked when read,
its state against the checksum in the record (studies/store/checkpoints.py): a
point that fails is set aside into ``corrupt/``, with a warning, and computed
again.  ``sweep.json`` is rewritten from the good points alone."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
from mpi4py import MPI

from rawehelix.parameters import Parameters
from rawehelix.solvers.periodic import CRITERION
from rawehelix.studies.store import checkpoints, outdir_lock, writers
from rawehelix.studies.store.checkpoints import NUMBER, OPTIONAL_NUMBER

RESULTS = "sweep.json"


class SweepError(ValueError):
    """The output directory belongs to another sweep."""


def fingerprint(params: Parameters) -> str:
    """A hash of everything that changes the points: not f1 itself, the f1
    list, the end time nor the output sampling (the time step and the
    periodicity test do count).  The directory's identity: each point's own
    fingerprint folds in the run's PETSc options too (:class:`DirectoryStore`)."""
    return writers.digest(_fingerprinted(params))


def scene_keys(params: Parameters) -> dict:
    """The keys :func:`fingerprint` hashes, dotted, for a header to record
    (``writers.SCENE_KEYS``): a refusal then says which of them changed."""
    return writers.scene_keys(_fingerprinted(params))


def _fingerprinted(params: Parameters) -> dict:
    data = params.as_dict()
    data["ends"].pop("circle_frequency_Hz")
    data["time"] = {"dt_s": data["time"]["dt_s"]}
    for key in ("f1_start_Hz", "f1_stop_Hz", "f1_step_Hz"):
        data["sweep"].pop(key)
    data["sweep"]["criterion"] = CRITERION  # the periodicity test judges the points too
    return data


#: the command-line way to each key of a sweep's or a branch's header
OPTION_OF = {"scene": "SCENE", "fingerprint": "the scene's keys (--set, --elements, --degree, "
             "--scheme)", "scheme": "--scheme", "elements": "--elements", "degree": "--degree",
             "windows": "--f1 (or the ranks)", "tension_step": "--tension-step",
             "superharmonics": "--superharmonics", "f1_step_Hz": "--f1-step"}


def _key(f1: float) -> str:
    return f"f1_{f1:010.5f}"


class MemoryStore:
    """Finished points kept in memory (a sweep without a checkpoint directory)."""

    def __init__(self):
        self.records, self.states = {}, {}

    def finished(self, f1: float) -> dict | None:
        return self.records.get(_key(f1))

    def state(self, f1: float):
        return self.states.get(_key(f1))

    def save(self, f1: float, record: dict, state_arrays: dict | None, note: str = ""):
        self.records[_key(f1)] = record
        if state_arrays is not None:
            self.states[_key(f1)] = state_arrays

    def all_records(self, comm) -> list[dict]:
        gathered = comm.gather(list(self.records.values()), root=0)
        return None if gathered is None else [r for part in gathered for r in part]


#: what a stored point's record must hold (checkpoints.check_schema)
SCHEMA = {"entry": dict, "entry.f1_Hz": NUMBER, "entry.tension_max_N": OPTIONAL_NUMBER,
          "entry.tension_min_N": OPTIONAL_NUMBER, "entry.tension_mean_N": OPTIONAL_NUMBER,
          "entry.periods": int, "entry.periodic": bool}
STATE = "state"  # the seal's name of the point's final state (.npz)


class DirectoryStore:
    """Finished points in a checkpoint directory: resumable (see the module
    docstring), each point sealed and checked when read (studies/store/checkpoints.py),
    the directory locked from :meth:`open` on (studies/store/outdir_lock.py)."""

    def __init__(self, outdir: Path, header: dict):
        self.outdir, self.header = Path(outdir), header
        self.points = self.outdir / "points"
        self.options = checkpoints.petsc_options()
        self.fingerprint = checkpoints.fingerprint(header["fingerprint"], self.options)

    def open(self, comm):
        """Lock the directory, refuse one of another sweep, set aside the points
        that fail their checks, then create it (collective)."""
        self._lock = outdir_lock.hold(self.outdir, comm)
        error = None
        if comm.rank == 0:
            try:
                check_directory(self.outdir, self.header)
            except SweepError as err:
                error = str(err)
        error = comm.bcast(error, root=0)
        if error:
            raise SweepError(error)
        if comm.rank == 0:
            self.points.mkdir(parents=True, exist_ok=True)
            for path in sorted(self.points.glob("f1_*.json")):
                if self._read(path) is not None:
                    self._state(path)  # a good record with a bad state: both set aside
            self.merge()
        comm.Barrier()

    def _read(self, path: Path) -> dict | None:
        """The checked record of ``path``, or None (set aside, with a warning)."""
        try:
            record, _ = checkpoints.read(path, self.fingerprint, self.options, SCHEMA)
            if _key(record["entry"]["f1_Hz"]) != path.stem:
                raise checkpoints.Corrupt(f"holds f1 = {record['entry']['f1_Hz']} Hz, not "
                                          f"the f1 of its name")
        except checkpoints.Corrupt as err:
            checkpoints.set_aside([path, path.with_suffix(".npz")], self.outdir, str(err))
            return None
        return record

    def _state(self, path: Path):
        """The checked final state of the point whose record is ``path``, or None
        (a point without one, or set aside with its record)."""
        try:
            _, stamp = checkpoints.read(path, self.fingerprint, self.options, SCHEMA)
            if STATE not in stamp["files"]:
                return None  # a failed point
            return checkpoints.load_npz(path.with_suffix(".npz"), stamp["files"][STATE], ("t",))
        except checkpoints.Corrupt as err:
            checkpoints.set_aside([path, path.with_suffix(".npz")], self.outdir, str(err))
            return None

    def finished(self, f1: float) -> dict | None:
        path = self.points / f"{_key(f1)}.json"
        return self._read(path) if path.exists() else None

    def state(self, f1: float):
        path = self.points / f"{_key(f1)}.json"
        return self._state(path) if path.exists() else None

    def save(self, f1: float, record: dict, state_arrays: dict | None, note: str = ""):
        files = {}
        if state_arrays is not None:  # written first: the record is the point's marker
            npz = writers.write_npz(self.points / f"{_key(f1)}.npz", state_arrays)
            files[STATE] = writers.file_sha256(npz)
        writers.write_json(self.points / f"{_key(f1)}.json",
                           checkpoints.seal(record, self.fingerprint, self.options, files))
        self.merge()  # before the log's line: a point logged is in sweep.json, if killed
        writers.append_line(self.outdir / "computed.log",
                            f"{f1} rank {MPI.COMM_WORLD.rank} pid {os.getpid()}{note}")

    def records(self) -> list[dict]:
        """The checked records of the finished points, by f1 (a bad one set aside)."""
        records = [r for path in sorted(self.points.glob("f1_*.json"))
                   if (r := self._read(path)) is not None]
        return sorted(records, key=lambda r: r["entry"]["f1_Hz"])

    def merge(self, records: list[dict] | None = None) -> dict:
        """Rewrite sweep.json from the finished points (atomic; any rank may call it)."""
        records = self.records() if records is None else records
        data = {**self.header, "petsc_options": self.options,
                "points": [r["entry"] for r in records]}
        writers.write_json(self.outdir / RESULTS, data)
        return data

    def all_records(self, comm) -> list[dict] | None:
        comm.Barrier()
        if comm.rank != 0:
            return None
        records = self.records()
        self.merge(records)
        return records


def check_directory(outdir: Path, header: dict):
    """Refuse an output directory that holds another sweep."""
    path = outdir / RESULTS
    if not path.exists():
        return
    try:
        old = json.loads(path.read_text())
        if not isinstance(old, dict):
            raise ValueError(f"holds {type(old).__name__}, not an object")
    except (ValueError, UnicodeDecodeError) as err:  # written whole: damaged outside a run
        checkpoints.set_aside([path], outdir, f"not a sweep's results ({err})",
                              then="written again from the points")
        return
    if old.get("fingerprint") != header["fingerprint"]:
        what = writers.changed(old, header, OPTION_OF)
        raise SweepError(
            f"{path}: holds a sweep of another scene or discretisation or periodicity test (scene "
            f"{old.get('scene')!r}, scheme {old.get('scheme')!r}, N = {old.get('elements')}, "
            f"p = {old.get('degree')}" + (f"; changed: {', '.join(what)}" if what else "")
            + "); use another -o directory or delete it")
