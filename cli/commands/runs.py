"""The single-run commands: stationary, modes, simulate, sweep, response, orbits,
campbell, and section (closed forms, no solve)."""

from __future__ import annotations

import math
from pathlib import Path

from rawehelix.cli.commands.base import Command, check_branch_output, method_argument, say
from rawehelix.studies import needs
from rawehelix.studies.scene import SceneError


def _written(comm, result, text: str, outdir, before: str = "\n  ") -> int:
    """A run's files (``result.write``) and its report with where they are."""
    result.write(outdir)
    say(comm, text + f"{before}wrote {outdir}/")
    return 0


def _section(rh, params, args, outdir, comm) -> int:
    from rawehelix.studies import section_moduli
    result = rh.section(params)
    result.write(outdir, comm.rank)
    say(comm, section_moduli.report(result) + f"\n  wrote {outdir}/")
    return 0


def _stationary(rh, params, args, outdir, comm) -> int:
    from rawehelix.studies import stationary
    result = rh.stationary(params, comm)
    return _written(comm, result, stationary.report(result), outdir)


def _modes_arguments(p):
    p.add_argument("--count", type=int, default=None,
                   help="report the k slowest modes (default: the lowest 3 of each family)")


def _modes(rh, params, args, outdir, comm) -> int:
    from rawehelix.studies import modes
    result = rh.modes(params, count=args.count, comm=comm)
    return _written(comm, result, modes.report(result), outdir, before="\n")


def _simulate_arguments(p):
    p.add_argument("--until", type=float, default=None,
                   help="end of the simulation [s] (default: the scene's time.until_s)")
    p.add_argument("--no-gif", action="store_true", help="skip the animated GIF")


def _simulate(rh, params, args, outdir, comm) -> int:
    from rawehelix.studies.store import outdir as outdir_check
    from rawehelix.studies import resources, simulate
    resources.check_run(params, "simulate")  # before allocating (rh.simulate's check)
    resources.check_simulate(params, args.until)  # its outputs, frames and steps
    outdir_check.check(outdir, needs.get("simulate"),
                       extra_bytes=resources.simulate_output_bytes(params, args.until))

    def checkpoint(partial):  # the last good state and the series so far, every minute
        partial.write(outdir, pictures=False)

    try:
        result = simulate.compute(params, until_s=args.until, comm=comm, checkpoint=checkpoint)
    except simulate.SimulationError as err:
        err.partial.write(outdir, pictures=False)
        raise rh.SolverError(f"{str(err).rstrip('.')}. The series and the last good state are in "
                             f"{outdir}/ (time_series.csv, state.npz).") from None
    result.write(outdir, gif=not args.no_gif)
    say(comm, simulate.report(result) + f"\n  wrote {outdir}/")
    return 0


def _f1_grid_arguments(p):
    p.add_argument("--f1", default=None, metavar="START:STOP:STEP",
                   help="frequencies in Hz (default: the scene's [sweep] section)")


def _sweep_arguments(p):
    _f1_grid_arguments(p)
    p.add_argument("--series", action="store_true",
                   help="also write each point's tension time series (CSV)")


def _sweep(rh, params, args, outdir, comm) -> int:
    from rawehelix.studies.store import outdir as outdir_check
    from rawehelix.studies import resources, sweep
    from rawehelix.studies.store.sweep_store import SweepError
    count = resources.frequency_count(params)
    resources.check_run(params, "sweep")  # before the disk's estimate counts its points
    outdir_check.check(outdir, needs.get("sweep"), points=count,
                       extra_bytes=resources.sweep_output_bytes(params, count))
    try:
        result = rh.sweep(params, comm=comm, checkpoint=outdir)
    except SweepError as err:
        raise SceneError("-o", str(outdir), str(err)) from None
    result.write(outdir, series=args.series)
    say(comm, sweep.report(result) + f"\n  wrote {outdir}/")
    return 0


def _response(rh, params, args, outdir, comm) -> int:
    from rawehelix.studies import response
    result = rh.response(params, comm=comm)
    return _written(comm, result, response.report(result), outdir)


