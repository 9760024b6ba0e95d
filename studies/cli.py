"""The `rawehelix` command line.

    rawehelix stationary SCENE [-o DIR] [--elements N] [--degree p] [PETSc options]
    rawehelix modes SCENE [--scheme fe|spline] [--elements N] [--degree p] [--count k] [-o DIR]

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
from pathlib import Path

from rawehelix.studies import scene as scenes

COMMANDS = ("stationary", "modes")


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="rawehelix", description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    for name, help_text in (("stationary", "stationary state with fixed ends (Sec. 5.1)"),
                            ("modes", "natural modes about the stationary state (Table 3)")):
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
    return parser


def _fail(message: str) -> int:
    print(f"rawehelix: error: {message}", file=sys.stderr)
    return 2


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    args, petsc_args = _parser().parse_known_args(argv)
    stray = [a for a in petsc_args if not a.startswith("-")]
    if stray:
        return _fail(f"unexpected argument(s) {' '.join(stray)}")
    try:
        params = scenes.load(args.scene, elements=args.elements, degree=args.degree,
                             scheme=args.scheme)
    except scenes.SceneError as err:
        return _fail(str(err))
    if args.command == "modes" and args.count is not None and args.count < 1:
        return _fail("--count: must be an integer >= 1")
    path = scenes.resolve(args.scene)
    name = path.stem
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
    except SolverError as err:
        print(f"rawehelix: {err}", file=sys.stderr)
        return 1
    except NotImplementedError as err:
        return _fail(str(err))
    return 0


if __name__ == "__main__":
    sys.exit(main())
