"""The README's design maps (issue 31): the Sec. 5.3 helix (mobile_end, N = 4, the
extensible rod) in (f1, the end's elongation: the nominal tension) and (f1, EI), with the
solid and the tensegrity section, by harmonic balance.  Writes docs/envelope/<map>/
(summary.json, envelope.png) and docs/envelope/design_maps.png.  Usage:
    python scripts/design_maps.py [solid|tensegrity [elongation|EI]|figure]"""

import json
import sys
from pathlib import Path

import rawehelix as rh
from rawehelix.studies import envelope
from rawehelix.studies.present.envelope_figure import envelope_png, panels_png

OUT = Path(__file__).resolve().parents[1] / "docs" / "envelope"
SECTIONS = {"solid": {"model.kinematics": "extensible"},
            "tensegrity": {"model.kinematics": "extensible", "section.law": "tensegrity"}}
#: (the key's range, f1 window [Hz], the base scene's other keys): from 2 Hz, below the
#: first slack member (3-3.5 Hz at the scene's elongation), past the primary resonance
MAPS = {"elongation": ("ends.elongation=0.002:0.005:4", 2.0, 16.0, {}),
        "EI": ("helix.EI_Nm2=2500:6500:4", 2.0, 16.0, {})}


#: the tensegrity: its members with a self-stress of 30 N (bars of EA 1e4 N), so that
#: they are taut at rest; without it (the scene's P0 = 0) they are slack at rest and
#: neither HB (first orbit at 16 Hz not found in 30 min, H raised to 40) nor shooting
#: (no period-1 orbit found at 13, 9 or 8 Hz) starts.  HB raises H where they slack.
#: With the members' law EI is the tethers' (n k R^2 cos^3(beta) / 2, 477 N m^2 at the
#: default k = 4400 N), and helix.EI_Nm2 sets only the sections' rotational inertia: the
#: (f1, EI) map of the tensegrity varies the members' stiffness k instead.
_PRESTRESSED = {"section.self_stress_N": 30.0, "section.bar_EA_N": 1e4}
TENSEGRITY = {"elongation": ("ends.elongation=0.002:0.005:3", 2.0, 12.0, _PRESTRESSED),
              "EI": ("section.tether_EA_N=3000:9000:3", 2.0, 12.0, _PRESTRESSED)}


#: the most a branch steps in f1 [Hz]: 0.1 for the solid (a narrow unstable band between
#: two points is then found); none for the tensegrity, whose slack kinks hold HB's
#: branch poorly at small steps (at elongation 0.002 it turned back at a kink near 7.09 Hz)
F1_STEP = {"solid": 0.1, "tensegrity": None}


def run(section: str, only: str | None = None):
    maps = TENSEGRITY if section == "tensegrity" else MAPS
    for name, (vary, lo, hi, base) in maps.items():
        if only and name != only:
            continue
        params = rh.load_scene("mobile_end", elements=4, degree=3,
                               overrides={**SECTIONS[section], **base})
        result = rh.envelope(params, vary, lo, hi, method="hb", f1_step_Hz=F1_STEP[section])
        result.write(OUT / f"{section}_{name}")
        print(envelope.report(result), flush=True)


def figure():
    names = [(s, m) for m in MAPS for s in SECTIONS if (OUT / f"{s}_{m}").exists()]
    summaries = [json.loads((OUT / f"{s}_{m}" / "summary.json").read_text()) for s, m in names]
    titles = {"solid": "solid section", "tensegrity": "tensegrity section (self-stress 30 N)"}
    for (s, m), summary in zip(names, summaries):  # each map's own figure, drawn again
        envelope_png(OUT / f"{s}_{m}" / "envelope.png", summary, f"{titles[s]}, N = 4")
    panels_png(OUT / "design_maps.png", summaries, [titles[s] for s, _ in names],
               "Sec. 5.3 helix, N = 4: where one stable response stays within the limits")


if __name__ == "__main__":
    what = sys.argv[1] if len(sys.argv) > 1 else "figure"
    run(what, *sys.argv[2:3]) if what in SECTIONS else figure()