def _orbits_arguments(p):
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
    method_argument(p, "orbits", "the periodic-orbit problem: {methods}")


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
    check_branch_output(params, "orbits", outdir, comm.size, start, stop, args.method,
                        key="--f1", max_points=args.max_points)
    try:
        result = rh.orbits(params, start, stop, comm=comm, outdir=outdir,
                           tension_step=args.tension_step, max_points=args.max_points,
                           superharmonics=orders, method=args.method,
                           progress=lambda o: say(comm, f"  f1 = {o.f1_Hz:.4f} Hz: T max "
                                                  f"{o.tension_max_N:.2f} N, |multiplier| "
                                                  f"{o.max_multiplier:.5f}" + (
                                                      f", H = {o.accuracy['H']}"
                                                      if o.accuracy else "")))
    except orbits.OrbitsStoreError as err:
        raise SceneError("-o", str(outdir), str(err)) from None
    if comm.rank == 0:
        result.write(outdir, sweep_dir=args.sweep)
    say(comm, orbits.report(result) + f"\n  wrote {outdir}/")
    return 0


def _operate_arguments(p):
    p.add_argument("--wind", required=True, metavar="LO:HI:STEP",
                   help="wind speeds in m/s at the reference height (the scene's [wind] "
                        "profile, or environment.wind_speed_m_s's uniform wind)")


def _operate(rh, params, args, outdir, comm) -> int:
    from rawehelix.studies.store import outdir as outdir_check
    from rawehelix.studies import operate
    winds = operate.parse_wind(args.wind)
    operate.plan(params, winds, key="--wind", text=args.wind)  # numpy: refuses before any work
    outdir_check.check(outdir, needs.get("operate"), points=len(winds))
    result = rh.operate(params, winds, comm=comm)
    return _written(comm, result, operate.report(result), outdir)


def _campbell_arguments(p):
    p.add_argument("--wind", required=True, metavar="LO:HI:STEP",
                   help="wind speeds in m/s at the wind's reference height, LO to HI")
    p.add_argument("--envelope", type=Path, default=None, metavar="DIR",
                   help="an envelope's output directory: the band where the forced helix "
                        "slackens (Sec. 5.3) on the diagram")


def _campbell(rh, params, args, outdir, comm) -> int:
    from rawehelix.studies import campbell, operate
    from rawehelix.studies.store import outdir as outdir_check
    winds = operate.parse_wind(args.wind)
    envelope = campbell.read_envelope(args.envelope) if args.envelope is not None else None
    campbell.refuse_moving_top(params)
    operate.plan(params, winds, key="--wind", text=args.wind)  # numpy: refuses before any work
    outdir_check.check(outdir, needs.get("campbell"), points=len(winds))
    result = rh.campbell(params, wind_m_s=winds, envelope=envelope, comm=comm)
    if comm.rank == 0:
        result.write(outdir)
    say(comm, campbell.report(result) + f"\n  wrote {outdir}/")
    return 0


def _none(p):
    """No options of its own."""


COMMANDS = [
    Command("stationary", "stationary state with fixed ends (Sec. 5.1), under the ends' balanced "
            "torque (a twisted state)", _none, _stationary, needs.get("stationary")),
    Command("modes", "natural modes about the stationary state (Table 3)", _modes_arguments,
            _modes, needs.get("modes")),
    Command("simulate", "dynamics from the stationary state (Secs. 5.2, 5.3)",
            _simulate_arguments, _simulate, needs.get("simulate")),
    Command("sweep", "sweep of the upper end's forcing frequency f1 (Fig. 8)", _sweep_arguments,
            _sweep, needs.get("sweep"), kept="points/f1_*.json", f1_grid=True),
    Command("response", "linear frequency response to the upper end's circle",
            _f1_grid_arguments, _response, needs.get("response"), f1_grid=True),
    Command("orbits", "periodic orbits over f1 with Floquet stability, through folds",
            _orbits_arguments, _orbits, needs.get("orbits"), kept="window*/p*.json"),
    Command("operate", "operating points of the rotor and generator over the wind speed: "
            "the power curve up to the helix's first limit", _operate_arguments, _operate,
            needs.get("operate")),
    Command("campbell", "Campbell diagram: the helix's modes about its operating points "
            "against the rotor speed, the 1P, 2P, BP lines and their crossings",
            _campbell_arguments, _campbell, needs.get("campbell")),
    Command("section", "EA, EI and GJ of the section's members (and the lab tests' values)",
            _none, _section, needs.get("section")),
]
