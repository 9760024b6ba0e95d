"""Why a sweep point is not periodic and what to try (issue 41): read from what its
periodicity test measured (solvers/periodic.py, ``unsettled``: the change of the
tension's extremes a period, its decay, and the state's parts by how much they
still move), printed under the point and kept in its summary.json entry
(``not_periodic``, with ``advice``)."""

from __future__ import annotations

import math

from rawehelix.parameters import Parameters

#: the shipped forced scenes' controller gain (mobile_end, nominal_operation)
K1 = 0.5
#: a retardation time that damps the torsional and bending modes of the shipped
#: scenes by a few percent (damping ratio pi f tau: 5 % at 17 Hz)
TAU_S = 1.0e-3


def too_few_periods(sweep) -> str | None:
    """The warning before a sweep whose ``max_periods`` is below what the periodicity
    test needs (the tester's D8b), or None."""
    if sweep.max_periods >= sweep.periods_to_judge:
        return None
    return (f"sweep.max_periods = {sweep.max_periods} is below the {sweep.periods_to_judge} "
            f"periods the periodicity test needs (3 x sweep.record_periods + 1): a point that "
            f"is not stationary will be flagged NOT PERIODIC; raise it with --set "
            f"sweep.max_periods={sweep.periods_to_judge}")


def reason(why: dict) -> str:
    """One line: what the test measured, and which parts move the most."""
    if "change_N" not in why:
        return why["reason"]
    text = (f"T max and T min at s = 0 still change by {why['change_N']:.3g} N a period "
            f"after {why['periods']} periods, ")
    if why["remainder_N"] is None:
        text += (f"and the changes do not decay (allowed: {why['allowed_N']:.3g} N, "
                 f"{why['tolerance']:g} of T max - T min): an undamped oscillation")
    else:
        text += (f"decaying by {why['decay_per_period']:.4f} a period: what remains, "
                 f"{why['remainder_N']:.3g} N, is above the {why['allowed_N']:.3g} N allowed "
                 f"({why['tolerance']:g} of T max - T min)")
    moving = why.get("moving")
    if moving:
        text += "; moving most: " + ", ".join(
            f"{m['part']} ({m['change_per_period']:.1e} of its size a period)"
            for m in moving[:2])
    return text


def advice(params: Parameters, why: dict, f1_Hz: float) -> list[str]:
    """What to try, most likely first, each as the command-line way to do it."""
    moving = why.get("moving") or []
    twist_first = bool(moving) and "twist" in moving[0]["part"]
    out = []
    if params.controller.k1 == 0.0:
        out.append(f"a controller, whose integral action holds the spin (free without it): "
                   f"add '[controller]' with 'k1 = {K1:g}' to the scene, or "
                   f"--set controller.k1={K1:g}")
    if why.get("reason") == "not decaying":
        key = "torsion_s" if twist_first or not moving else "bending_s"
        out.append(f"damping: add '[damping]' with '{key} = {TAU_S:g}' to the scene, or "
                   f"--set damping.{key}={TAU_S:g} (a change of the model)")
    more = why.get("periods_to_settle")
    if "periods_to_judge" in why:
        out.append(f"more periods, at least the test's {why['periods_to_judge']}: "
                   f"--set sweep.max_periods={max(why['periods_to_judge'], 100)}")
    elif more:
        total = params.sweep.max_periods + more
        total = int(math.ceil(total / 100.0) * 100)
        out.append(f"more periods (about {more} more at this decay): "
                   f"--set sweep.max_periods={total}")
    out.append(f"the periodic orbit by Newton, without waiting for the transient: "
               f"rawehelix orbits {params.name} --f1 {f1_Hz:g}:{f1_Hz * 0.95:.4g}"
               + (f" --set controller.k1={K1:g}" if params.controller.k1 == 0.0 else ""))
    return out


def lines(params: Parameters, why: dict, f1_Hz: float) -> list[str]:
    """The lines printed under a point that is not periodic."""
    return ([f"      why: {reason(why)}"] +
            [f"      try: {a}" for a in advice(params, why, f1_Hz)])
