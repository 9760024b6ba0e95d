"""`rawehelix section`: EA, EI and GJ of a scene's helix from its section's members,
what they come from, and the paper's lab tests' values as the alternative
(docs/explanation/section.md, "EA, EI, GJ of your own helix").

The members (parameters/section.py: n tethers of axial stiffness k at the radius R,
laid at beta, the self-stress P0 and bars EA_b) give the closed forms of
:meth:`~rawehelix.members.Members.taut_moduli` at zero strain, which
``helix.stiffness = "from_section"`` puts in the rod, and their tangent moduli
(:meth:`~rawehelix.members.Members.tangent`) under the chord's tension, where the
tethers' tension T_t adds to GJ T_t R^2 without a lay (the torsional stiffness of a
TRPT), less with one.  The lab
tests measured the paper's helix (R = 0.19 m, Sec. 4): EA by Eq. (62), EI by the law
Eq. (64) and GJ = 140 N m^2 at 200 N by Eq. (65).  No solve: the numbers are closed forms.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from rawehelix.parameters import Parameters
from rawehelix.studies.analysis import labfit

#: the closed forms of members.py, as printed
from rawehelix.studies import labtest
from rawehelix.studies.store import writers
FORMULAS = {"EA_N": "n (k cos^3 beta + P0 cos beta sin^2 beta) + EA_b",
            "EI_Nm2": "n (k cos^3 beta + P0 cos beta sin^2 beta) R^2 / 2",
            "GJ_Nm2": "n cos beta R^2 (k sin^2 beta + P0 cos^2 beta)"}


@dataclass
class SectionResult:
    """The section's moduli (``summary``: what summary.json holds)."""

    params: Parameters
    summary: dict

    def write(self, outdir, rank: int = 0) -> Path:
        """summary.json into ``outdir`` (rank 0)."""
        return writers.summary_and_figure(outdir, rank, self.summary, lambda d: None)


def _moduli(d: dict) -> dict:
    return {"EA_N": d["EA"], "EI_Nm2": d["EI"], "GJ_Nm2": d["GJ"]}


def _finite(x: float) -> float | None:
    """x, or None where it is infinite (no critical twist: tethers shorter than 2 R)."""
    return x if math.isfinite(x) else None


def chord_tension(params: Parameters) -> tuple[float, str]:
    """(T [N], its source): the scene's tension where it gives one (ends.tension_N),
    else the straight chord's T = EA eps0 (ends.elongation, Eq. 66)."""
    given = getattr(params.ends, "tension_N", None)
    if given is not None:
        return float(given), "ends.tension_N"
    return params.helix.EA_N * params.ends.elongation, "helix.EA_N x ends.elongation"


def compute(params: Parameters) -> SectionResult:
    """The moduli of ``params``'s section (see the module doc)."""
    section, helix = params.model.section, params.helix
    m = section.members(helix, width=0.0)
    T, source = chord_tension(params)
    eps = T / m.taut_moduli()["EA"]
    lab_EI = float(labtest.eq64(T))
    GJ_lab, T_GJ = labfit.GJ_TARGET
    spacing = section.spacing(helix)
    summary = {
        "scene": params.name, "stiffness": helix.stiffness,
        "members": {
            "tethers": m.n, "radius_m": m.R,
            "radius_from": "section.radius_m" if section.radius_m else "helix.radius_m",
            "lay_angle_deg": section.lay_angle_deg, "tether_EA_N": m.k,
            "tether_EA_from": ("section.tether_EA_N" if section.tether_EA_N is not None
                               else "derived: the k whose taut EA is helix.EA_N"),
            "self_stress_N": m.P0, "bar_EA_N": m.EA_b, "rings": section.rings,
            "ring_spacing_m": spacing,
            "ring_spacing_from": ("section.rings: L0 / (rings - 1)" if section.rings
                                  else "section.ring_spacing_m" if spacing else None),
            "critical_twist_rad": _finite(m.critical_twist()) if spacing else None},
        "taut_moduli": _moduli(m.taut_moduli()),
        "taut_moduli_meaning": "members.py's closed forms at zero strain, every tether "
                               "taut: what helix.stiffness = 'from_section' puts in the rod",
        "formulas": FORMULAS,
        "at_tension": {"tension_N": T, "tension_from": source,
                       "tethers_tension_N": T * (1 - m.EA_b / m.taut_moduli()["EA"]),
                       **_moduli(m.tangent(eps)),
                       "meaning": "the members' tangent moduli at the stretch of that "
                                  "tension: the tethers' share T_t of it (the bars carry "
                                  "the rest) adds T_t R^2 to GJ without a lay, less with one"},
        "helix": {"EA_N": helix.EA_N, "EI_Nm2": helix.EI_Nm2, "GJ_Nm2": helix.GJ_Nm2,
                  "from": ("helix.stiffness = 'from_section': the section's members"
                           if helix.stiffness == "from_section"
                           else "helix.stiffness = 'given': the scene's values")},
        "lab_tests": {
            "helix": "the paper's helix (Sec. 4, Table 2: R = 0.19 m)",
            "EA_N": labtest.LAB_EA_N, "EA_from": "Eq. (62), the axial test (Fig. 3)",
            "EI_law": {"a_Nm2_per_N": labtest.EQ64[0], "b_Nm2": labtest.EQ64[1]},
            "EI_from": "Eq. (64), the bending test (Fig. 4): EI = a T + b",
            "EI_at_tension_Nm2": lab_EI,
            "GJ_Nm2": GJ_lab, "GJ_at_tension_N": T_GJ,
            "GJ_from": "Eq. (65), the torsion test (Fig. 5; hysteretic, Table 2's 140)"},
    }
    return SectionResult(params, summary)


