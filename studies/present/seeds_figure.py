"""The figure of a seed study (issue 44, studies/seeds.py): each quantity's mean (with
+- one standard deviation) and maximum over the seeds against the wind speed, the
operating-points curve of the same scene beside the ones it has: plots take data."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from rawehelix.studies.store import writers

__all__ = ["seeds_png"]


def seeds_png(path: Path, rows: list[dict], wanted, x_key: str, curve: dict | None,
              curve_fields: dict, title: str) -> Path:
    """One panel a quantity: mean +- std (error bars) and max (triangles) over the
    seeds at each ``x_key`` value of ``rows`` (studies/seeds.statistics); the operating
    curve's ``curve_fields[name]`` against its ``wind_m_s`` where it has one."""
    plt = writers._pyplot()
    n = len(wanted)
    cols = min(n, 3)
    nrows = (n + cols - 1) // cols
    fig, axes = plt.subplots(nrows, cols, figsize=(4.2 * cols, 3.2 * nrows), squeeze=False)
    x = np.array([float(r["keys"][x_key]) for r in rows])
    order = np.argsort(x, kind="stable")
    for ax, name in zip(axes.flat, wanted):
        stats = [rows[i]["quantities"][name] for i in order]
        mean = np.array([np.nan if s["mean"] is None else s["mean"] for s in stats])
        std = np.array([0.0 if s["std"] is None else s["std"] for s in stats])
        top = np.array([np.nan if s["max"] is None else s["max"] for s in stats])
        ax.errorbar(x[order], mean, yerr=std, fmt="o", ms=4, capsize=3, label="mean +- std")
        ax.plot(x[order], top, "^", ms=5, color="C3", label="max over seeds")
        field = curve_fields.get(name)
        if curve and field and field in curve:
            cx = np.array(curve["wind_m_s"], float)
            cy = np.array([np.nan if v is None else v for v in curve[field]], float)
            ax.plot(cx, cy, "k-", lw=1.0, label=f"operating point ({field})")
        ax.set_xlabel(x_key)
        ax.set_ylabel(name)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    for ax in list(axes.flat)[n:]:
        ax.axis("off")
    return writers._finish(fig, path, title)
