"""The `rawehelix` command line.

    rawehelix stationary SCENE [-o DIR] [--elements N] [--degree p] [PETSc options]
    rawehelix modes SCENE [--scheme fe|spline] [--elements N] [--degree p] [--count k] [-o DIR]
    rawehelix simulate SCENE [-o DIR] [--until T] [--elements N] [--degree p] [PETSc options]
    rawehelix sweep SCENE [--f1 START:STOP:STEP] [--series] [-o DIR] [--scheme ...] [--elements N]
    rawehelix converge SCENE --quantity Q [-o DIR]

SCENE is a TOML file or the name of a shipped scene (``stationary_table2``,
``nominal_operation``, ``mobile_end``).  Options that argparse does not know
and that start with ``-`` go to PETSc (e.g. ``-rawehelix_snes_monitor``).
Bad input exits with status 2 and one message naming file, key and what is
allowed; nothing is written.
"""

from __future__ import annotations

import argparse
import logging
import sys
import traceback
from pathlib import Path

from rawehelix.studies import scene as scenes

COMMANDS = ("stationary", "modes", "simulate", "sweep", "converge", "extremes")


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="rawehelix", description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    for name, help_text in (("stationary", "stationary state with fixed ends (Sec. 5.1)"),
                            ("modes", "natural modes about the stationary state (Table 3)"),
                            ("simulate", "dynamics from the stationary state (Secs. 5.2, 5.3)"),
                            ("sweep", "sweep of the upper end's forcing frequency f1 (Fig. 8)"),
                            ("converge", "refinement study and work-precision figure")):
        p = sub.add_parser(name, help=help_text)
        p.add_argument("scene", help="scene TOML file, or the name of a shipped scene")
        p.add_argument("-o", "--output", type=Path, default=None,
                       help="output directory (default results/<scene>/<command>)")
        p.add_argument("--elements", type=int, default=None, help="number of elements N")
        p.add_argument("--degree", type=int, default=None, help="Lagrange degree p (FE)")
        p.add_argument("--scheme", choices=("fe", "spline"), default=None,
                       help="discretisation scheme (default: the scene's)")
        if name == "modes":
            p.add_argument("--count", type=int, default=None, help="number of modes to report")
        if name == "simulate":
            p.add_argument("--until", type=float, default=None,
                           help="end of the simulation [s] (default: the scene's time.until_s)")
        if name == "converge":
            p.add_argument("--quantity", required=True,
                           help="quantity of interest: tension_s0, eigenvalues, ...")
        if name == "sweep":
            p.add_argument("--f1", default=None, metavar="START:STOP:STEP",
                           help="frequencies in Hz (default: the scene's [sweep] section)")
            p.add_argument("--series", action="store_true",
                           help="also write each point's tension time series (CSV)")
    p = sub.add_parser("extremes", help="the scenes at the edges of the physics (studies/extremes)")
    p.add_argument("-o", "--output", type=Path, default=Path("results/extremes"),
                   help="output directory (default results/extremes)")
    p.add_argument("cases", nargs="*", help="case names (default: all)")
    return parser


def _fail(message: str) -> int:
    print(f"rawehelix: error: {message}", file=sys.stderr)
    return 2


def _frequencies(spec: str | None, params) -> list[float]:
    """START:STOP:STEP in Hz, or the scene's [sweep] section."""
    if spec is None:
        return params.sweep.frequencies()
    try:
        start, stop, step = (float(v) for v in spec.split(":"))
    except ValueError:
        raise ValueError(f"{spec!r} is not START:STOP:STEP (numbers in Hz)") from None
    if not (start > 0 and stop >= start and step > 0):
        raise ValueError(f"{spec!r}: needs 0 < START <= STOP and STEP > 0")
    from rawehelix.parameters import Sweep
    import dataclasses
    return dataclasses.replace(Sweep(), f1_start_Hz=start, f1_stop_Hz=stop,
                               f1_step_Hz=step).frequencies()


