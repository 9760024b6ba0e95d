"""The commands that build their own scenes: extremes (the scenes at the edges
of the physics) and labtest (the paper's lab tests as virtual tests)."""

from __future__ import annotations

from pathlib import Path

from rawehelix.cli.commands.base import Command, overrides, petsc_unused, say
from rawehelix.studies.store import outdir as outdir_check, outdir_lock
from rawehelix.studies import needs
from rawehelix.studies.scene import SceneError


def _extremes_arguments(p):
    p.add_argument("-o", "--output", type=Path, default=Path("results/extremes"),
                   help="output directory (default results/extremes)")
    p.add_argument("-v", "--verbose", action="count", default=0, help="more messages")
    petsc_unused(p)
    p.add_argument("cases", nargs="*", help="case names (default: all)")


def _extremes(rh, args, comm) -> int:
    from rawehelix.studies import extremes
    with outdir_lock.hold(args.output, comm, "extremes"):
        outdir_check.check(args.output, needs.get("extremes"))
        unknown = [c for c in args.cases if c not in extremes.CASES]
        if unknown:
            raise SceneError("extremes", ", ".join(unknown),
                             f"unknown case(s); known: {', '.join(extremes.CASES)}")
        extremes.run(args.output, cases=args.cases or None)
    return 0


def _labtest_arguments(p):
    p.add_argument("test", choices=("axial", "bending", "torsion"))
    p.add_argument("--tension", default=None, metavar="T1,T2,...",
                   help="tensions T_e in N (default: axial 50-250, bending 90,181,259, torsion 200)")
    p.add_argument("--loads", default=None, metavar="X1,X2,...",
                   help="bending: F_N in N (default 2.5,5,7.5,10); torsion: M_t in Nm (default 5-25)")
    p.add_argument("--fit", action="store_true",
                   help="bending: identify the intrinsic law EI = a T + b that reproduces Eq. (64); "
                        "every test: fit the [section] members (section level, members.py)")
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
    petsc_unused(p)


def _numbers(option: str, text: str | None):
    """"1,2.5,3" -> (1.0, 2.5, 3.0); None stays None."""
    if text is None:
        return None
    try:
        return tuple(float(v) for v in text.split(","))
    except ValueError:
        raise SceneError(option, text, "must be numbers separated by commas, e.g. 90,181,259") from None


def _labtest(rh, args, comm) -> int:
    from rawehelix.studies import labtest
    scene = rh.load_scene(args.scene, overrides=overrides(args))
    outdir = args.output or Path("results") / "labtest" / (args.test + "_fit" * args.fit)
    outdir_check.check(outdir, needs.get("labtest"))
    with outdir_lock.hold(outdir, comm, "labtest"):  # one writer, one command, as every command
        result = rh.labtest(args.test, scene, tensions_N=_numbers("--tension", args.tension),
                            loads=_numbers("--loads", args.loads), fit=args.fit,
                            rod_EI_Nm2=args.rod_EI, elements=args.elements, degree=args.degree,
                            gravity=not args.no_gravity, comm=comm)
        result.write(outdir)
    say(comm, labtest.report(result) + f"\n  wrote {outdir}/")
    return result.exit_status  # 3: a fit its data could not determine (fits.py)


COMMANDS = [
    Command("extremes", "the scenes at the edges of the physics (studies/extremes)",
            _extremes_arguments, _extremes, needs.get("extremes"), scene=False),
    Command("labtest", "the paper's lab tests (Sec. 4, Fig. 2) as virtual tests",
            _labtest_arguments, _labtest, needs.get("labtest"), scene=False),
]
