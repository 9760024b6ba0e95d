"""Where a sweep keeps its finished points: in memory, or in a checkpoint
directory that makes it resumable (see :mod:`rawehelix.studies.sweep`).

A store holds, per f1, the record (the summary entry, the per-period maxima and
the tension series) and the final state as plain arrays; it reads and writes
only its own files."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
from mpi4py import MPI

from rawehelix.parameters import Parameters
from rawehelix.solvers.periodic import CRITERION
from rawehelix.studies import writers

RESULTS = "sweep.json"


class SweepError(ValueError):
    """The output directory belongs to another sweep."""


def fingerprint(params: Parameters) -> str:
    """A hash of everything that changes the points: not f1 itself, the f1
    list, the end time nor the output sampling (the time step and the
    periodicity test do count)."""
    data = params.as_dict()
    data["ends"].pop("circle_frequency_Hz")
    data["time"] = {"dt_s": data["time"]["dt_s"]}
    for key in ("f1_start_Hz", "f1_stop_Hz", "f1_step_Hz"):
        data["sweep"].pop(key)
    data["sweep"]["criterion"] = CRITERION  # the periodicity test judges the points too
    return writers.digest(data)


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


class DirectoryStore:
    """Finished points in a checkpoint directory: resumable (see the module docstring)."""

    def __init__(self, outdir: Path, header: dict):
        self.outdir, self.header = Path(outdir), header

    def open(self, comm):
        """Refuse a directory of another sweep, then create it (collective)."""
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
            (self.outdir / "points").mkdir(parents=True, exist_ok=True)
            merge_results(self.outdir, self.header)
        comm.Barrier()

    def finished(self, f1: float) -> dict | None:
        path = self.outdir / "points" / f"{_key(f1)}.json"
        return json.loads(path.read_text()) if path.exists() else None

    def state(self, f1: float):
        path = self.outdir / "points" / f"{_key(f1)}.npz"
        if not path.exists():
            return None
        with np.load(path) as data:
            return {k: data[k] for k in data.files}

    def save(self, f1: float, record: dict, state_arrays: dict | None, note: str = ""):
        points = self.outdir / "points"
        if state_arrays is not None:
            writers.write_npz(points / f"{_key(f1)}.npz", state_arrays)
        writers.write_json(points / f"{_key(f1)}.json", record)
        with open(self.outdir / "computed.log", "a") as f:
            f.write(f"{f1} rank {MPI.COMM_WORLD.rank} pid {os.getpid()}{note}\n")
        merge_results(self.outdir, self.header)

    def all_records(self, comm) -> list[dict] | None:
        comm.Barrier()
        if comm.rank != 0:
            return None
        records = read_records(self.outdir)
        merge_results(self.outdir, self.header, records)
        return records


def read_records(outdir: Path) -> list[dict]:
    """The finished points' records of a checkpoint directory, by f1 (a file
    without an entry, or not yet whole, is passed over)."""
    records = []
    for path in sorted((outdir / "points").glob("f1_*.json")):
        try:
            record = json.loads(path.read_text())
        except json.JSONDecodeError:
            continue
        if "entry" in record:
            records.append(record)
    return sorted(records, key=lambda r: r["entry"]["f1_Hz"])


def merge_results(outdir: Path, header: dict, records: list[dict] | None = None) -> dict:
    """Rewrite sweep.json from the finished points (atomic; any rank may call it)."""
    records = read_records(outdir) if records is None else records
    data = {**header, "points": [r["entry"] for r in records]}
    writers.write_json(outdir / RESULTS, data)
    return data


def check_directory(outdir: Path, header: dict):
    """Refuse an output directory that holds another sweep."""
    path = outdir / RESULTS
    if not path.exists():
        return
    try:
        old = json.loads(path.read_text())
    except json.JSONDecodeError:
        return  # cannot happen with atomic writes; treat as empty
    if old.get("fingerprint") != header["fingerprint"]:
        raise SweepError(
            f"{path}: holds a sweep of another scene or discretisation or periodicity test (scene "
            f"{old.get('scene')!r}, scheme {old.get('scheme')!r}, N = {old.get('elements')}, "
            f"p = {old.get('degree')}); use another -o directory or delete it")