def report(result: SectionResult) -> str:
    """The lines a designer reads: the members, their moduli, the alternative."""
    s = result.summary
    m, taut, at, h, lab = (s[k] for k in ("members", "taut_moduli", "at_tension", "helix",
                                          "lab_tests"))
    lines = [f"section of {s['scene']}: {m['tethers']} tethers of EA {m['tether_EA_N']:.6g} N "
             f"({m['tether_EA_from']}) at R = {m['radius_m']:g} m ({m['radius_from']}), lay "
             f"{m['lay_angle_deg']:g} deg, self-stress {m['self_stress_N']:g} N, bars "
             f"{m['bar_EA_N']:g} N"]
    if m["ring_spacing_m"]:
        rings = f"{m['rings']} rings, " if m["rings"] else ""
        twist = m["critical_twist_rad"]
        lines.append(f"  {rings}spacing {m['ring_spacing_m']:.6g} m ({m['ring_spacing_from']}): "
                     + (f"critical twist {twist:.4g} rad between rings" if twist is not None
                        else "no critical twist (tethers shorter than 2 R)"))
    else:
        lines.append("  rings: not given (section.rings or section.ring_spacing_m switches on "
                     "the torsional collapse check)")
    lines.append("  the members' taut moduli at zero strain (members.py):")
    for key, unit in (("EA_N", "N"), ("EI_Nm2", "N m^2"), ("GJ_Nm2", "N m^2")):
        lines.append(f"    {key[:2]} = {FORMULAS[key]:52s} = {taut[key]:.6g} {unit}")
    lines.append(f"  under the tension T = {at['tension_N']:.6g} N ({at['tension_from']}):"
                 f" EA = {at['EA_N']:.6g} N, EI = {at['EI_Nm2']:.6g} N m^2, GJ = "
                 f"{at['GJ_Nm2']:.6g} N m^2 (their tension T_t = {at['tethers_tension_N']:.4g} N adds "
                 f"{at['GJ_Nm2'] - taut['GJ_Nm2']:.4g} to GJ; T_t R^2 = "
                 f"{at['tethers_tension_N'] * m['radius_m'] ** 2:.4g} without a lay"
                 + (")" if m["lay_angle_deg"] == 0 else
                    f", less at the lay of {m['lay_angle_deg']:g} deg)"))
    lines.append(f"  the scene's helix: EA_N = {h['EA_N']:.6g}, EI_Nm2 = {h['EI_Nm2']:.6g}, "
                 f"GJ_Nm2 = {h['GJ_Nm2']:.6g} ({h['from']})")
    a, b = lab["EI_law"]["a_Nm2_per_N"], lab["EI_law"]["b_Nm2"]
    lines.append(f"  or the lab tests of {lab['helix']}: EA = {lab['EA_N']:.4g} N (Eq. 62), "
                 f"EI = {a:g} T + {b:g} N m^2 (Eq. 64; {lab['EI_at_tension_Nm2']:.6g} at T), "
                 f"GJ = {lab['GJ_Nm2']:g} N m^2 at {lab['GJ_at_tension_N']:g} N (Eq. 65)")
    lines.append(f"    as scene keys: helix.EA_N = {lab['EA_N']:g}, helix.EI_Nm2 = "
                 f"{lab['EI_at_tension_Nm2']:.6g} (or helix.EI_law = {{a_Nm2_per_N = {a:g}, "
                 f"b_Nm2 = {b:g}}}), helix.GJ_Nm2 = {lab['GJ_Nm2']:g}")
    return "\n".join(lines)
