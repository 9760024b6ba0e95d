"""The tensegrity members' fit of the lab tests (issue 29) after labfit.section_fit: the
fitted members run through the FE section law (forms/section_law.py) in the simulated
tests (:func:`rod_check`), and the fit's lines in the test's report (:func:`report`).

The simulated tests are studies/labtest.py's, given as callables (this module sits
below it): the axial layout's Eq. (62) (law "tensegrity"); each dead-load torsion fit's
Eq. (65) at 200 N (the members carry the twist, ``torsion = "members"``; the lab's
ballast is a dead load, so the held fit has no rod test); the fallback cone's Eq. (64)
at the bending tensions (law "saturating", the cone's EI per tension).  Each reading
with its relative error against the lab's value.
"""

from __future__ import annotations

import numpy as np

from rawehelix.studies.analysis import labfit


def _members(layout: dict, **keys) -> dict:
    """A scene's ``[section]`` of a fitted layout (labfit._layout: its keys are the
    section's)."""
    return {"law": "tensegrity", **layout, **keys}


def rod_check(block: dict, solver, tests: dict, L0: float) -> dict:
    """The readings of the fitted members in the rod (module doc).  ``solver(section,
    **helix)``: a lab-segment solver with that ``[section]`` (and helix keys);
    ``tests``: "axial" (solver), "torsion" (solver, T_e, torques), "bending" (solver,
    T_e), labtest.py's tests; ``L0`` the segment's length [m]."""
    EA = block["EA_target_N"]
    ax = tests["axial"](solver(_members(block["layout"])))
    out = {"axial": {"apparent_EA_N": ax["apparent_EA_N"],
                     "relative_error": ax["apparent_EA_N"] / EA - 1}}
    GJ, T = labfit.GJ_TARGET
    for key in ("lay_angle_fit_dead_load", "self_stress_fit_dead_load"):
        fit = block.get(key)
        if fit is None:
            continue
        # the reference's own torque holds a laid ring's lay (labfit.section_torsion)
        Q_ref = fit["reference_torque_Nm"]
        rows = tests["torsion"](solver(_members(fit["layout"], torsion="members")), T,
                                [Q_ref + M for M in (0.0, *fit["torque_Nm"])])
        angle = np.asarray(rows["angle_rad"])
        apparent = labfit.slope((angle[1:] - angle[0]) / L0, fit["torque_Nm"])
        out[key] = {"apparent_GJ_Nm2": apparent, "relative_error": apparent / GJ - 1}
    if "cone" in block:
        cone, rows = block["cone"], []
        for r in cone["rows"]:
            S = solver({"law": "saturating", "radius_m": cone["R_m"]}, EI_Nm2=r["EI_Nm2"])
            rows.append(tests["bending"](S, r["tension_N"])["apparent_EI_Nm2"])
        error = [a / r["eq64_EI_Nm2"] - 1 for a, r in zip(rows, cone["rows"])]
        out["cone"] = {"apparent_EI_Nm2": rows, "relative_error": error,
                       "within_1_percent": bool(np.all(np.abs(error) <= labfit.FIT_TARGET))}
    return out


def report(b: dict) -> list:
    """The members' fit (labfit.section_fit) in a few lines, its level first."""
    lay = b["layout"]
    lines = [f"members' fit at the {b['level']}",
             f"  Eq. (62): {lay['tethers']} tethers at R = {lay['radius_m']:g} m, lay "
             f"{lay['lay_angle_deg']:g} deg: k = {b['axial']['tether_EA_N']:.5g} N per tether "
             f"reads EA = {b['axial']['apparent_EA_N']:.5g} N ({100 * b['axial']['relative_error']:+.3f} %)"]
    for key in ("lay_angle_fit_held", "lay_angle_fit_dead_load", "self_stress_fit_dead_load"):
        if key not in b:
            continue
        f = b[key]
        if f is None:
            lines.append(f"  GJ = 140 N m^2 at 200 N, {key}: no solution in range")
            continue
        m, rise = f["layout"], f["tension_change_at_fixed_length_N"]
        lines.append(f"  GJ = 140 N m^2 at 200 N, {key}: lay {m['lay_angle_deg']:.3f} deg, P0 "
                     f"{m['self_stress_N']:.4g} N, k {m['tether_EA_N']:.5g} N, bars {m['bar_EA_N']:.4g} N: "
                     f"GJ dead load "
                     f"{f['apparent_GJ_dead_load_Nm2']:.4g}, held {f['apparent_GJ_held_Nm2']:.4g} "
                     f"N m^2; T change at fixed length +50 deg {rise['+50deg']:+.1f} N, -50 deg "
                     f"{rise['-50deg']:+.1f} N")
    if "bending" in b:
        for T, EI, app, e64, R in zip(*(b["bending"][k] for k in (
                "tension_N", "members_EI_Nm2", "apparent_EI_Nm2", "eq64_EI_Nm2", "radius_needed_m"))):
            lines.append(f"  Eq. (64) at {T:g} N: members' EI {EI:.0f} reads {app:.0f} N m^2 against "
                         f"{e64:.0f} ({100 * (app / e64 - 1):+.1f} %); needs R = {R:.3f} m")
        c = b["cone"]
        lines.append(f"  fallback (saturating, c = {c['c']:.3f}): reproduces Eq. (64) within "
                     f"{100 * max(abs(e) for e in c['relative_error']):.2g} %, convex "
                     f"{c['convex']}; moment saturates at F_N = " + ", ".join(
                         f"{r['saturation_load_N']:.2f}" for r in c["rows"]) + " N")
        lines.append(f"  verdict: {b['verdict']}")
    rod = b.get("rod")
    if rod:
        pct = lambda e: f"{100 * e:+.2f} %"  # noqa: E731
        text = [f"Eq. (62) EA {rod['axial']['apparent_EA_N']:.5g} N ({pct(rod['axial']['relative_error'])})"]
        text += [f"{key}: GJ {rod[key]['apparent_GJ_Nm2']:.4g} N m^2 ({pct(rod[key]['relative_error'])})"
                 for key in ("lay_angle_fit_dead_load", "self_stress_fit_dead_load") if key in rod]
        if "cone" in rod:
            text.append("cone Eq. (64) " + ", ".join(pct(e) for e in rod["cone"]["relative_error"]))
        lines.append(f"  in the rod (FE section law, gravity {'on' if rod['gravity'] else 'off'}): "
                     + "; ".join(text))
    return lines
