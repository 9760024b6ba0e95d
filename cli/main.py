"""The `rawehelix` command line: a thin layer over the Python API (:mod:`rawehelix.api`).

    rawehelix stationary SCENE [-o DIR] [--elements N] [--degree p] [PETSc options]
    rawehelix modes SCENE [--scheme fe|spline] [--elements N] [--degree p] [--count k] [-o DIR]
    rawehelix simulate SCENE [-o DIR] [--until T] [--no-gif] [--elements N] [--degree p] [PETSc options]
    rawehelix sweep SCENE [--f1 START:STOP:STEP] [--series] [-o DIR] [--scheme ...] [--elements N]
    rawehelix response SCENE [--f1 START:STOP:STEP] [--elements N] [--degree p] [-o DIR]
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
are checked before it starts: studies/outdir.py, studies/resources.py).  A
failed solve exits with status 1.  A study with failed points, or a
calibration that missed a target by more than its tolerance, writes its
results and exits with status 3.  Ctrl-C exits with 130, saying what was kept
and how to resume.
"""

from __future__ import annotations

import argparse
import logging
import signal
import math
import sys
import tomllib
import traceback
from pathlib import Path

from rawehelix import errors
from rawehelix.studies.scene import SceneError

#: exit statuses (README): bad input, a failed solve, Ctrl-C (128 + SIGINT)
BAD_INPUT, FAILED, INTERRUPTED = 2, 1, 130
#: a resumable command's finished points in its output directory, for Ctrl-C's message
KEPT = {"sweep": "points/f1_*.json", "orbits": "window*/p*.json", "study": "points/*.json",
        "calibrate": "points/*.json", "converge": "runs/*.json"}
COMMANDS = ("stationary", "modes", "simulate", "sweep", "response", "orbits", "converge",
            "extremes", "labtest", "study", "calibrate")
log = logging.getLogger("rawehelix")


class _Parser(argparse.ArgumentParser):
    """argparse with its refusals on one line, as every other bad input."""

    def error(self, message):
        self.exit(BAD_INPUT, f"{self.prog}: error: {message}\n")


def _petsc_unused(p):
    p.add_argument("--petsc-unused", choices=("error", "warn"), default="error",
                   help="a PETSc option that no solver reads: refuse the run (default) "
                        "or only warn")


