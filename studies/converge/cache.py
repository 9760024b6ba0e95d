"""Finished runs of a refinement study as files in ``DIR/runs/``.

A study stopped (or crashed) part-way is resumed by the same command, and a
run is never done twice.  A file counts only for the same scene,
discretisation and quantity (its fingerprint).  A failed run is recorded
too (its values nan, its reason kept): it is a result, and is not retried.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from rawehelix.parameters import Parameters
from rawehelix.studies.store import writers


class RunCache:
    """``folder`` None: nothing is kept (every ``get`` misses)."""

    def __init__(self, folder: Path | None, params: Parameters, quantity: str):
        self.folder = None if folder is None else Path(folder)
        self.fingerprint = writers.digest([params.as_dict(), quantity])

    def _path(self, label: str, value) -> Path:
        slug = "".join(c if c.isalnum() else "_" for c in label)
        return self.folder / f"{slug}_{value:g}.json"

    def get(self, label: str, value):
        """(values, wall time [s], why it failed or None) of a finished run, or None."""
        if self.folder is None or not self._path(label, value).exists():
            return None
        data = json.loads(self._path(label, value).read_text())
        if data.get("fingerprint") != self.fingerprint:
            return None
        return (np.asarray(data["result"], dtype=float),
                math.nan if data["wall_s"] is None else data["wall_s"], data["failed"])

    def put(self, label: str, value, result, wall: float, failed: str | None):
        if self.folder is not None:
            writers.write_json(self._path(label, value), {
                "fingerprint": self.fingerprint, "method": label, "value": value,
                "result": [None if not np.isfinite(v) else float(v) for v in result],
                "wall_s": None if not np.isfinite(wall) else wall, "failed": failed})
