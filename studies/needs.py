"""What each command needs, declared once by its name: the step that sets its memory
(studies/resources.py counts the bytes of that step) and the disk it writes before its
points (studies/store/outdir.py adds the points).  The command line's
:class:`~rawehelix.cli.commands.base.Command` names its entry (``needs``, required);
the API's checks read it by the command's name.  A command without its entry is an
internal error naming this file, never a default (tests/test_resource_keys.py)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from rawehelix.parameters.schemes import FECore
from rawehelix.registry import Registry

MB = 1e6  # [bytes]
#: the steps that set a run's memory (their bytes per unknown: parameters/schemes.py)
STEPS = tuple(FECore.BYTES_PER_UNKNOWN)


@dataclass(frozen=True)
class Needs:
    """One command's estimates (rough, from the files and peak RSS of runs at the
    default resolutions: studies/resources.py's and studies/store/outdir.py's docstrings)."""

    name: str  # the command
    memory_step: str  # the step that sets its memory, one of STEPS
    output_bytes: float  # what it writes [bytes], before its points and stored branches

    def __post_init__(self):
        if self.memory_step not in STEPS:
            raise ValueError(f"{self.name}: memory step {self.memory_step!r} is none of {STEPS}")
        if not (self.output_bytes > 0 and math.isfinite(self.output_bytes)):
            raise ValueError(f"{self.name}: output estimate {self.output_bytes!r} [bytes] "
                             f"must be positive")


def _unregistered(key: str, name, why: str) -> Exception:
    return KeyError(f"internal: {key} {name!r} has no estimates in studies/needs.py NEEDS "
                    f"({why})")


#: every command's needs, in ``rawehelix --help``'s order
NEEDS: Registry[Needs] = Registry("command", (
    Needs("stationary", "stationary", 5 * MB),
    Needs("modes", "modes", 20 * MB),
    # below the stationary state it starts from in memory (resources.py); its XDMF
    # series and GIF up to ~50 MB, + its counted outputs and frames
    Needs("simulate", "dynamics", 200 * MB),
    Needs("sweep", "dynamics", 20 * MB),
    Needs("response", "modes", 10 * MB),
    Needs("orbits", "modes", 50 * MB),  # + its branch's stored points
    # one stationary solver at a time, a point after another; summary.json and its figure
    Needs("operate", "stationary", 2 * MB),
    # an eigenproblem at each operating point; summary.json and campbell.png
    Needs("campbell", "modes", 2 * MB),
    Needs("section", "stationary", 0.1 * MB),  # closed forms, no FE (the smallest estimate)
    Needs("converge", "modes", 20 * MB),
    # a design's points: the stage its quantities need (resources.check_quantities);
    # the worst (modes) for the command as a whole
    Needs("study", "modes", 10 * MB),
    Needs("envelope", "modes", 10 * MB),  # its branches are orbits' (+ their stored points)
    Needs("calibrate", "modes", 5 * MB),
    Needs("extremes", "modes", 50 * MB),  # its cases' eigenproblems
    Needs("labtest", "stationary", 5 * MB),
), error=_unregistered)

#: the needs of a command by its name; an internal error (KeyError) for any other name
get = NEEDS.get
