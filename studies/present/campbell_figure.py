"""The Campbell diagram's figure: each mode's frequency against the rotor speed along its
branch (a colour per family, dashed past an unstable point), the 1P, 2P and BP lines,
the crossings marked, and, when an ``envelope`` result was given, the band of forcing
frequencies where the forced helix of Sec. 5.3 slackens shaded.  Plots take data (the
summary)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from rawehelix.families import FAMILY_LABELS
from rawehelix.studies.store import writers

COLOURS = {"longitudinal": "tab:blue", "lateral_in_plane": "tab:green",
           "lateral_out_of_plane": "tab:olive", "torsional": "tab:red"}
LINE_RPM_HZ = 1.0 / 60.0  # Hz per rpm


def campbell_png(path: Path, summary: dict, title: str) -> Path:
    plt = writers._pyplot()
    fig, ax = plt.subplots(figsize=(8, 5.5))
    draw(ax, summary)
    return writers._finish(fig, path, title)


def draw(ax, summary: dict):
    """Each track of summary["tracks"] ([rotor_rpm, frequency_Hz, wind_m_s, index,
    damping_ratio] along a branch), crosses on its growing points (damping ratio < 0),
    a triangle at 0 Hz for an unstable point whose growth is a real root, the lines,
    crossings and slack bands."""
    points = summary["points"]
    top_rpm = 1.05 * max([p["rotor_rpm"] for p in points] + [1e-9])
    labelled = set()
    growing_rpm = set()
    for track in summary.get("tracks", []):
        family = track["family"]
        x = np.array([t[0] for t in track["points"]])
        f = np.array([t[1] for t in track["points"]])
        zeta = np.array([t[4] for t in track["points"]])
        colour = COLOURS.get(family, "k")
        ax.plot(x, f, "-", color=colour, marker="o", ms=3,
                label=None if family in labelled else FAMILY_LABELS.get(family, family))
        labelled.add(family)
        bad = zeta < 0
        if bad.any():
            ax.plot(x[bad], f[bad], "x", color=colour, ms=9, mew=2,
                    label=None if "growing" in labelled else "growing mode")
            labelled.add("growing")
            growing_rpm.update((track["branch"], r) for r in x[bad])
    real = [p["rotor_rpm"] for p in points
            if not p["stable"] and (p["branch"], p["rotor_rpm"]) not in growing_rpm]
    if real:
        ax.plot(real, [0.0] * len(real), "^", color="k", ms=8, clip_on=False,
                label="unstable: a growing real root")
    orders = [int(name[:-1]) for name in summary.get("lines", [])]
    for n in orders:
        ax.plot([0.0, top_rpm], [0.0, n * top_rpm * LINE_RPM_HZ], "k--", lw=0.8)
        ax.annotate(f"{n}P", (top_rpm, n * top_rpm * LINE_RPM_HZ), fontsize=8, ha="right",
                    va="bottom")
    crossings = summary.get("crossings", [])
    for k, c in enumerate(crossings):
        ax.plot(c["rotor_rpm"], c["frequency_Hz"], "s", mfc="none", mec="k", ms=9,
                label="crossing" if k == 0 else None)
    bands = summary.get("slack_bands_Hz", [])
    for k, (lo, hi) in enumerate(bands):
        ax.axhspan(lo, hi, color="tab:purple", alpha=0.15,
                   label="forced helix slackens (Sec. 5.3)" if k == 0 else None)
    # the lines' region: modes far above the highest line cannot cross it
    f_top = 1.5 * max(orders + [1]) * top_rpm * LINE_RPM_HZ
    f_top = max([f_top] + [c["frequency_Hz"] * 1.1 for c in crossings]
                + [hi * 1.1 for _, hi in bands])
    ax.set_xlim(0.0, top_rpm)
    ax.set_ylim(0.0, f_top)
    ax.set_xlabel("rotor speed [rpm]")
    ax.set_ylabel("frequency [Hz]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
