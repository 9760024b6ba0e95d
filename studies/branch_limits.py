"""The ``limits`` block of a sweep's and an orbit branch's points (issue 29), and
their summary's block over the points.

A point's block is studies/structure_limits.py's :class:`Tracker` block over the
section states of its steady window (a sweep: the recorded periods; an orbit: one
period); its entry also carries the block's headline values flat, for the table of
points: ``moment_ratio_max``, ``slack_fraction_max`` and ``first_limit`` (the kind).
A point that has none (stored before the block existed, failed, or of a scheme
without fields along s) says why in ``status``, and its values are None: never a
made-up number.

The summary's block (:func:`over_points`) is over the points: the extremes with the
f1 where they occur, and the first limit by f1 (the lowest f1 whose point reached a
criterion), not by t: a sweep's or a branch's points are states at different f1.
"""

from __future__ import annotations

from rawehelix.studies import structure_limits

#: why a point has no block (its ``status``)
NOT_RECORDED = "not recorded (a point stored before the limits block existed)"
NOT_AVAILABLE = "not available: the scheme has no section fields along s"
FAILED = "not recorded (the point failed)"

#: the flat keys of a point's entry (the table of points)
FLAT = ("moment_ratio_max", "slack_fraction_max", "first_limit")


def absent(status: str) -> dict:
    """The block of a point without one: its status, and no numbers."""
    return {"status": status, "moment_ratio_max": None, "slack_fraction_max": None,
            "first_limit": None}


def point_block(params, sections) -> dict:
    """The block over ``sections`` ([(t, Probes.section() dict)], normalised), or the
    absent block when ``sections`` is None (a scheme without fields along s)."""
    if sections is None:
        return absent(NOT_AVAILABLE)
    tracker = structure_limits.of_params(params)
    q = params.normalised()
    for t, section in sections:
        structure_limits.add_normalised(tracker, q, section, t)
    return {"status": "recorded", "samples": len(sections), **tracker.block()}


def flat(block: dict) -> dict:
    """The headline values of a point's block, for its entry (None where absent)."""
    ratio, first = block.get("moment_ratio_max"), block.get("first_limit")
    return {"moment_ratio_max": ratio["value"] if isinstance(ratio, dict) else ratio,
            "slack_fraction_max": block.get("slack_fraction_max"),
            "first_limit": first["kind"] if isinstance(first, dict) else first}


def with_block(entry: dict, block: dict) -> dict:
    """``entry`` with its ``limits`` block and the block's flat values."""
    return {**entry, **flat(block), "limits": block}


def loaded(entry: dict) -> dict:
    """A stored point's entry with a block: an old point's says "not recorded"."""
    if "limits" in entry:
        return entry
    return with_block(entry, absent(FAILED if entry.get("failed") else NOT_RECORDED))


def over_points(points: list[dict], order: str = "f1") -> dict:
    """The summary's block over the points (module docstring); ``order`` says how
    the first limit is found ("f1": the lowest f1 whose point reached one)."""
    have = [p for p in points if p.get("limits", {}).get("status") == "recorded"]
    out = {"over": "the points' blocks (points[i].limits)",
           "first_limit_by": f"{order} (the lowest f1 whose point reached a criterion), not t",
           "points_recorded": len(have), "points_without": len(points) - len(have),
           "moment_ratio_max": None, "slack_fraction_max": None, "first_limit": None}
    if not have:
        return out
    top = max(have, key=lambda p: p["moment_ratio_max"] if p["moment_ratio_max"] is not None
              else -1.0)
    if top["moment_ratio_max"] is not None:
        out["moment_ratio_max"] = {**top["limits"]["moment_ratio_max"], "f1_Hz": top["f1_Hz"]}
    slack = max(have, key=lambda p: p["slack_fraction_max"])
    out["slack_fraction_max"] = {"value": slack["slack_fraction_max"], "f1_Hz": slack["f1_Hz"]}
    reached = sorted((p for p in have if p["limits"]["first_limit"] is not None),
                     key=lambda p: p["f1_Hz"])
    if reached:
        out["first_limit"] = {**reached[0]["limits"]["first_limit"], "f1_Hz": reached[0]["f1_Hz"]}
    for level in (0.5, 1.0):
        above = [p["f1_Hz"] for p in sorted(have, key=lambda p: p["f1_Hz"])
                 if p["moment_ratio_max"] is not None and p["moment_ratio_max"] > level]
        out[f"first_f1_moment_ratio_above_{level:g}_Hz"] = above[0] if above else None
    return out


#: the levels drawn on the moment-ratio panel: 1, |M| = N R; 1/2, where the first
#: tether of a 6-ring slackens under statics (members.py: cos 60 deg)
LEVELS = ((1.0, "|M| = N R"), (0.5, "first of 6 tethers slack (statics)"))


def moment_ratio_panel(ax, points: list[dict], label: str = "sweep"):
    """moment_ratio_max against f1, with the lines of :data:`LEVELS`; False if no
    point has one (the panel then says so)."""
    have = [p for p in points if p.get("moment_ratio_max") is not None]
    for level, what in LEVELS:
        ax.axhline(level, color="C3" if level == 1 else "C1", ls="--", lw=1, label=what)
    if have:
        ax.plot([p["f1_Hz"] for p in have], [p["moment_ratio_max"] for p in have], "o-",
                color="C2", ms=4, label=label)
    else:
        ax.text(0.5, 0.5, "moment ratio not recorded", transform=ax.transAxes, ha="center")
    ax.set_xlabel("forcing frequency f1 [Hz]")
    ax.set_ylabel("max |M| / (N R)")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper left", fontsize=8)
    return bool(have)


class OrbitLimits:
    """The limits of a branch's orbits: each orbit's block over one period from its
    state (the period map's ``sections``: solvers/orbits.py::AlphaMap.sections; a
    map without them, the spline reference, gives the absent block), computed once
    an orbit, and the branch points' observables ``moment_ratio_max`` and
    ``slack_fraction_max`` (problem.py's Observable, of the orbit alone)."""

    def __init__(self, m, params):
        from rawehelix.periodic_orbits.problem import Observable
        self.m, self.params = m, params
        self._blocks = {}  # id(orbit) -> (orbit, block): the orbit kept while cached
        self.observables = tuple(
            Observable(name, None, lambda o, name=name: flat(self.block(o))[name])
            for name in ("moment_ratio_max", "slack_fraction_max"))

    def block(self, orbit) -> dict:
        """The orbit's block (t from the period's phase 0)."""
        key = id(orbit)
        if key not in self._blocks:
            sections = (self.m.sections(orbit.X, orbit.f1_Hz, steps=orbit.steps)
                        if hasattr(self.m, "sections") else None)
            self._blocks[key] = (orbit, point_block(self.params, sections))
        return self._blocks[key][1]

    def entry(self, orbit) -> dict:
        """The orbit's branch entry with its observables, first limit and block."""
        block = self.block(orbit)
        return {**orbit.entry(), **{ob.name: ob.of_orbit(orbit) for ob in self.observables},
                "first_limit": flat(block)["first_limit"], "limits": block}
