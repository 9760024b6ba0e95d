"""Damaged files of an output folder set aside, not deleted: into
``<outdir>/corrupt/<UTC time>/`` with a warning that names the file and the reason
(studies/store/checkpoints.py, docs/explanation/faults.md)."""

from __future__ import annotations

import logging
import os
import time
from pathlib import Path

from rawehelix.errors import OutputFault

CORRUPT = "corrupt"  # the folder of set-aside files, below the output folder
log = logging.getLogger("rawehelix.checkpoints")


def set_aside(paths, outdir: Path, reason: str, then: str = "computed again") -> list[Path]:
    """Move the files ``paths`` (those that exist) into ``outdir/corrupt/<UTC
    time>/`` (their paths below ``outdir`` kept) and warn, naming the first
    file, ``reason`` and what happens ``then``.  Another rank may have moved
    them first: not an error."""
    outdir = Path(outdir)
    stamp = time.strftime("%Y%m%dT%H%M%SZ", time.gmtime())
    moved = []
    for path in map(Path, paths):
        try:
            relative = path.resolve().relative_to(outdir.resolve())
        except ValueError:
            relative = Path(path.name)
        target = outdir / CORRUPT / stamp / relative
        n = 1
        while target.exists():  # set aside twice in one second: keep both
            target = outdir / CORRUPT / f"{stamp}-{n}" / relative
            n += 1
        try:
            target.parent.mkdir(parents=True, exist_ok=True)
            os.replace(path, target)
        except FileNotFoundError:
            continue
        except OSError as err:
            raise OutputFault.of(err, target) from err
        moved.append(target)
    if moved:
        log.warning(f"{paths[0]}: {reason}; moved to {moved[0].parent}/ and {then}")
    return moved
