"""The rawehelix command line: a thin layer over the Python API (:mod:`rawehelix.api`).

    rawehelix stationary SCENE [-o DIR] [--elements N] [--degree p] [--scheme fe|network] [PETSc options]
    rawehelix modes SCENE [--scheme fe|spline|network] [--elements N] [--degree p] [--count k] [-o DIR]
    rawehelix simulate SCENE [-o DIR] [--until T] [--no-gif] [--elements N] [--degree p] [--scheme fe|network] [PETSc options]
    rawehelix sweep SCENE [--f1 START:STOP:STEP] [--series] [-o DIR] [--scheme fe|spline|network] [--elements N]
    rawehelix response SCENE [--f1 START:STOP:STEP] [--elements N] [--degree p] [-o DIR]
    rawehelix section SCENE [--set KEY=VALUE] [-o DIR]
    rawehelix converge SCENE --quantity Q [-o DIR]
    rawehelix extremes [CASE ...] [-o DIR]
    rawehelix labtest axial|bending|torsion [--tension T1,T2,...] [--loads X1,...] [--fit]
                      [--EI VALUE] [--scene SCENE] [--no-gravity] [--elements N] [-o DIR]
    rawehelix study SCENE --vary KEY=START:STOP:COUNT [--vary ...] [--sample grid|lhs|sobol
                    --points N] --quantity Q[,Q...] [--fd-step h] [--point-timeout S] [-o DIR]
    rawehelix calibrate SCENE --fit KEY[,KEY...] --target Q=VALUE[,...] [--bounds KEY=LO:HI]
                    [--uncertainty REL] [--tolerance REL] [-o DIR]

SCENE is a TOML file or the name of a shipped scene (``stationary_table2``,
``nominal_operation``, ``mobile_end``).  ``--set KEY=VALUE`` sets any dotted
scene key.  Options that argparse does not know go to PETSc, with or without
a value (``-rawehelix_snes_monitor``, ``-rawehelix_snes_linesearch_type bt``);
put them after the scene.  An option no solver reads, or a value PETSc
refuses, is bad input (``--petsc-unused warn``: a warning only), as is an
unknown ``--option``.  ``-v`` shows more (``-vv`` everything).  Bad input
exits with status 2 and one message naming file, key and what is allowed;
nothing is written (the output folder, the memory and the disk a run needs
are checked before it starts: studies/store/outdir.py, studies/resources.py).  A
failed solve exits with status 1.  A study with failed points, a
calibration that missed a target by more than its tolerance, or a fit
(calibrate, labtest --fit) whose data could not determine its parameters,
writes its results and exits with status 3.  Ctrl-C exits with 130, saying what was kept
and how to resume.
"""

from __future__ import annotations

import argparse
import logging
import signal
import sys
import traceback
from pathlib import Path

from rawehelix import errors
from rawehelix.cli.commands import COMMANDS
from rawehelix.cli.commands.base import overrides, scene_arguments
from rawehelix.cli.text import plain, printable
from rawehelix.parameters import SCHEMES
from rawehelix.studies.scene import SceneError

#: exit statuses (README): bad input, a failed solve, Ctrl-C (128 + SIGINT)
BAD_INPUT, FAILED, INTERRUPTED = 2, 1, 130
log = logging.getLogger("rawehelix")


class _Parser(argparse.ArgumentParser):
    """argparse with its refusals on one line, as every other bad input, and
    its help in plain text (the descriptions reuse the modules' docstrings)."""

    def error(self, message):
        self.exit(BAD_INPUT, f"{self.prog}: error: {message}\n")

    def format_help(self):
        return plain(super().format_help())

    def format_usage(self):
        return plain(super().format_usage())


class _Version(argparse.Action):
    """``--version``: rawehelix's version and the DOLFINx and PETSc it runs on."""

    def __init__(self, option_strings, dest=argparse.SUPPRESS, default=argparse.SUPPRESS,
                 help="print rawehelix's version and those of DOLFINx and PETSc, and exit"):
        super().__init__(option_strings, dest=dest, default=default, nargs=0, help=help)

    def __call__(self, parser, namespace, values, option_string=None):
        print(version_text())
        parser.exit(0)


def version_text() -> str:
    import dolfinx
    import petsc4py
    petsc4py.init([])
    from petsc4py import PETSc

    import rawehelix
    petsc = ".".join(str(x) for x in PETSc.Sys.getVersion())
    return (f"rawehelix {rawehelix.__version__} (DOLFINx {dolfinx.__version__}, "
            f"PETSc {petsc}, petsc4py {petsc4py.__version__}, Python {sys.version.split()[0]})")


