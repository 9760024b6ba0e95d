"""The output folder, checked before anything is computed: it is not a file
(nor below one), the user may write there (a temporary file is created and
removed in its nearest existing folder, so that nothing is left), and its
filesystem has room for the run's estimated output.

Estimated output per command (rough, from the files of runs at the default
resolutions: pictures of 0.1-0.3 MB, summaries of a few kB, a simulate's
XDMF series and GIF of up to ~50 MB, a sweep's or study's records of a few
kB a point): ``OUTPUT_BYTES``, plus ``BYTES_PER_POINT`` for each point of a
count, plus what a command counts from its own keys (``extra_bytes``: the stored
branch points of ``orbits`` and ``envelope``, about 1.1 MB a point at N = 4,
studies/resources.py::store_bytes_per_point; a simulation's series and frames).
A refusal is a :class:`SceneError` on ``-o`` (exit status 2).
"""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

from rawehelix.errors import SceneError

MB = 1e6
OUTPUT_BYTES = {"stationary": 5 * MB, "modes": 20 * MB, "simulate": 200 * MB,
                "sweep": 20 * MB, "response": 10 * MB, "orbits": 50 * MB,
                "converge": 20 * MB, "extremes": 50 * MB, "labtest": 5 * MB,
                "study": 10 * MB, "calibrate": 5 * MB, "section": 0.1 * MB,
                "envelope": 10 * MB,  # + its branches' stored points (extra_bytes)
                "operate": 2 * MB,
                "campbell": 2 * MB}  # summary.json and campbell.png, + a point a wind
BYTES_PER_POINT = 20e3  # a stored point (study, calibrate, orbits: JSON and arrays)


def _existing(path: Path) -> Path:
    """The nearest existing ancestor of ``path`` (itself if it exists)."""
    p = path
    while not p.exists() and p != p.parent:
        p = p.parent
    return p


def estimate_bytes(command: str, points: int = 0, extra_bytes: float = 0.0) -> float:
    """The disk ``command`` writes [bytes]: :data:`OUTPUT_BYTES`, its points, ``extra_bytes``;
    an internal error for a command registered without its estimate
    (tests/test_resource_keys.py)."""
    try:
        base = OUTPUT_BYTES[command]
    except KeyError:
        raise KeyError(f"internal: command {command!r} has no output estimate in "
                       f"studies/store/outdir.py OUTPUT_BYTES (registered: {sorted(OUTPUT_BYTES)})"
                       ) from None
    return base + BYTES_PER_POINT * points + extra_bytes


def check(outdir, command: str, points: int = 0, option: str = "-o", extra_bytes: float = 0.0):
    """Refuse ``outdir`` for ``command`` (SceneError on ``option``); writes nothing."""
    path = Path(outdir).absolute()
    base = _existing(path)
    if not base.is_dir():
        raise SceneError(option, str(outdir),
                         f"{base} is a file, not a folder: name a folder (new or existing)")
    try:
        fd, name = tempfile.mkstemp(prefix=".rawehelix-check-", dir=base)
    except OSError as err:
        raise SceneError(option, str(outdir),
                         f"cannot write in {base} ({err.strerror}): name a writable folder"
                         ) from None
    os.close(fd)
    os.unlink(name)
    need, free = estimate_bytes(command, points, extra_bytes), shutil.disk_usage(base).free
    if free < need:
        raise SceneError(option, str(outdir),
                         f"its filesystem has {free / MB:.3g} MB free, less than the about "
                         f"{need / MB:.3g} MB that '{command}' writes (estimates in "
                         f"studies/store/outdir.py): free some space or name another folder")
