"""Stored points that are checked when they are read (issue 27).

A store (sweep_store, pool, orbits' WindowStore) writes each point's record
with :func:`seal`: the record gets a ``"_seal"`` with

- ``fingerprint``: of everything that changes the point's result, the
  store's own (scene, discretisation, design, ...) folded with the PETSc
  options of the run (:func:`petsc_options`), so that a rerun with other
  options computes its points again (a point that failed under a broken
  option is retried with the corrected one);
- ``files``: the SHA-256 of the point's other files (its .npz state), which
  are written before the record;
- ``sha256``: of the canonical JSON of the record with the rest of its seal.

The record is written last, atomically: it is the point's completeness
marker.  :func:`read` checks the JSON, the checksum, the fingerprint and the
store's schema (required keys and their types); :func:`load_npz` checks a
state file against its checksum.  A point that fails is :class:`Corrupt`:
the store moves its files aside into ``OUTDIR/corrupt/<UTC time>/`` with
:func:`set_aside` (a warning on the log names the file and the reason) and
computes the point again.  Nothing is dropped silently, nothing raises a
traceback.
"""

from __future__ import annotations

import hashlib
import json
import zipfile
from pathlib import Path

import numpy as np

from rawehelix.studies.store import writers
from rawehelix.studies.store.quarantine import CORRUPT, set_aside  # noqa: F401  (re-exported)

SEAL = "_seal"
NUMBER = (int, float)
OPTIONAL_NUMBER = (int, float, type(None))
#: PETSc options that change no result: monitors, viewers, logging, help
HARMLESS = ("monitor", "view", "log_", "options_left", "help", "version", "malloc_debug")


class Corrupt(ValueError):
    """A stored point that is not whole, not this run's or not what its store writes."""


def petsc_options() -> list[str]:
    """The PETSc options given to the run (command line, PETSC_OPTIONS, files)
    that can change a result, sorted: ``["-name value", ...]``.  Read between
    solves, when the database holds the user's options alone (solvers put their
    defaults in and take them out again: solvers/snes.temporary_options)."""
    from petsc4py import PETSc
    return sorted(f"-{k} {'' if v is None else v}".strip()
                  for k, v in PETSc.Options().getAll().items()
                  if not any(word in k for word in HARMLESS))


def fingerprint(base: str, options: list[str] | None = None) -> str:
    """A point's fingerprint: the store's ``base`` with the PETSc options."""
    options = petsc_options() if options is None else options
    return writers.digest({"store": base, "petsc_options": options})


def _canonical(data) -> str:
    return json.dumps(writers._jsonable(data), sort_keys=True, separators=(",", ":"))


def seal(record: dict, fingerprint: str, options: list[str], files: dict | None = None) -> dict:
    """``record`` with its seal (module docstring); ``files``: name -> SHA-256."""
    out = dict(writers._jsonable(record))
    out[SEAL] = {"fingerprint": fingerprint, "petsc_options": options, "files": files or {}}
    out[SEAL]["sha256"] = hashlib.sha256(_canonical(out).encode()).hexdigest()
    return out


def read(path: Path, fingerprint: str, options: list[str], schema: dict) -> tuple[dict, dict]:
    """The record of ``path`` without its seal, and the seal; raises :class:`Corrupt`
    saying why.  ``schema``: dotted key -> allowed types."""
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
    except (ValueError, UnicodeDecodeError) as err:
        raise Corrupt(f"not JSON, so not whole ({err})") from None
    if not isinstance(data, dict) or not data:
        raise Corrupt(f"holds {json.dumps(data)[:40]}, not a point's record")
    stamp = data.get(SEAL)
    if not isinstance(stamp, dict) or not isinstance(stamp.get("sha256"), str):
        raise Corrupt("has no checksum (not written whole, or by an older rawehelix)")
    body = {**data, SEAL: {k: v for k, v in stamp.items() if k != "sha256"}}
    if hashlib.sha256(_canonical(body).encode()).hexdigest() != stamp["sha256"]:
        raise Corrupt("its checksum differs: changed after it was written")
    if stamp.get("fingerprint") != fingerprint:
        theirs = stamp.get("petsc_options")
        if theirs != options:
            raise Corrupt(f"computed with other PETSc options ({' '.join(theirs or []) or 'none'})"
                          f" than this run's ({' '.join(options) or 'none'})")
        raise Corrupt("of another scene, discretisation or design (fingerprint "
                      f"{stamp.get('fingerprint')}, this run's {fingerprint})")
    record = {k: v for k, v in data.items() if k != SEAL}
    check_schema(record, schema)
    return record, stamp


def check_schema(record: dict, schema: dict):
    """Each dotted key of ``schema`` is in ``record`` with one of its types."""
    for dotted, types in schema.items():
        value = record
        for part in dotted.split("."):
            if not isinstance(value, dict) or part not in value:
                raise Corrupt(f"has no key {dotted!r}")
            value = value[part]
        types = types if isinstance(types, tuple) else (types,)
        if not isinstance(value, types) or (bool not in types and isinstance(value, bool)):
            allowed = " or ".join("null" if t is type(None) else t.__name__ for t in types)
            raise Corrupt(f"{dotted!r} is {json.dumps(value)[:40]}, must be {allowed}")


def load_npz(path: Path, sha256: str | None, keys=()) -> dict:
    """The arrays of an .npz, checked against its checksum and for ``keys``;
    raises :class:`Corrupt`."""
    path = Path(path)
    if not path.exists():
        raise Corrupt(f"its state {path.name} is missing")
    if sha256 is not None and writers.file_sha256(path) != sha256:
        raise Corrupt(f"its state {path.name} differs from the one written with it")
    try:
        with np.load(path) as data:
            arrays = {k: data[k] for k in data.files}
    except (zipfile.BadZipFile, ValueError, OSError, EOFError) as err:
        raise Corrupt(f"its state {path.name} is not a readable .npz ({type(err).__name__}: "
                      f"{err})") from None
    missing = [k for k in keys if k not in arrays]
    if missing:
        raise Corrupt(f"its state {path.name} has no {', '.join(missing)}")
    return arrays
