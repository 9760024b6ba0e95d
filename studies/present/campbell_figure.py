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
    points = summary["points"]
    rpm = np.array([p["rotor_rpm"] for p in points]) if points else np.zeros(1)
    top_rpm = float(rpm.max()) * 1.05 if rpm.max() > 0 else 1.0
    labelled = set()
    tracks = {}
    for p in points:
        for m in p["modes"]:
            tracks.setdefault((p["branch"], m["family"], m["index"]), []).append(
                (p["rotor_rpm"], m["frequency_Hz"], p["stable"]))
    f_max = 0.0
    for (branch, family, index), track in tracks.items():
        track.sort()
        x, f, stable = (np.array(v) for v in zip(*track))
        f_max = max(f_max, float(f.max()))
        label = FAMILY_LABELS.get(family, family) if family not in labelled else None
        labelled.add(family)
        colour = COLOURS.get(family, "k")
        ax.plot(x, f, "-", color=colour, marker="o", ms=3, label=label)
        unstable = ~stable.astype(bool)
        if unstable.any():
            ax.plot(x[unstable], f[unstable], "x", color=colour, ms=7)
    for name in summary.get("lines", []):
        n = int(name[:-1])
        ax.plot([0.0, top_rpm], [0.0, n * top_rpm * LINE_RPM_HZ], "k--", lw=0.8)
        ax.annotate(name, (top_rpm, n * top_rpm * LINE_RPM_HZ), fontsize=8, ha="right")
    for k, c in enumerate(summary.get("crossings", [])):
        ax.plot(c["rotor_rpm"], c["frequency_Hz"], "s", mfc="none", mec="k", ms=9,
                label="crossing" if k == 0 else None)
    for k, (lo, hi) in enumerate(summary.get("slack_bands_Hz", [])):
        ax.axhspan(lo, hi, color="tab:purple", alpha=0.15,
                   label="forced helix slackens (Sec. 5.3)" if k == 0 else None)
    ax.set_xlim(0.0, top_rpm)
    ax.set_ylim(0.0, 1.1 * max(f_max, 1e-9))
    ax.set_xlabel("rotor speed [rpm]")
    ax.set_ylabel("frequency [Hz]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
