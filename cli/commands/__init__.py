"""The registry of ``rawehelix`` commands, in the order ``rawehelix --help``
lists them: name -> :class:`~rawehelix.cli.commands.base.Command` (its help
line, its options, its runner).  Adding a command is one entry in one of the
family modules:

- :mod:`.runs`: one scene, one run (stationary, modes, simulate, sweep, response, orbits,
  section);
- :mod:`.designs`: one scene, many runs (converge, study, calibrate);
- :mod:`.benches`: commands that build their own scenes (extremes, labtest).
"""

from rawehelix.cli.commands import benches, designs, runs
from rawehelix.cli.commands.base import Command

COMMANDS: dict[str, Command] = {c.name: c for c in runs.COMMANDS + designs.COMMANDS
                                + benches.COMMANDS}

__all__ = ["COMMANDS", "Command"]
