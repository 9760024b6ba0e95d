"""Where harmonic balance can run, where it is the wrong tool, and the size of its
unknown: decisions from the scene's parameters alone, which the orbit-method registry
(studies/orbit_method.py) asks without loading the FE rod
(docs/explanation/harmonic_balance.md, "Where HB is the wrong tool"); it loads
neither scipy nor MPI, so that ``import rawehelix`` stays light (tests/test_api.py)."""

from __future__ import annotations

from rawehelix.parameters import Parameters, schemes

H_START, H_MAX = 3, 40  # harmonics: the first tried, the most allowed


def cannot(params: Parameters) -> str | None:
    """Why harmonic balance cannot trace ``params``'s orbits (None: it can): a scheme
    without the FE rod, a free rotation, or an internal variable that breaks its unknowns."""
    refusal = schemes.of(params).harmonic_balance_refusal
    if refusal:
        return refusal
    if params.normalised().steady_torque().k1 == 0.0:
        from rawehelix.periodic_orbits.problem import FREE_ROTATION  # (scipy: late)
        return FREE_ROTATION
    if params.model.torsion_hysteresis.active:
        return ("the hysteretic torsion's internal twist is non-smooth and hardly moves over "
                "a period (its multipliers are 1 - O(beta x twist travel): shooting carries "
                "it): use --method shooting (or auto)")
    return None


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


def state_size(params: Parameters) -> int:
    """The entries of an orbit's unknown X at the first H tried (studies/resources.py):
    2 H + 1 coefficients per unknown; where it cannot run, its period map's state."""
    scheme = schemes.of(params)
    if scheme.harmonic_balance_refusal:
        return scheme.period_state_size(params)
    return (2 * H_START + 1) * scheme.unknowns(params)