def _parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="rawehelix", description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    for name, help_text in (("stationary", "stationary state with fixed ends (Sec. 5.1)"),
                            ("modes", "natural modes about the stationary state (Table 3)"),
                            ("simulate", "dynamics from the stationary state (Secs. 5.2, 5.3)"),
                            ("sweep", "sweep of the upper end's forcing frequency f1 (Fig. 8)"),
                            ("response", "linear frequency response to the upper end's circle"),
                            ("orbits", "periodic orbits over f1 with Floquet stability, through folds"),
                            ("converge", "refinement study and work-precision figure"),
                            ("study", "named quantities over a design of scene keys, on MPI ranks"),
                            ("calibrate", "fit scene keys to target quantities (least squares)")):
        p = sub.add_parser(name, help=help_text)
        p.add_argument("scene", help="scene TOML file, or the name of a shipped scene")
        p.add_argument("-o", "--output", type=Path, default=None,
                       help="output directory (default results/<scene>/<command>)")
        p.add_argument("--elements", type=int, default=None, help="number of elements N")
        p.add_argument("--degree", type=int, default=None, help="Lagrange degree p (FE)")
        p.add_argument("--scheme", choices=("fe", "spline"), default=None,
                       help="discretisation scheme (default: the scene's)")
        p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                       help="set a dotted scene key, e.g. --set helix.EI_Nm2=9000 (repeatable)")
        p.add_argument("-v", "--verbose", action="count", default=0,
                       help="more messages (-vv: the solvers' and compilers' too)")
        _petsc_unused(p)
        if name == "modes":
            p.add_argument("--count", type=int, default=None,
                           help="report the k slowest modes (default: the lowest 3 of each family)")
        if name == "simulate":
            p.add_argument("--until", type=float, default=None,
                           help="end of the simulation [s] (default: the scene's time.until_s)")
            p.add_argument("--no-gif", action="store_true", help="skip the animated GIF")
        if name == "converge":
            p.add_argument("--quantity", required=True,
                           help="quantity of interest: tension_s0, eigenvalues, ...")
        if name == "study":
            p.add_argument("--vary", action="append", required=True,
                           metavar="KEY=START:STOP:COUNT",
                           help="a dotted scene key and its range (repeatable; COUNT: grid points)")
            p.add_argument("--sample", choices=("grid", "lhs", "sobol"), default="grid",
                           help="the design (default grid; lhs, sobol: scipy.stats.qmc, SALib)")
            p.add_argument("--points", type=int, default=None,
                           help="lhs: points; sobol: base points N (N (d + 2) scenes)")
            p.add_argument("--point-timeout", type=float, default=None, metavar="S",
                           help="a point still running after S seconds (wall) fails with "
                                "that reason; a rerun with a longer limit computes it again")
        if name in ("study", "calibrate"):
            p.add_argument("--quantity" if name == "study" else "--target", required=True,
                           metavar="Q[,Q...]" if name == "study" else "Q=VALUE[,...]",
                           help="quantities: " + ", ".join(_quantity_names())
                           if name == "study" else "target values of quantities")
            p.add_argument("--fd-step", type=float, default=None, metavar="h",
                           help="relative finite-difference step (default 1e-2 for the "
                                "sensitivities, 1e-3 for the Jacobian)")
        if name == "calibrate":
            p.add_argument("--fit", required=True, metavar="KEY[,KEY...]",
                           help="the dotted scene keys to fit")
            p.add_argument("--bounds", action="append", default=[], metavar="KEY=LO:HI",
                           help="bounds of a fitted key (repeatable)")
            p.add_argument("--uncertainty", type=float, default=0.01, metavar="REL",
                           help="relative standard uncertainty of the targets, for the "
                                "linearised confidence (default 0.01)")
            p.add_argument("--tolerance", type=float, default=None, metavar="REL",
                           help="a target is met within this relative residual (default "
                                "1e-3); missed: exit status 3")
        if name == "orbits":
            p.add_argument("--f1", required=True, metavar="START:STOP",
                           help="the f1 window in Hz, traced from START towards STOP")
            p.add_argument("--sweep", type=Path, default=None, metavar="DIR",
                           help="a sweep's output directory: its points on the diagram")
            p.add_argument("--tension-step", type=float, default=None, metavar="FRACTION",
                           help="largest relative change of T max between two points "
                                "(default 0.05)")
            p.add_argument("--max-points", type=int, default=400,
                           help="stop each rank's window after this many points (a rerun "
                                "with the same -o resumes)")
            p.add_argument("--superharmonics", default="2,3", metavar="K[,K...]",
                           help="orders k of the k:1 resonances f_n / k of the lateral natural "
                                "frequencies where the step closes in on a multiplier's "
                                "crossing of +1 ('none': the T max step only)")
        if name in ("sweep", "response"):
            p.add_argument("--f1", default=None, metavar="START:STOP:STEP",
                           help="frequencies in Hz (default: the scene's [sweep] section)")
        if name == "sweep":
            p.add_argument("--series", action="store_true",
                           help="also write each point's tension time series (CSV)")
    p = sub.add_parser("extremes", help="the scenes at the edges of the physics (studies/extremes)")
    p.add_argument("-o", "--output", type=Path, default=Path("results/extremes"),
                   help="output directory (default results/extremes)")
    p.add_argument("-v", "--verbose", action="count", default=0, help="more messages")
    _petsc_unused(p)
    p.add_argument("cases", nargs="*", help="case names (default: all)")
    p = sub.add_parser("labtest", help="the paper's lab tests (Sec. 4, Fig. 2) as virtual tests")
    p.add_argument("test", choices=("axial", "bending", "torsion"))
    p.add_argument("--tension", default=None, metavar="T1,T2,...",
                   help="tensions T_e in N (default: axial 50-250, bending 90,181,259, torsion 200)")
    p.add_argument("--loads", default=None, metavar="X1,X2,...",
                   help="bending: F_N in N (default 2.5,5,7.5,10); torsion: M_t in Nm (default 5-25)")
    p.add_argument("--fit", action="store_true",
                   help="bending: identify the intrinsic law EI = a T + b that reproduces Eq. (64)")
    p.add_argument("--EI", type=float, default=None, dest="rod_EI", metavar="NM2",
                   help="the rod's constant EI in N m^2 (default: Eq. (64) at each T_e for bending, "
                        "the scene's EI otherwise)")
    p.add_argument("--scene", default="stationary_table2",
                   help="the scene whose helix the segment is cut from (default stationary_table2)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="set a dotted key of that scene (repeatable)")
    p.add_argument("--no-gravity", action="store_true", help="switch gravity off (the lab has it)")
    p.add_argument("--elements", type=int, default=None, help="number of elements N (default 8)")
    p.add_argument("--degree", type=int, default=None, help="Lagrange degree p")
    p.add_argument("-o", "--output", type=Path, default=None,
                   help="output directory (default results/labtest/<test>)")
    p.add_argument("-v", "--verbose", action="count", default=0, help="more messages")
    _petsc_unused(p)
    return parser


def _quantity_names() -> list[str]:
    from rawehelix.studies import quantities
    return quantities.names()


def _fail(message: str) -> int:
    print(f"rawehelix: error: {message}", file=sys.stderr)
    return BAD_INPUT


def _interrupted(command: str, outdir, comm) -> int:
    """Ctrl-C: one line saying what was kept (rank 0), no traceback."""
    if comm.rank == 0:
        if command in KEPT and outdir is not None:
            n = len(list(Path(outdir).glob(KEPT[command])))
            said = (f"{n} finished point{'s' * (n != 1)} kept in {outdir}/; run the same "
                    "command again to resume")
        elif command == "simulate" and outdir is not None and Path(outdir).is_dir():
            said = f"the series up to the last checkpoint is in {outdir}/ (no resume)"
        else:
            said = "nothing was written"
        print(f"rawehelix: interrupted: {said}", file=sys.stderr, flush=True)
    _abort_other_ranks(comm, INTERRUPTED)  # a rank that was not interrupted would wait
    return INTERRUPTED


def _overrides(args) -> dict:
    """--set KEY=VALUE (values in TOML syntax: 9000, 1e-3, true, "graded") and
    --f1 START:STOP:STEP, as dotted scene keys: validated by the scene loader."""
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
    if args.command in ("sweep", "response") and args.f1 is not None:
        try:
            start, stop, step = (float(v) for v in args.f1.split(":"))
        except ValueError:
            raise SceneError("--f1", args.f1, "is not START:STOP:STEP (numbers in Hz)") from None
        over.update({"sweep.f1_start_Hz": start, "sweep.f1_stop_Hz": stop,
                     "sweep.f1_step_Hz": step})
    return over


def main(argv: list[str] | None = None) -> int:
    from rawehelix.cli import argv as argv_split
    from rawehelix.studies import logs, outdir as outdir_check, outdir_lock

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
    outdir = None
    try:
        petsc_options.check(args.petsc_unused, argv_split.option_strings(parser, args.command))
        if args.command == "extremes":
            with outdir_lock.hold(args.output, comm):
                status = _extremes(args)
        elif args.command == "labtest":
            status = _labtest(rh, args, comm)
        else:
            params = rh.load_scene(args.scene, elements=args.elements, degree=args.degree,
                                   scheme=args.scheme, overrides=_overrides(args))
            outdir = args.output or Path("results") / params.name / args.command
            outdir_check.check(outdir, args.command)
            with outdir_lock.hold(outdir, comm):  # one writer per output folder: exit 2 if held
                status = COMMAND[args.command](rh, params, args, outdir, comm)
        _warn_unused_after_run(petsc_options, comm)
        return status
    except SceneError as err:
        return _fail(str(err))
    except outdir_lock.OutputFault as err:  # a full disk: one line, exit 1 (outdir_lock.py)
        print(f"rawehelix: error: {err}", file=sys.stderr)
        _abort_other_ranks(comm, 1)
        return 1
    except rh.SolverError as err:
        print(f"rawehelix: {err}", file=sys.stderr)
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


def _say(comm, text: str):
    """The command's result, on rank 0's stdout."""
    if comm.rank == 0:
        print(text, flush=True)


def _stationary(rh, params, args, outdir, comm) -> int:
    from rawehelix.studies import stationary
    result = rh.stationary(params, comm)
    result.write(outdir)
    _say(comm, stationary.report(result) + f"\n  wrote {outdir}/")
    return 0


def _modes(rh, params, args, outdir, comm) -> int:
    from rawehelix.studies import modes
    result = rh.modes(params, count=args.count, comm=comm)
    result.write(outdir)
    _say(comm, modes.report(result) + f"\nwrote {outdir}/")
    return 0


def _simulate(rh, params, args, outdir, comm) -> int:
    from rawehelix.studies import resources, simulate
    resources.check_run(params, "simulate")  # before allocating (rh.simulate's check)

    def checkpoint(partial):  # the last good state and the series so far, every minute
        partial.write(outdir, pictures=False)

    try:
        result = simulate.compute(params, until_s=args.until, comm=comm, checkpoint=checkpoint)
    except simulate.SimulationError as err:
        err.partial.write(outdir, pictures=False)
        raise rh.SolverError(f"{err} The series and the last good state are in "
                             f"{outdir}/ (time_series.csv, state.npz).") from None
    result.write(outdir, gif=not args.no_gif)
    _say(comm, simulate.report(result) + f"\n  wrote {outdir}/")
    return 0


def _sweep(rh, params, args, outdir, comm) -> int:
    from rawehelix.studies import sweep
    from rawehelix.studies.sweep_store import SweepError
    try:
        result = rh.sweep(params, comm=comm, checkpoint=outdir)
    except SweepError as err:
        raise SceneError("-o", str(outdir), str(err)) from None
    result.write(outdir, series=args.series)
    _say(comm, sweep.report(result) + f"\n  wrote {outdir}/")
    return 0


def _orbits(rh, params, args, outdir, comm) -> int:
    from rawehelix.studies import orbits
    try:
        start, stop = (float(x) for x in args.f1.split(":"))
    except ValueError:
        raise SceneError("--f1", args.f1, "must be START:STOP in Hz") from None
    if not (start > 0 and stop > 0 and start != stop and math.isfinite(start + stop)):
        raise SceneError("--f1", args.f1, "must be START:STOP with START != STOP, both > 0 Hz "
                         "(an empty or negative window)")
    try:
        orders = (() if args.superharmonics.strip().lower() == "none"
                  else tuple(int(k) for k in args.superharmonics.split(",")))
    except ValueError:
        raise SceneError("--superharmonics", args.superharmonics,
                         "must be integers K[,K...] >= 2 or 'none'") from None
    if args.sweep is not None:
        orbits.check_sweep_dir(args.sweep)
    try:
        result = rh.orbits(params, start, stop, comm=comm, outdir=outdir,
                           tension_step=args.tension_step, max_points=args.max_points,
                           superharmonics=orders,
                           progress=lambda o: _say(comm, f"  f1 = {o.f1_Hz:.4f} Hz: T max "
                                                   f"{o.tension_max_N:.2f} N, |multiplier| "
                                                   f"{o.max_multiplier:.5f}"))
    except orbits.OrbitsStoreError as err:
        raise SceneError("-o", str(outdir), str(err)) from None
    if comm.rank == 0:
        result.write(outdir, sweep_dir=args.sweep)
    _say(comm, orbits.report(result) + f"\n  wrote {outdir}/")
    return 0


def _response(rh, params, args, outdir, comm) -> int:
    from rawehelix.studies import response
    result = rh.response(params, comm=comm)
    result.write(outdir)
    _say(comm, response.report(result) + f"\n  wrote {outdir}/")
    return 0


def _converge(rh, params, args, outdir, comm) -> int:
    from rawehelix.studies import converge
    if args.quantity not in converge.quantities():
        raise SceneError("--quantity", args.quantity,
                         f"is not one of {', '.join(converge.quantities())}")
    converge.run(params, args.quantity, outdir, name=params.name,
                 log=lambda m: _say(comm, m), comm=comm)
    return 0


def _numbers(option: str, text: str | None):
    """"1,2.5,3" -> (1.0, 2.5, 3.0); None stays None."""
    if text is None:
        return None
    try:
        return tuple(float(v) for v in text.split(","))
    except ValueError:
        raise SceneError(option, text, "must be numbers separated by commas, e.g. 90,181,259") from None


def _labtest(rh, args, comm) -> int:
    from rawehelix.studies import labtest, outdir as outdir_check, outdir_lock
    scene = rh.load_scene(args.scene, overrides=_overrides(args))
    outdir = args.output or Path("results") / "labtest" / (args.test + "_fit" * args.fit)
    outdir_check.check(outdir, "labtest")
    with outdir_lock.hold(outdir, comm):  # one writer per output folder, as every command
        result = rh.labtest(args.test, scene, tensions_N=_numbers("--tension", args.tension),
                            loads=_numbers("--loads", args.loads), fit=args.fit,
                            rod_EI_Nm2=args.rod_EI, elements=args.elements, degree=args.degree,
                            gravity=not args.no_gravity, comm=comm)
        result.write(outdir)
    _say(comm, labtest.report(result) + f"\n  wrote {outdir}/")
    return 0


def _extremes(args) -> int:
    from rawehelix.studies import extremes, outdir as outdir_check
    outdir_check.check(args.output, "extremes")
    unknown = [c for c in args.cases if c not in extremes.CASES]
    if unknown:
        raise SceneError("extremes", ", ".join(unknown),
                         f"unknown case(s); known: {', '.join(extremes.CASES)}")
    extremes.run(args.output, cases=args.cases or None)
    return 0


def _source(args):
    from rawehelix.studies.study import Source
    return Source(args.scene, args.elements, args.degree, args.scheme, _overrides(args))


def _study(rh, params, args, outdir, comm) -> int:
    from rawehelix.studies import quantities, study
    variables = [study.parse_vary(v) for v in args.vary]
    result = study.compute(_source(args), variables, quantities.parse_list(args.quantity),
                           outdir, sample=args.sample, points=args.points, fd_step=args.fd_step,
                           comm=comm, log=log.info, point_timeout=args.point_timeout)
    return _write_and_say(comm, result, study.report(result), outdir)


def _calibrate(rh, params, args, outdir, comm) -> int:
    from rawehelix.studies import calibrate
    fit = calibrate.parse_fit(args.fit)
    result = calibrate.compute(_source(args), fit, calibrate.parse_targets(args.target), outdir,
                               bounds=calibrate.parse_bounds(args.bounds, fit),
                               uncertainty=args.uncertainty, fd_step=args.fd_step, comm=comm,
                               log=log.info, tolerance=args.tolerance)
    return _write_and_say(comm, result, calibrate.report(result), outdir)


def _write_and_say(comm, result, text: str, outdir) -> int:
    """A study's or a calibration's files (rank 0) and its report; its exit status."""
    if comm.rank == 0:
        result.write(outdir)
    _say(comm, text + f"\n  wrote {outdir}/")
    return result.exit_status


COMMAND = {"stationary": _stationary, "modes": _modes, "simulate": _simulate, "sweep": _sweep,
           "response": _response, "orbits": _orbits, "converge": _converge, "study": _study,
           "calibrate": _calibrate}


def _abort_other_ranks(comm, code: int):
    """Under mpirun an error on one rank would leave the others waiting in a
    collective call for ever (Open MPI waits busily: both cores stay at 100 %):
    end the whole job instead."""
    if comm.size > 1:
        sys.stderr.flush()
        comm.Abort(code)


if __name__ == "__main__":
    sys.exit(main())
