"""The power curve of `rawehelix operate`: P(V) on top, the rotor's speed, the helix's
tension (max and min along s) and the smallest tether force below it on a shared wind
axis; each branch drawn, its unstable stretches dashed, its folds marked, the first limit's
wind speed marked and named.  Plots take data (the summary)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from rawehelix.studies.store import writers


#: the markers of a row's one value, or of its max and min
MARKERS = {1: ("o",), 2: ("^", "v")}


def _runs(points: list, details: list):
    """Each branch's points (wind ascending) cut into runs of one stability:
    (branch, stable, points, details)."""
    out = []
    for b in sorted({p["branch"] for p in points}):
        pairs = sorted(((p, d) for p, d in zip(points, details) if p["branch"] == b),
                       key=lambda pd: pd[0]["wind_m_s"])
        run = [pairs[0]]
        for pd in pairs[1:]:
            if pd[0]["stable"] != run[-1][0]["stable"]:
                out.append((b, run[-1][0]["stable"], run))
                run = [run[-1]]  # the runs join at the change
            run.append(pd)
        out.append((b, run[-1][0]["stable"], run))
    return out


def power_curve_png(path: Path, summary: dict, title: str) -> Path:
    """The figure of the module docstring from ``summary`` (studies/operate.py)."""
    plt = writers._pyplot()
    rows = [("power [W]", lambda p, d: [p["power_W"]]),
            ("rotor speed [rpm]", lambda p, d: [p["rotor_rpm"]]),
            ("tension max (^), min (v) [N]", lambda p, d: [p["tension_max_N"], p["tension_min_N"]]),
            ("smallest tether force [N]", lambda p, d: [d["member_force_min_N"]])]
    fig, axes = plt.subplots(len(rows), 1, figsize=(7.5, 9.5), sharex=True)
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    branches = len({p["branch"] for p in summary["points"]})
    labelled = set()
    for b, stable, run in _runs(summary["points"], summary["details"]):
        V = [p["wind_m_s"] for p, _ in run]
        name = f"branch {b}" if branches > 1 and b not in labelled else None
        labelled.add(b)
        for ax, (_, values) in zip(axes, rows):
            y = np.array([[np.nan if v is None else v for v in values(p, d)] for p, d in run])
            for k in range(y.shape[1]):  # max and min: their own markers
                ax.plot(V, y[:, k], "-" if stable else "--", marker=MARKERS[y.shape[1]][k],
                        ms=4, color=colours[b % len(colours)],
                        label=name if ax is axes[0] and k == 0 else None)
    for ax, (label, _) in zip(axes, rows):
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    axes[-1].axhline(0.0, color="0.5", lw=0.8)
    axes[-1].set_xlabel("wind speed V [m/s]")
    winds = [p["wind_m_s"] for p in summary["points"]]
    for k, fold in enumerate(f for f in summary.get("folds", [])
                             if min(winds) <= f["wind_m_s"] <= max(winds)):
        for ax in axes:  # where a branch turns back in the wind
            ax.axvline(fold["wind_m_s"], color="0.6", ls="-.", lw=0.8,
                       label="fold" if ax is axes[0] and k == 0 else None)
    first = summary.get("first_limit")
    if first:
        for ax in axes:
            ax.axvline(first["wind_m_s"], color="tab:red", ls=":", lw=1.2)
        axes[0].annotate(f"first limit: {first['kind']}\nat {first['wind_m_s']:g} m/s",
                         (first["wind_m_s"], 0.95), xycoords=("data", "axes fraction"),
                         ha="right", va="top", color="tab:red", fontsize=9)
    if any(not p["stable"] for p in summary["points"]):
        axes[0].plot([], [], "k--", label="unstable (dashed)")
    if axes[0].get_legend_handles_labels()[0]:
        axes[0].legend(loc="upper left", fontsize=8)
    return writers._finish(fig, path, title)
