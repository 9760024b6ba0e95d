"""The table against the experiment of Sec. 5.3 (Fig. 7), issue 29: from the
summary.json of `rawehelix sweep` or `rawehelix orbits` runs of the mobile_end scene.

    .venv/bin/python scripts/experiment_table.py LABEL=DIR [LABEL=DIR ...] [--breaking 50,100,200]

Per run (a column): the quasi-static T max (the lowest f1's), where T max first rises
10 % above it, where the first member slackens (the limits block's slack fraction >
0), where the response stops being a stable periodic orbit (orbits: the first fold
or bifurcation and its kind; sweeps: the first point flagged not periodic, or the
first fall of T max by more than JUMP between two points: the followed branch's fold), where T
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

SETTLING = 0.5  # [N]: a not-periodic point oscillating less than this is still settling
JUMP = 0.2  # a sweep's T max falling by more than this fraction between two points

EXPERIMENT = {"rise": "3.5", "slack": "-", "stability": "irregular near 5 Hz",
              "x3": "~5 (then failure)", "breaking": "~5 (tethers ripped)"}


def points(summary: dict) -> list[dict]:
    """The run's points by increasing f1.  An orbit branch is walked from its
    lowest-f1 end while f1 rises: the branch the experiment's slowly rising f1
    follows, up to the fold where it turns (and the response would jump)."""
    if "branch" in summary:
        pts = list(summary["branch"])
        if pts[0]["f1_Hz"] > pts[-1]["f1_Hz"]:
            pts.reverse()
        walk = pts[:1]
        for p in pts[1:]:
            if p["f1_Hz"] < walk[-1]["f1_Hz"]:
                break
            walk.append(p)
        return walk
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
    if "branch" in summary:  # the fold or bifurcation nearest where the walk turned
        turn = pts[-1]["f1_Hz"]
        events = [(f["f1_Hz"], "fold") for f in summary.get("folds", [])]
        events += [(b["f1_Hz"], b.get("kind", "bifurcation")) for b in summary.get("bifurcations", [])]
        events = [e for e in events if e[0] <= turn + 0.05 * turn]
        if not events:
            return "-"
        f, kind = max(events)
        return f"{f:.2f} ({kind})"
    events = []
    # not periodic after max_periods; "*": its oscillation T max - T min is below
    # SETTLING N, a slow transient near the quasi-static state rather than a response
    bad = [p for p in pts if not p.get("periodic", True)]
    if bad:
        names = ", ".join(f"{p['f1_Hz']:g}" + ("*" if p["tension_max_N"] - p["tension_min_N"]
                                                < SETTLING else "") for p in bad)
        events.append((bad[0]["f1_Hz"], f"not periodic at {names}"))
    for a, b in zip(pts, pts[1:]):  # a jump down: the branch the sweep followed ended in a fold
        if b["tension_max_N"] < (1 - JUMP) * a["tension_max_N"]:
            events.append((b["f1_Hz"], f"({a['f1_Hz']:g}, {b['f1_Hz']:g}] (jump down: a fold)"))
            break
    return min(events)[1] if events else "-"


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


def load(folder: Path) -> dict:
    """A run's summary.json, or an unfinished sweep's sweep.json (its points so far)."""
    if (folder / "summary.json").exists():
        return json.loads((folder / "summary.json").read_text())
    return json.loads((folder / "sweep.json").read_text())


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
        cols[label] = column(load(Path(folder)), breaking)
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
