"""Logging of the `rawehelix` command: one handler on stderr, ``rawehelix: message``.

rawehelix code logs on ``logging.getLogger(__name__)`` (``rawehelix.*``).
The verbosity counts ``-v``: 0 shows rawehelix's own progress (INFO, e.g. a
sweep's points) and everybody's warnings and errors, 1 adds rawehelix's
DEBUG, 2 adds everything else: the solvers' and the form compilers' chatter.

The chatter, on a cold form cache (DOLFINx 0.5): FFCx calls
``cffi.FFI.compile(verbose=True)``, which sets the threshold of distutils'
log to INFO for the build.  Under setuptools' distutils (the default with
setuptools >= 60) that log is the *root* logger, so "running build_ext",
"building 'libffcx_forms_...' extension" and the gcc command lines arrive as
INFO records of the logger "root", and ffcx's ``logging.basicConfig()`` (at
import) prints them on stderr as ``INFO:root:...``.  Setting the root level
does not help, as cffi resets it around every build; a filter on our handler
does.  (The stdlib distutils prints them on stdout, which FFCx captures; gcc
itself inherits stderr but prints nothing for the generated code.)  UFL
attaches its own handler on stdout to the logger "UFL": it is removed, so
UFL's warnings come through ours, once.
"""

from __future__ import annotations

import logging
import sys

# the loggers of the form compilers and of the build of their C code
# ("root": setuptools' distutils logs on the root logger)
JIT_LOGGERS = ("root", "ffcx", "UFL", "ufl", "cffi", "distutils", "setuptools")
LEVELS = (logging.INFO, logging.DEBUG, logging.DEBUG)  # of rawehelix's own loggers
FORMAT = "rawehelix: %(message)s"


def _ours(record: logging.LogRecord) -> bool:
    return record.name.split(".")[0] == "rawehelix"


def _not_jit_chatter(record: logging.LogRecord) -> bool:
    return record.levelno >= logging.WARNING or _ours(record)


def configure(verbosity: int = 0) -> logging.Handler:
    """Log to stderr as ``rawehelix: message``: rawehelix's INFO and above
    (``verbosity`` 0) or DEBUG (1 or more), other loggers' WARNING and above;
    their INFO and DEBUG (the form compilers') only at 2.  Replaces any handler already on the root logger (ffcx's
    ``basicConfig``), so calling it again reconfigures.  Returns the handler."""
    level = LEVELS[min(max(verbosity, 0), len(LEVELS) - 1)]
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter(FORMAT))
    handler.setLevel(level)
    if verbosity < 2:
        handler.addFilter(_not_jit_chatter)
    root = logging.getLogger()
    for old in list(root.handlers):
        root.removeHandler(old)
    root.addHandler(handler)
    root.setLevel(level)
    import ufl  # noqa: F401  (attaches its stdout handler on import)
    ufl_log = logging.getLogger("UFL")
    for old in list(ufl_log.handlers):
        ufl_log.removeHandler(old)
    return handler
