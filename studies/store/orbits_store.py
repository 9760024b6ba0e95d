"""The store of `rawehelix orbits` (studies/orbits.py): one directory per f1
window, every point stored as it is found (its entry, multipliers and state, and
the continuation's state after it), whole or not at all and checked when read
(:class:`WindowStore`); a rerun continues after the last stored point.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from rawehelix.studies.store import checkpoints, outdir_lock, writers
from rawehelix.studies.store.checkpoints import NUMBER

HEADER = "orbits.json"


class OrbitsStoreError(ValueError):
    """The output directory holds another branch."""


def _pairs(values) -> list:
    """Complex numbers as [re, im] pairs (JSON)."""
    return [[float(m.real), float(m.imag)] for m in values]


def _complex(pairs) -> np.ndarray:
    """The complex numbers of :func:`_pairs`."""
    return np.array([complex(re, im) for re, im in pairs])


#: what a stored orbit's record must hold (checkpoints.check_schema)
SCHEMA = {"entry": dict, "entry.f1_Hz": NUMBER, "entry.tension_max_N": NUMBER,
          "entry.tension_min_N": NUMBER, "entry.newton_iterations": int,
          "entry.residual": NUMBER, "entry.steps_per_period": (int, type(None)),
          "entry.wall_s": NUMBER,
          "delta": NUMBER, "events": list, "multipliers": list}
STATE_KEYS = ("X", "state_tau", "state_A", "state_gf", "state_w", "state_ds")


class WindowStore:
    """The points of one window in ``DIR/window<k>``: per point ``p<i>.npz`` (X
    and the continuation's state after the point, ``state_*``), then ``p<i>.json``
    (entry, multipliers, events), sealed with the fingerprint of the branch and
    the PETSc options and the .npz's checksum (studies/store/checkpoints.py): written
    last, the record is the point's completeness marker, so a point is stored
    whole or not at all; and ``computed.log`` (one line per point computed).
    :meth:`open` locks ``DIR`` first (studies/store/outdir_lock.py)."""

    def __init__(self, directory: Path, base: str = ""):
        self.dir = Path(directory)
        self.dir.mkdir(parents=True, exist_ok=True)
        self.options = checkpoints.petsc_options()
        self.fingerprint = checkpoints.fingerprint(base, self.options)

    @classmethod
    def open(cls, outdir: Path, header: dict, comm) -> "WindowStore":
        """Lock ``outdir``, refuse another branch's (:func:`open_directory`), and
        this rank's window's store (collective)."""
        lock = outdir_lock.hold(outdir, comm)
        open_directory(Path(outdir), header, comm)
        store = cls(Path(outdir) / f"window{comm.rank}", writers.digest(header))
        store._lock = lock
        return store

    def save(self, orbit, events, state):
        k = len(list(self.dir.glob("p*.json")))
        record = {"entry": orbit.entry(), "delta": orbit.delta, "events": events,
                  "multipliers": _pairs(orbit.multipliers)}
        if orbit.internal_multipliers is not None:  # the carried variables' (floquet.py)
            record["internal_multipliers"] = _pairs(orbit.internal_multipliers)
        npz = writers.write_npz(self.dir / f"p{k:04d}.npz",
                                {"X": orbit.X, **{f"state_{n}": a for n, a in state.arrays().items()}})
        files = {"npz": writers.file_sha256(npz)}
        writers.write_json(self.dir / f"p{k:04d}.json",
                           checkpoints.seal(record, self.fingerprint, self.options, files))
        writers.append_line(self.dir / "computed.log", f"{k} {orbit.f1_Hz!r} pid {os.getpid()}")

    def _point(self, k: int):
        """(record, arrays) of point k, checked; raises checkpoints.Corrupt."""
        record, stamp = checkpoints.read(self.dir / f"p{k:04d}.json", self.fingerprint,
                                         self.options, SCHEMA)
        arrays = checkpoints.load_npz(self.dir / f"p{k:04d}.npz", stamp["files"].get("npz"),
                                      STATE_KEYS)
        return record, arrays

    def load(self):
        """(orbits, state, folds, bifurcations, peaks) of the stored points, or None.
        The points are read in order up to the first that fails its checks: it and
        the points after it (continued from it) are set aside and computed again;
        a .npz without its record (written before an interruption) is removed."""
        from rawehelix.periodic_orbits.continuation import State
        from rawehelix.periodic_orbits.floquet import Orbit
        root = self.dir.parent
        legacy = self.dir / "state.npz"  # an older rawehelix's: its points have no seal either
        if legacy.exists():
            checkpoints.set_aside([legacy], root, "the continuation state of an older store",
                                  then="no longer read")
        orbits, events, arrays = [], {"fold": [], "peak": [], "bifurcation": []}, None
        k = 0
        while (self.dir / f"p{k:04d}.json").exists():
            try:
                record, arrays_k = self._point(k)
            except checkpoints.Corrupt as err:
                bad = [self.dir / f"p{k:04d}.json", self.dir / f"p{k:04d}.npz"]
                checkpoints.set_aside(bad, root, str(err))
                later = sorted(p for p in self.dir.glob("p*.*") if p.name > bad[1].name)
                if later:
                    checkpoints.set_aside(later, root, f"continued from p{k:04d}, set aside")
                break
            arrays = arrays_k
            e = record["entry"]
            mu = _complex(record["multipliers"])
            internal = record.get("internal_multipliers")
            if internal is not None:
                internal = _complex(internal)
            orbits.append(Orbit(f1_Hz=e["f1_Hz"], X=arrays["X"], delta=record["delta"],
                                tension_max_N=e["tension_max_N"], tension_min_N=e["tension_min_N"],
                                multipliers=mu, newton_iterations=e["newton_iterations"],
                                residual=e["residual"], steps=e["steps_per_period"],
                                wall_s=e["wall_s"], defects=e.get("defects", {}),
                                internal_multipliers=internal,
                                accuracy=e.get("accuracy", {})))
            for ev in record["events"]:
                kind = "peak" if ev["kind"] == "superharmonic" else ev["kind"]
                events.get(kind, events["bifurcation"]).append(ev)
            k += 1
        for stray in self.dir.glob("p*.npz"):  # beyond the last record: not whole
            if int(stray.stem[1:]) >= k:
                stray.unlink()
        if not orbits:
            return None
        state = State.from_arrays({n[len("state_"):]: a for n, a in arrays.items()
                                   if n.startswith("state_")})
        return orbits, state, events["fold"], events["bifurcation"], events["peak"]


def open_directory(outdir: Path, header: dict, comm):
    """Refuse a directory that holds another branch, then write its header (collective)."""
    old = writers.claim_directory(Path(outdir) / HEADER, header, comm)
    if old is not None:
        from rawehelix.studies.store.sweep_store import OPTION_OF
        what = writers.changed(old, header, OPTION_OF)
        raise OrbitsStoreError(f"{Path(outdir) / HEADER}: holds another branch (scene "
                               f"{old.get('scene')!r}, f1 windows {old.get('windows')}, "
                               f"tension_step {old.get('tension_step')}"
                               + (f"; changed: {', '.join(what)}" if what else "")
                               + "); use another -o directory or delete it")