def _extremes(args, petsc_args) -> int:
    from rawehelix.studies import extremes
    unknown = [c for c in args.cases if c not in extremes.CASES]
    if unknown:
        return _fail(f"extremes: unknown case(s) {', '.join(unknown)}; "
                     f"known: {', '.join(extremes.CASES)}")
    import petsc4py
    petsc4py.init([sys.argv[0], *petsc_args])
    logging.getLogger().setLevel(logging.WARNING)
    extremes.run(args.output, cases=args.cases or None)
    return 0


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    args, petsc_args = _parser().parse_known_args(argv)
    stray = [a for a in petsc_args if not a.startswith("-")]
    if stray:
        return _fail(f"unexpected argument(s) {' '.join(stray)}")
    if args.command == "extremes":
        return _extremes(args, petsc_args)
    try:
        params = scenes.load(args.scene, elements=args.elements, degree=args.degree,
                             scheme=args.scheme)
    except scenes.SceneError as err:
        return _fail(str(err))
    if args.command == "simulate" and args.until is not None and not args.until > 0:
        return _fail("--until: must be a number of seconds > 0")
    if args.command == "simulate" and params.discretisation.scheme != "fe":
        return _fail(f"{scenes.resolve(args.scene)}: discretisation.scheme: 'simulate' runs the FE "
                     "scheme (the spline reference is solvers.spline_galerkin.dynamics)")
    path = scenes.resolve(args.scene)
    name = path.stem
    if args.command == "sweep":
        try:
            frequencies = _frequencies(args.f1, params)
        except ValueError as err:
            return _fail(f"--f1: {err}")
    outdir = args.output or Path("results") / name / args.command

    # PETSc reads its options once, at initialisation: before any import of PETSc.
    import petsc4py
    petsc4py.init([sys.argv[0], *petsc_args])
    logging.getLogger().setLevel(logging.WARNING)  # quiet the JIT compilers
    from mpi4py import MPI
    from rawehelix.solvers.snes import SolverError
    log = print if MPI.COMM_WORLD.rank == 0 else (lambda *a, **k: None)
    try:
        if args.command == "stationary":
            if params.discretisation.scheme != "fe":
                return _fail(f"{path}: discretisation.scheme: 'stationary' runs the FE scheme; "
                             "the spline reference's stationary state is part of 'modes'")
            from rawehelix.studies import stationary
            stationary.run(params, outdir, name=name, title=scenes.title(path), log=log)
        elif args.command == "modes":
            from rawehelix.studies import modes
            modes.run(params, outdir, count=args.count, log=log)
        elif args.command == "simulate":
            from rawehelix.studies import simulate
            simulate.run(params, outdir, name=name, title=scenes.title(path), until_s=args.until,
                         log=log)
        elif args.command == "converge":
            from rawehelix.studies import converge
            if args.quantity not in converge.quantities():
                return _fail(f"--quantity: {args.quantity!r} is not one of "
                             f"{', '.join(converge.quantities())}")
            converge.run(params, args.quantity, outdir, name=name, log=log)
        elif args.command == "sweep":
            from rawehelix.studies import sweep
            try:
                sweep.run(params, outdir, frequencies, name=name, log=log, series=args.series)
            except sweep.SweepError as err:
                return _fail(str(err))
    except scenes.SceneError as err:  # e.g. modes: count (checked by the library)
        return _fail(str(err))
    except SolverError as err:
        print(f"rawehelix: {err}", file=sys.stderr)
        _abort_other_ranks(MPI.COMM_WORLD, 1)
        return 1
    except NotImplementedError as err:
        return _fail(str(err))
    except Exception:
        if MPI.COMM_WORLD.size == 1:
            raise
        traceback.print_exc()
        _abort_other_ranks(MPI.COMM_WORLD, 1)
        raise
    return 0


def _abort_other_ranks(comm, code: int):
    """Under mpirun an error on one rank would leave the others waiting in a
    collective call for ever (Open MPI waits busily: both cores stay at 100 %):
    end the whole job instead."""
    if comm.size > 1:
        sys.stderr.flush()
        comm.Abort(code)


if __name__ == "__main__":
    sys.exit(main())
