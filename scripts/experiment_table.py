"""The table against the experiment of Sec. 5.3 (Fig. 7), issue 29: from the
summary.json of `rawehelix sweep` or `rawehelix orbits` runs of the mobile_end scene.

    .venv/bin/python scripts/experiment_table.py LABEL=DIR [LABEL=DIR ...] [--breaking 50,100,200]

Per run (a column): the quasi-static T max (the lowest f1's), where T max first rises
10 % above it, where the first member slackens (the limits block's slack fraction >
0), where the response stops being a stable periodic orbit (orbits: the first fold
or bifurcation and its kind; sweeps: the first point flagged not periodic), where T
max first reaches three times the quasi-static value, and where the largest member
force first reaches each breaking force of ``--breaking`` [N].  Every frequency is
linearly interpolated between the two points that bracket it (a sweep's step, or
the branch's), and the bracket is printed beside it (the slack, an indicator, by its
bracket alone); "-" where the run never gets
there, "n/r" where the run did not record the quantity.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

EXPERIMENT = {"rise": "3.5", "slack": "-", "stability": "irregular near 5 Hz",
              "x3": "~5 (then failure)", "breaking": "~5 (tethers ripped)"}


def points(summary: dict) -> list[dict]:
    """The run's points by increasing f1 (the orbits' branch up to its first fold:
    the branch the experiment's slowly rising f1 follows)."""
    if "branch" in summary:
        pts = sorted(summary["branch"], key=lambda p: p["f1_Hz"])
        folds = [f["f1_Hz"] for f in summary.get("folds", [])]
        first = min(folds) if folds else float("inf")
        return [p for p in pts if p["f1_Hz"] <= first + 1e-9]
    return sorted((p for p in summary["points"] if "tension_max_N" in p),
                  key=lambda p: p["f1_Hz"])


def first_crossing(pts, value, level):
    """(f1, bracket) where value(p) first reaches level, interpolated; None if never;
    "n/r" if a point lacks the value."""
    prev = None
    for p in pts:
        v = value(p)
        if v is None:
            return "n/r"
        if v >= level:
            if prev is None:
                return p["f1_Hz"], (p["f1_Hz"], p["f1_Hz"])
            f0, v0 = prev
            f = f0 + (level - v0) / (v - v0) * (p["f1_Hz"] - f0) if v != v0 else p["f1_Hz"]
            return f, (f0, p["f1_Hz"])
        prev = (p["f1_Hz"], v)
    return None


def limit(p, key):
    """A point's limits entry (sweep points and orbit branch points carry them)."""
    block = p.get("limits")
    if isinstance(block, dict):
        v = block.get(key)
        return v.get("value") if isinstance(v, dict) else v
    return p.get(key)


def stability(summary: dict, pts) -> str:
    if "branch" in summary:
        events = [(f["f1_Hz"], "fold") for f in summary.get("folds", [])]
        events += [(b["f1_Hz"], b.get("kind", "bifurcation")) for b in summary.get("bifurcations", [])]
        if not events:
            return "-"
        f, kind = min(events)
        return f"{f:.2f} ({kind})"
    bad = [p["f1_Hz"] for p in summary["points"] if not p.get("periodic", True)]
    return f"{min(bad):.2f} (not periodic)" if bad else "-"


def fmt(x, interpolate: bool = True) -> str:
    """'f [a, b]' (interpolated in its bracket), or '(a, b]' for an indicator."""
    if x is None:
        return "-"
    if x == "n/r":
        return "n/r"
    f, (a, b) = x
    if a == b:
        return f"<= {f:g}"
    return f"{f:.2f} [{a:g}, {b:g}]" if interpolate else f"({a:g}, {b:g}]"


def column(summary: dict, breaking: list[float]) -> dict:
    pts = points(summary)
    T_qs = pts[0]["tension_max_N"]
    out = {"T_qs": f"{T_qs:.1f} N at {pts[0]['f1_Hz']:g} Hz",
           "rise": fmt(first_crossing(pts, lambda p: p["tension_max_N"], 1.1 * T_qs)),
           "slack": fmt(first_crossing(pts, lambda p: limit(p, "slack_fraction_max"), 1e-12),
                        interpolate=False),
           "stability": stability(summary, pts),
           "x3": fmt(first_crossing(pts, lambda p: p["tension_max_N"], 3 * T_qs))}
    for F in breaking:
        out[f"break{F:g}"] = fmt(first_crossing(pts, lambda p: limit(p, "max_member_force_N"), F))
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("runs", nargs="+", help="LABEL=DIR of a sweep's or orbits' output")
    ap.add_argument("--breaking", default="50,100,200,400",
                    help="breaking forces of a tether [N], comma-separated")
    args = ap.parse_args(argv)
    breaking = [float(x) for x in args.breaking.split(",")]
    cols = {}
    for run in args.runs:
        label, _, folder = run.rpartition("=")
        cols[label] = column(json.loads((Path(folder) / "summary.json").read_text()), breaking)
    rows = [("quasi-static T max", "T_qs", "80 N nominal"),
            ("T max 10 % above it [Hz]", "rise", EXPERIMENT["rise"]),
            ("first member slack [Hz]", "slack", EXPERIMENT["slack"]),
            ("loss of a stable periodic response [Hz]", "stability", EXPERIMENT["stability"]),
            ("T max = 3 x quasi-static [Hz]", "x3", EXPERIMENT["x3"])]
    rows += [(f"largest member force = {F:g} N [Hz]", f"break{F:g}", EXPERIMENT["breaking"])
             for F in breaking]
    print("| | experiment (Sec. 5.3, Fig. 7) | " + " | ".join(cols) + " |")
    print("|---|---|" + "---|" * len(cols))
    for name, key, exp in rows:
        print(f"| {name} | {exp} | " + " | ".join(c[key] for c in cols.values()) + " |")


if __name__ == "__main__":
    main()
