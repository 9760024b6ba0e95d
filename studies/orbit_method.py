"""Which periodic-orbit problem traces a scene's orbits (``--method``): shooting on
the scheme's period map or harmonic balance (solvers/harmonic_balance.py), and
the rule of ``auto``, stated once here and reported with every result
(docs/explanation/harmonic_balance.md, "Where HB is the wrong tool")."""

from __future__ import annotations

from rawehelix.errors import SceneError
from rawehelix.parameters import Parameters
from rawehelix.periodic_orbits.problem import FREE_ROTATION

METHODS = ("shooting", "hb", "auto")


def cannot(params: Parameters) -> str | None:
    """Why harmonic balance cannot trace ``params``'s orbits (None: it can): an
    internal variable or a free rotation breaks its unknowns."""
    from rawehelix.studies import schemes
    refusal = schemes.of(params).harmonic_balance_refusal
    if refusal:
        return refusal
    from rawehelix.solvers import harmonic_balance
    return harmonic_balance.cannot(params)


def wrong_tool(params: Parameters) -> str | None:
    """Why harmonic balance may be the wrong tool for ``params`` (None: it is not): what
    :func:`cannot` says, or a non-smooth law that needs many harmonics (then ``hb``
    runs, its H raised by the tail test, with this warning; where its first orbit needs
    more, it says to shoot)."""
    if params.model.section.active:
        return ("the members' slack is a non-smooth law: past the first slack member the "
                "orbits need many harmonics (where its first orbit is not found, HB says so: "
                "then try --method shooting)")
    return cannot(params)


def choose(params: Parameters, method: str) -> tuple[str, str]:
    """(the method that runs, why): ``auto`` takes harmonic balance wherever it can run
    (:func:`cannot`), with :func:`wrong_tool`'s warning for a non-smooth law: on the
    tensegrity section (mobile_end, N = 4, 10 to 9 Hz) HB traced 5 points in 23 s where
    shooting failed at the first in 100 s (at 16 Hz both fail: HB in 52 s, shooting in
    8 s).  ``hb`` where it cannot run is refused (bad input); a scene without the
    controller's integral action by every method, with the way out."""
    if method not in METHODS:
        raise SceneError("--method", method, f"must be one of {METHODS}")
    if params.normalised().steady_torque().k1 == 0.0:  # neither method: the way out
        raise SceneError("--method", method, FREE_ROTATION)
    why = wrong_tool(params)
    if method == "hb" and cannot(params):
        raise SceneError("--method", method, f"harmonic balance is the wrong tool here: "
                         f"{cannot(params)}")
    if method == "auto":
        if cannot(params):
            return "shooting", f"auto: shooting, as {cannot(params)}"
        if why:
            return "hb", f"auto: harmonic balance, which runs here; warning: {why}"
        return "hb", "auto: harmonic balance, as every law of the scene is smooth"
    if method == "hb" and why:
        return method, f"as asked; warning: {why}"
    return method, "as asked"


def problem(params: Parameters, method: str):
    """The periodic-orbit problem of ``method`` (one of :func:`choose`'s answers)
    on this rank."""
    if method == "hb":
        from rawehelix.solvers.harmonic_balance import HarmonicBalance
        return HarmonicBalance(params)
    from rawehelix.studies import schemes
    return schemes.of(params).period_map(params)