def _parser() -> argparse.ArgumentParser:
    """The parser of every command of the registry (:mod:`rawehelix.cli.commands`)."""
    parser = _Parser(prog="rawehelix", description=__doc__.split("\n\n")[0])
    parser.add_argument("--version", action=_Version)
    sub = parser.add_subparsers(dest="command", required=True)
    for command in COMMANDS.values():
        p = sub.add_parser(command.name, help=command.help)
        if command.scene:
            scene_arguments(p, SCHEMES)
        command.arguments(p)
    return parser


def _fail(message: str) -> int:
    print(printable(f"rawehelix: error: {message}"), file=sys.stderr)
    return BAD_INPUT


def _interrupted(command: str, outdir, comm) -> int:
    """Ctrl-C: one line saying what was kept (rank 0), no traceback."""
    if comm.rank == 0:
        kept = COMMANDS[command].kept
        if kept and outdir is not None:
            n = len(list(Path(outdir).glob(kept)))
            said = (f"{n} finished point{'s' * (n != 1)} kept in {outdir}/; run the same "
                    "command again to resume")
        elif command == "simulate" and outdir is not None and Path(outdir).is_dir():
            said = f"the series up to the last checkpoint is in {outdir}/ (no resume)"
        else:
            said = "nothing was written"
        print(f"rawehelix: interrupted: {said}", file=sys.stderr, flush=True)
    _abort_other_ranks(comm, INTERRUPTED)  # a rank that was not interrupted would wait
    return INTERRUPTED


def main(argv: list[str] | None = None) -> int:
    from rawehelix.cli import argv as argv_split
    from rawehelix.studies import logs
    from rawehelix.studies.store import outdir as outdir_check, outdir_lock

    argv = sys.argv[1:] if argv is None else argv
    parser = _parser()
    try:
        ours, petsc_args = argv_split.split(argv, parser)
    except SceneError as err:  # a mistyped option of ours
        return _fail(str(err))
    args = parser.parse_args(ours)
    logs.configure(args.verbose)
    # PETSc reads its options once, at initialisation: before any import of PETSc.
    import petsc4py
    petsc4py.init(["rawehelix", *petsc_args])  # argv[0] may be "-c": never an option
    signal.signal(signal.SIGINT, errors.on_sigint)  # Ctrl-C inside a PETSc solve: errors.py
    from mpi4py import MPI

    import rawehelix as rh
    from rawehelix.solvers import petsc_options

    comm = MPI.COMM_WORLD
    command = COMMANDS[args.command]
    outdir = None
    try:
        petsc_options.check(args.petsc_unused, argv_split.option_strings(parser, args.command))
        if not command.scene:
            status = command.run(rh, args, comm)
        else:
            params = rh.load_scene(args.scene, elements=args.elements, degree=args.degree,
                                   scheme=args.scheme,
                                   overrides=overrides(args, command.f1_grid))
            from rawehelix.parameters import schemes as scheme_cores
            refusal = scheme_cores.of(params).command_refusal(args.command)
            if refusal:  # before any work or folder
                raise SceneError("--scheme", params.discretisation.scheme, refusal)
            from rawehelix.solvers import tension_target
            params = tension_target.resolve(params, comm)  # ends.tension_N -> its elongation
            outdir = args.output or Path("results") / params.name / args.command
            outdir_check.check(outdir, command.needs)
            # one writer per output folder, one command's output in it: exit 2 otherwise
            with outdir_lock.hold(outdir, comm, args.command):
                status = command.run(rh, params, args, outdir, comm)
        _warn_unused_after_run(petsc_options, comm)
        return status
    except SceneError as err:
        return _fail(str(err))
    except outdir_lock.OutputFault as err:  # a full disk: one line, exit 1 (outdir_lock.py)
        print(printable(f"rawehelix: error: {err}"), file=sys.stderr)
        _abort_other_ranks(comm, 1)
        return 1
    except rh.SolverError as err:
        print(printable(f"rawehelix: {err}"), file=sys.stderr)
        _abort_other_ranks(comm, FAILED)
        return FAILED
    except KeyboardInterrupt:
        return _interrupted(args.command, outdir, comm)
    except Exception:
        if comm.size == 1:
            raise
        traceback.print_exc()
        _abort_other_ranks(comm, 1)
        raise


def _warn_unused_after_run(petsc_options, comm):
    """PETSc options only a solve reads (a viewer, MUMPS' ICNTL: not checked before
    the work) that none read, on rank 0."""
    left = petsc_options.left_after_run()
    if left and comm.rank == 0:
        log.warning("PETSc options %s: no solver read them", ", ".join("-" + n for n in left))


def _abort_other_ranks(comm, code: int):
    """Under mpirun an error on one rank would leave the others waiting in a
    collective call for ever (Open MPI waits busily: both cores stay at 100 %):
    end the whole job instead."""
    if comm.size > 1:
        sys.stderr.flush()
        comm.Abort(code)


if __name__ == "__main__":
    sys.exit(main())
