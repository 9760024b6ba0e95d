"""The commands that run a scene many times: converge (refinement ladders),
study (a design of scene keys) and calibrate (a least-squares fit)."""

from __future__ import annotations

import logging

from rawehelix.cli.commands.base import (Command, check_branch_output, method_argument,
                                          overrides, say)
from rawehelix.studies import needs, quantities
from rawehelix.studies.scene import SceneError

log = logging.getLogger("rawehelix")


def _converge_arguments(p):
    p.add_argument("--quantity", required=True,
                   help="quantity of interest: tension_s0, eigenvalues, ...")


def _converge(rh, params, args, outdir, comm) -> int:
    from rawehelix.studies.converge import study as converge
    if args.quantity not in quantities.refined():
        raise SceneError("--quantity", args.quantity,
                         f"is not one of {', '.join(quantities.refined())}"
                         + quantities.other_command(args.quantity))
    converge.run(params, quantities.refined()[args.quantity], outdir, name=params.name,
                 log=lambda m: say(comm, m), comm=comm)
    return 0


def _fd_step(p):
    p.add_argument("--fd-step", type=float, default=None, metavar="h",
                   help="relative finite-difference step (default 1e-2 for the "
                        "sensitivities, 1e-3 for the Jacobian)")


def _study_arguments(p):
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
    p.add_argument("--quantity", required=True, metavar="Q[,Q...]",
                   help="quantities: " + ", ".join(quantities.names()))
    _fd_step(p)


def _calibrate_arguments(p):
    p.add_argument("--target", required=True, metavar="Q=VALUE[,...]",
                   help="target values of quantities")
    _fd_step(p)
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


def _source(args):
    from rawehelix.studies.study import Source
    return Source(args.scene, args.elements, args.degree, args.scheme, overrides(args))


def _study(rh, params, args, outdir, comm) -> int:
    from rawehelix.studies import study
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
    say(comm, text + f"\n  wrote {outdir}/")
    return result.exit_status


def _envelope_arguments(p):
    p.add_argument("--vary", required=True, action="append", metavar="KEY=LO:HI[:COUNT]",
                   help="the dotted scene key across the map and its range (COUNT values, "
                        "default 5), e.g. helix.EI_Nm2=2000:8000:5 or ends.elongation; "
                        "one only (a map has one axis of keys)")
    p.add_argument("--f1", required=True, metavar="LO:HI", help="the f1 window in Hz")
    method_argument(p, "envelope", "the periodic-orbit problem of the branches and the "
                                   "curves (default {default})")


def _envelope(rh, params, args, outdir, comm) -> int:
    from rawehelix.studies import envelope
    if len(args.vary) > 1:
        raise SceneError("--vary", " ".join(args.vary),
                         "is given more than once: an envelope maps one scene key against "
                         "f1; give one --vary (several keys: rawehelix study)")
    try:
        lo, hi = (float(x) for x in args.f1.split(":"))
    except ValueError:
        raise SceneError("--f1", args.f1, "must be LO:HI in Hz") from None
    from rawehelix.studies.sampling import parse_vary
    vary = parse_vary(args.vary[0])
    check_branch_output(params, "envelope", outdir, vary.count or envelope.DEFAULT_VALUES,
                        lo, hi, args.method, key="--vary")
    try:
        result = rh.envelope(params, args.vary[0], lo, hi, comm=comm, outdir=outdir,
                             method=args.method,
                             progress=lambda v, o: say(comm, f"  {v:g}: f1 = {o.f1_Hz:.4f} "
                                                       f"Hz, T max {o.tension_max_N:.2f} N"))
    except envelope.OrbitsStoreError as err:  # the folder holds another envelope or branch
        raise SceneError("-o", str(outdir), str(err)) from None
    if comm.rank == 0:
        result.write(outdir)
    say(comm, envelope.report(result) + f"\n  wrote {outdir}/")
    return 0


COMMANDS = [
    Command("converge", "refinement study and work-precision figure", _converge_arguments,
            _converge, needs.get("converge"), kept="runs/*.json"),
    Command("study", "named quantities over a design of scene keys, on MPI ranks",
            _study_arguments, _study, needs.get("study"), kept="points/*.json"),
    Command("envelope", "design map in (f1, a scene key): folds, PD / NS, first limits",
            _envelope_arguments, _envelope, needs.get("envelope"),
            kept="tick*/window*/p*.json"),
    Command("calibrate", "fit scene keys to target quantities (least squares)",
            _calibrate_arguments, _calibrate, needs.get("calibrate"), kept="points/*.json"),
]
