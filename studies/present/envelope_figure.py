"""The envelope's figure: f1 across, the varied key up; each value's branch drawn as a
row coloured by what a designer needs (single stable response within the limits,
coexisting responses, a limit exceeded, unstable), the fold curves bounding the band
of coexistence, the period-doubling and Neimark-Sacker curves bounding the unstable
bands and the first-limit boundary over them, and on each row the first f1 of each
limit along its branch (f1 rising).  Plots take data (the summary)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from rawehelix.studies.analysis import branch_limits

from rawehelix.studies.store import writers

COLOURS = {"single": "tab:green", "coexisting": "tab:orange", "limit": "tab:red",
           "unstable": "0.55"}
LABELS = {"single": "single stable response within limits", "coexisting":
          "coexisting stable responses", "limit": "limit exceeded", "unstable": "unstable"}


STYLES = {"period_doubling": "m--", "neimark_sacker": "b-."}
CURVE_LABELS = {"period_doubling": "period-doubling curves",
                "neimark_sacker": "Neimark-Sacker curves"}


def _bands(ax, curves, colour, label):
    """The region between two curves traced from one value to the same other value (the
    two folds of a resonance, or a band's two stability boundaries), filled over the
    values both reach; a curve that comes back to its own value (round a band's tip)
    encloses its region alone."""
    pairs = {}
    for c in curves:
        if len(c["points"]) >= 2:
            pairs.setdefault((c["from_value"], c["to_value"]), []).append(c)
    labelled = False
    for (v0, v1), group in pairs.items():
        if v0 == v1:
            for c in group:
                ax.fill([p["f1_Hz"] for p in c["points"]], [p["value"] for p in c["points"]],
                        color=colour, alpha=0.35, lw=0, label=None if labelled else label)
                labelled = True
            continue
        if len(group) != 2:
            continue
        (a, b) = ([(p["value"], p["f1_Hz"]) for p in c["points"]] for c in group)
        if any(np.any(np.diff([v for v, _ in x]) * (v1 - v0) <= 0) for x in (a, b)):
            continue  # a curve that turns in the key: no single f1 per value to fill between
        a, b = sorted(a), sorted(b)
        lo, hi = max(a[0][0], b[0][0]), min(a[-1][0], b[-1][0])
        y = np.array(sorted({v for v, _ in a + b if lo <= v <= hi}))
        if y.size < 2:
            continue
        xa = np.interp(y, *zip(*a))
        xb = np.interp(y, *zip(*b))
        ax.fill_betweenx(y, xa, xb, color=colour, alpha=0.35, lw=0,
                         label=None if labelled else label)
        labelled = True


def classify(tick: dict) -> list[str]:
    """Each branch point's class: unstable; a limit reached; stable inside the band of
    two folds (coexisting); or the single stable response within the limits."""
    folds = sorted(f["f1_Hz"] for f in tick["folds"])
    band = (folds[0], folds[-1]) if len(folds) >= 2 else None
    out = []
    for p in tick["branch"]:
        if not p["stable"]:
            out.append("unstable")
        elif p["first_limit"] is not None:
            out.append("limit")
        elif band and band[0] <= p["f1_Hz"] <= band[1]:
            out.append("coexisting")
        else:
            out.append("single")
    return out


def envelope_png(path: Path, summary: dict, title: str) -> Path:
    plt = writers._pyplot()
    fig, ax = plt.subplots(figsize=(8, 5))
    draw(ax, summary)
    return writers._finish(fig, path, title)


def panels_png(path: Path, summaries: list, titles: list, title: str, columns: int = 2) -> Path:
    """Several envelopes side by side (the README's design maps)."""
    plt = writers._pyplot()
    rows = -(-len(summaries) // columns)
    fig, axes = plt.subplots(rows, columns, figsize=(6.5 * columns, 4.2 * rows), squeeze=False)
    for ax, summary, name in zip(axes.flat, summaries, titles):
        draw(ax, summary)
        ax.set_title(name, fontsize=9)
    for ax in list(axes.flat)[len(summaries):]:
        ax.axis("off")
    return writers._finish(fig, path, title)


def draw(ax, summary: dict):
    """One envelope on the axes ``ax``."""
    values = summary["values"]
    gap = (max(values) - min(values)) / max(len(values) - 1, 1)
    seen, firsts_seen = set(), set()
    cuts = {}
    for c in summary["limit_curve"]:
        cuts.setdefault(c["value"], []).append(c["f1_Hz"])

    def segment(f, kind, value):
        y = value + (0.12 * gap if kind == "unstable" else 0.0)
        ax.plot(f, [y, y], color=COLOURS[kind], lw=6 if kind != "unstable" else 2,
                solid_capstyle="butt", label=None if kind in seen else LABELS[kind])
        seen.add(kind)

    for tick in summary["ticks"]:
        f = np.array([p["f1_Hz"] for p in tick["branch"]])
        classes = classify(tick)
        # the branch as a band at its value (the unstable part above it), split at the
        # located first-limit crossings
        for i in range(len(f) - 1):
            a, b = classes[i], classes[i + 1]
            inside = [x for x in cuts.get(tick["value"], []) if min(f[i:i + 2]) < x < max(f[i:i + 2])]
            if a != b and inside:
                segment([f[i], inside[0]], a, tick["value"])
                segment([inside[0], f[i + 1]], b, tick["value"])
            else:
                segment(f[i:i + 2], b if a != b else a, tick["value"])
        for fold in tick["folds"]:
            ax.plot(fold["f1_Hz"], tick["value"], "k|", ms=14)
        branch_limits.mark_firsts((ax,), tick.get("limits_first_by_kind", {}), tick["value"],
                                  firsts_seen, window=summary["f1_window_Hz"])
    _bands(ax, summary["fold_curves"], COLOURS["coexisting"], "two stable responses coexist")
    _bands(ax, summary.get("bifurcation_curves", []), COLOURS["unstable"],
           "unstable between PD / NS curves")
    for k, curve in enumerate(summary["fold_curves"]):
        pts = curve["points"]
        if pts:
            ax.plot([p["f1_Hz"] for p in pts], [p["value"] for p in pts], "k-", lw=1.2,
                    label=None if k else "fold curves (two-parameter continuation)")
    drawn = set()
    for curve in summary.get("bifurcation_curves", []):
        pts, kind = curve["points"], curve["kind"]
        if pts:
            ax.plot([p["f1_Hz"] for p in pts], [p["value"] for p in pts], STYLES[kind],
                    lw=1.2, label=None if kind in drawn else CURVE_LABELS[kind])
            drawn.add(kind)
    limit = sorted(summary["limit_curve"], key=lambda c: c["value"])
    if limit:
        ax.plot([c["f1_Hz"] for c in limit], [c["value"] for c in limit], "rx--", lw=1,
                label="first limit reached")
    ax.set_xlabel("f1 [Hz]")
    ax.set_ylabel(summary["key"])
    ax.set_xlim(*summary["f1_window_Hz"])
    ax.grid(alpha=0.3)
    lo, hi = min(values), max(values)
    ax.set_ylim(lo - 0.4 * gap, hi + 1.3 * gap)  # room above the rows for the legend
    ax.legend(fontsize=7, loc="upper left", ncol=2, framealpha=0.9)
