"""The README's design maps (issue 31): the Sec. 5.3 helix (mobile_end, N = 4, the
extensible rod) in (f1, the end's elongation: the nominal tension) and (f1, EI), with the
solid and the tensegrity section, by harmonic balance.  Writes docs/envelope/<map>/
(summary.json, envelope.png) and docs/envelope/design_maps.png.  Usage:
    python scripts/design_maps.py [solid|tensegrity|figure]"""

import json
import sys
from pathlib import Path

import rawehelix as rh
from rawehelix.studies import envelope
from rawehelix.studies.envelope_figure import panels_png

OUT = Path(__file__).resolve().parents[1] / "docs" / "envelope"
SECTIONS = {"solid": {"model.kinematics": "extensible"},
            "tensegrity": {"model.kinematics": "extensible", "section.law": "tensegrity"}}
#: (the key's range, f1 window [Hz], the base scene's other keys): from 2 Hz, below the
#: first slack member (3-3.5 Hz at the scene's elongation), past the primary resonance
MAPS = {"elongation": ("ends.elongation=0.002:0.005:4", 2.0, 16.0, {}),
        "EI": ("helix.EI_Nm2=2500:6500:4", 2.0, 16.0, {})}


def run(section: str):
    for name, (vary, lo, hi, base) in MAPS.items():
        params = rh.load_scene("mobile_end", elements=4, degree=3,
                               overrides={**SECTIONS[section], **base})
        result = rh.envelope(params, vary, lo, hi, method="hb")
        result.write(OUT / f"{section}_{name}")
        print(envelope.report(result), flush=True)


def figure():
    names = [(s, m) for m in MAPS for s in SECTIONS]
    summaries = [json.loads((OUT / f"{s}_{m}" / "summary.json").read_text()) for s, m in names]
    panels_png(OUT / "design_maps.png", summaries, [f"{s} section" for s, _ in names],
               "Sec. 5.3 helix, N = 4: where one stable response stays within the limits")


if __name__ == "__main__":
    what = sys.argv[1] if len(sys.argv) > 1 else "figure"
    run(what) if what in SECTIONS else figure()
