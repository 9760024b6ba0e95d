"""What a command of the registry is (:class:`Command`), and what the commands share:
the scene options, --set and --f1 as scene keys, printing on rank 0."""

from __future__ import annotations

import argparse
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from rawehelix.cli.text import printable
from rawehelix.studies.needs import Needs
from rawehelix.studies.scene import SceneError


@dataclass
class Command:
    """One ``rawehelix`` command: adding a command is one of these in
    :data:`rawehelix.cli.commands.COMMANDS`, naming its needs (studies/needs.py)."""

    name: str
    help: str  # the one line of ``rawehelix --help``
    arguments: Callable[[argparse.ArgumentParser], None]  # its own options
    #: scene: (rh, params, args, outdir, comm) -> exit status, in its locked output folder;
    #: without scene: (rh, args, comm) -> exit status, the command loads and locks itself
    run: Callable
    #: its memory step and output estimate (studies/needs.py's entry of its name, required:
    #: a command without one would be checked against nothing)
    needs: Needs
    scene: bool = True  # takes SCENE and the scene options (-o, --elements, --set, ...)
    kept: str | None = None  # its finished points in the output folder (resumable: Ctrl-C)
    f1_grid: bool = False  # --f1 START:STOP:STEP sets the scene's [sweep] list

    def __post_init__(self):
        if not isinstance(self.needs, Needs) or self.needs.name != self.name:
            raise ValueError(f"command {self.name!r}: its needs must be studies/needs.py's "
                             f"entry of its name, not {self.needs!r}")


def petsc_unused(p):
    p.add_argument("--petsc-unused", choices=("error", "warn"), default="error",
                   help="a PETSc option that no solver reads: refuse the run (default) "
                        "or only warn")


def scene_arguments(p, schemes):
    """The options of every command that runs one scene."""
    p.add_argument("scene", help="scene TOML file (or its stem), or the name of a shipped scene")
    p.add_argument("-o", "--output", type=Path, default=None,
                   help="output directory (default results/<scene>/<command>)")
    p.add_argument("--elements", type=int, default=None, help="number of elements N")
    p.add_argument("--degree", type=int, default=None, help="Lagrange degree p (FE)")
    p.add_argument("--scheme", choices=schemes, default=None,
                   help="discretisation scheme (default: the scene's)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="set a dotted scene key, e.g. --set helix.EI_Nm2=9000 (repeatable)")
    p.add_argument("-v", "--verbose", action="count", default=0,
                   help="more messages (-vv: the solvers' and compilers' too)")
    petsc_unused(p)


def method_argument(p, command: str, help: str):
    """``--method``: its choices and ``command``'s default from the orbit methods'
    registry (studies/orbit_method.py); ``help`` may name {methods} (the methods in
    words) and {default}."""
    from rawehelix.studies import orbit_method
    default = orbit_method.default_for(command)
    p.add_argument("--method", default=default, choices=orbit_method.METHODS,
                   help=help.format(methods=orbit_method.described(), default=default))


def overrides(args, f1_grid: bool = False) -> dict:
    """--set KEY=VALUE (values in TOML syntax: 9000, 1e-3, true, "graded") and,
    for a command with ``f1_grid``, --f1 START:STOP:STEP, as dotted scene keys:
    validated by the scene loader."""
    over = {}
    for item in args.set:
        key, sep, text = item.partition("=")
        if not sep or not key:
            raise SceneError("--set", item, "must be KEY=VALUE, e.g. helix.EI_Nm2=9000")
        try:
            value = tomllib.loads(f"v = {text}")["v"]
        except ValueError:  # TOMLDecodeError, or an integer past Python's 4300 digits
            value = text  # a bare word: a string
        over[key.strip()] = value
    if f1_grid and args.f1 is not None:
        try:
            start, stop, step = (float(v) for v in args.f1.split(":"))
        except ValueError:
            raise SceneError("--f1", args.f1, "is not START:STOP:STEP (numbers in Hz)") from None
        over.update({"sweep.f1_start_Hz": start, "sweep.f1_stop_Hz": stop,
                     "sweep.f1_step_Hz": step})
    return over


def say(comm, text: str):
    """The command's result, on rank 0's stdout."""
    if comm.rank == 0:
        print(printable(text), flush=True)


def check_branch_output(params, command, outdir, branches, lo, hi, method, key: str,
                        max_points=None):
    """The disk of the branches' stored points (orbits, envelope): their memory first
    (studies/resources.py), then the folder's room (studies/store/outdir.py); ``key``:
    the option that sets their count (--f1, --vary)."""
    from rawehelix.studies import needs, resources
    from rawehelix.studies.store import outdir as outdir_check
    resources.check(params, command)  # the discretisation's own check comes first
    points = resources.check_branches(params, branches, lo, hi, method,
                                      key=key,
                                      max_points=max_points or resources.MAX_BRANCH_POINTS)
    outdir_check.check(outdir, needs.get(command),
                       extra_bytes=points * resources.store_bytes_per_point(params, method))
