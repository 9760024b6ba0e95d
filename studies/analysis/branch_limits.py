"""The ``limits`` block of a sweep's and an orbit branch's points (issue 29), and
their summary's block over the points.

A point's block is studies/analysis/structure_limits.py's :class:`Tracker` block over the
section states of its steady window (a sweep: the recorded periods; an orbit: one
period); its entry also carries the block's headline values flat, for the table of
points: ``moment_ratio_max``, ``slack_fraction_max`` and ``first_limit`` (the kind).
A point that has none (stored before the block existed, failed, or of a scheme
without fields along s) says why in ``status``, and its values are None: never a
made-up number.

The summary's block (:func:`over_points`) is over the points: the extremes with the
f1 where they occur, and the first limit in the run's own order of points (a sweep:
f1 rising; a branch: along the continuation from its first f1), not by t: a sweep's
or a branch's points are states at different f1.  The first point that reached any
criterion gives ``first_limit`` (and every kind it reached, ``kinds``); each kind's
own first point is :func:`first_by_kind` (the summary's ``limits_first_by_kind``),
so that a criterion met from the first point on (a collapse criterion met by the
stationary twist) does not hide another met further on (the first slack).  A kind
met at the run's first point says so (``already_at_first_point``): the run starts
past it, and its f1 is only an upper bound.  :func:`first_lines` prints them and
:func:`mark_firsts` marks them on a figure.
"""

from __future__ import annotations

from rawehelix.members import CRITERIA
from rawehelix.references.network.limits import Record as MembersRecord
from rawehelix.studies.analysis import structure_limits

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
    """The block over ``sections`` ([(t, Probes.section() dict)], normalised; or the
    network's record of its members, references/network/limits.py), or the absent block
    when ``sections`` is None (a scheme without fields along s)."""
    if sections is None:
        return absent(NOT_AVAILABLE)
    if isinstance(sections, MembersRecord):  # the network's own members (its sampler's)
        return sections.block()
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


#: why a criterion is off (its threshold None in a point's ``criteria``): the scene key
#: that turns it on
OFF = {"breaking": "section.breaking_force_N not set",
       "torsional_collapse": "no critical twist: section.ring_spacing_m not set, or tethers "
                             "shorter than the ring's diameter"}
#: each kind as the reports and figures name it, and its mark on a figure
NAMES = {"slack": "slack", "breaking": "breaking force", "moment_saturation":
         "moment saturation", "torsional_collapse": "torsional collapse"}
MARKS = {"slack": ("C3", "--", "v"), "breaking": ("k", "-", "X"),
         "moment_saturation": ("C1", "-.", "D"), "torsional_collapse": ("C4", ":", "s")}
RISING = "f1 rising, the sweep's order"  # a sweep's order of points


def recorded(points: list[dict]) -> list[dict]:
    """The points with a recorded block, in the order given."""
    return [p for p in points if p.get("limits", {}).get("status") == "recorded"]


def kinds_of(block: dict) -> dict:
    """A point's first of each kind: its block's ``first_by_kind``, or (a block stored
    before it existed) its ``first_limit`` alone, the other kinds then None."""
    by = block.get("first_by_kind")
    if by is not None:
        return by
    first, by = block.get("first_limit"), dict.fromkeys(CRITERIA)
    if first:
        by[first["kind"]] = first
    return by


def first_by_kind(points: list[dict]) -> dict:
    """Each criterion's first point in the order of ``points`` (the run's own): the
    point's first of that kind (value, s_m, t_s, ...) with its ``f1_Hz``, its index
    among ``points`` (``point``) and ``already_at_first_point``; None where no
    recorded point reached it (or it is off: the block's ``criteria_off``)."""
    have = recorded(points)
    out = dict.fromkeys(CRITERIA)
    for kind in CRITERIA:
        for p in have:
            x = kinds_of(p["limits"]).get(kind)
            if x:
                out[kind] = {**x, "f1_Hz": p["f1_Hz"], "point": points.index(p),
                             "already_at_first_point": p is have[0]}
                break
    return out


def over_points(points: list[dict], order: str = RISING) -> dict:
    """The summary's block over the points (module docstring), ``points`` in the run's
    own ``order`` (said in ``first_limit_by``)."""
    have = recorded(points)
    out = {"over": "the points' blocks (points[i].limits)",
           "first_limit_by": f"{order}: the first point that reached a criterion, not t",
           "points_recorded": len(have), "points_without": len(points) - len(have),
           "moment_ratio_max": None, "slack_fraction_max": None, "first_limit": None,
           "f1_range_Hz": [have[0]["f1_Hz"], have[-1]["f1_Hz"]] if have else None,
           "criteria_off": {kind: OFF[kind] for kind in OFF if have and all(
               p["limits"].get("criteria", {}).get(kind) is None for p in have)}}
    if not have:
        return out
    top = max(have, key=lambda p: p["moment_ratio_max"] if p["moment_ratio_max"] is not None
              else -1.0)
    if top["moment_ratio_max"] is not None:
        out["moment_ratio_max"] = {**top["limits"]["moment_ratio_max"], "f1_Hz": top["f1_Hz"]}
    slack = max(have, key=lambda p: p["slack_fraction_max"])
    out["slack_fraction_max"] = {"value": slack["slack_fraction_max"], "f1_Hz": slack["f1_Hz"]}
    reached = [p for p in have if p["limits"]["first_limit"] is not None]
    if reached:
        first = reached[0]
        out["first_limit"] = {**first["limits"]["first_limit"], "f1_Hz": first["f1_Hz"],
                              "kinds": [k for k, x in kinds_of(first["limits"]).items() if x],
                              "already_at_first_point": first is have[0]}
    for level in (0.5, 1.0):
        above = [p["f1_Hz"] for p in sorted(have, key=lambda p: p["f1_Hz"])
                 if p["moment_ratio_max"] is not None and p["moment_ratio_max"] > level]
        out[f"first_f1_moment_ratio_above_{level:g}_Hz"] = above[0] if above else None
    return out


def _each(firsts: dict, block: dict):
    """(name, first or None, why it is off or None) of each criterion, in CRITERIA's order."""
    off = block.get("criteria_off", {})
    return [(NAMES[kind], firsts.get(kind), off.get(kind)) for kind in CRITERIA]


def _met(x: dict) -> str:
    return ("already at the first point, " if x["already_at_first_point"] else "") + \
        f"f1 = {x['f1_Hz']:g} Hz"


def first_lines(firsts: dict, block: dict, indent: str = "  ", scene: str = "SCENE") -> list[str]:
    """The report's lines of each kind's first (:func:`first_by_kind`) over the points
    of the summary's ``block`` (:func:`over_points`): its f1 and place, or why none."""
    if not block or not block.get("points_recorded"):
        return [f"{indent}limits: not recorded at any point"
                + (f" ({block['points_without']} without)" if block else "")]
    lo, hi = block["f1_range_Hz"]
    span = f"f1 = {lo:g}..{hi:g} Hz"
    order = block["first_limit_by"].partition(":")[0]
    lines = [f"{indent}first limit of each kind ({order}; {block['points_recorded']} points, "
             f"{span}):"]
    for name, x, off in _each(firsts, block):
        lines.append(f"{indent}  {name}: " + (f"not checked ({off})" if off else
                                             f"not reached in {span}" if x is None else
                                             f"{_met(x)}, {place(x)}"))
    if any(x and x["already_at_first_point"] for x in firsts.values()):
        lines.append(f"{indent}  (met already at the first point, f1 = {lo:g} Hz: the run starts "
                     f"past it; extend the run before that f1 to find where it begins, unless "
                     f"the helix meets it at rest: if 'rawehelix stationary {scene}' reports "
                     f"it too, more rings, less torque or more tension move it, not the f1 window)")
    return lines


def first_line(firsts: dict, block: dict) -> str:
    """:func:`first_lines` on one line (an envelope's tick): each kind's f1 and s, or why
    none."""
    if not block or not block.get("points_recorded"):
        return "limits not recorded at any point"
    lo, hi = block["f1_range_Hz"]
    parts = [f"{name}: " + ("not checked" if off else "not reached" if x is None else
                            f"{_met(x)}, s = {x['s_m']:.3f} m")
             for name, x, off in _each(firsts, block)]
    return f"first limits in f1 = {lo:g}..{hi:g} Hz: " + "; ".join(parts)


def place(x: dict) -> str:
    """Where and how a kind's first is met: s, t, the member, the value and threshold."""
    text = f"s = {x['s_m']:.3f} m" + ("" if x.get("t_s") is None else f", t = {x['t_s']:.4g} s")
    if "member" in x:
        text += (f", member {x['member']} at {x['member_angle_deg']:.0f} deg from the "
                 f"bending plane's inner side")
    if x.get("quantity") in structure_limits.QUANTITIES:
        name, unit = structure_limits.QUANTITIES[x["quantity"]]
        unit = f" {unit}" if unit else ""
        value = "unbounded (a moment without tension)" if x["value"] is None else \
            f"{x['value']:.4g}{unit}"
        threshold = x.get("threshold")
        text += f": {name} {value}" + ("" if threshold is None else
                                       f", limit {threshold:.4g}{unit}")
    return text


def mark_firsts(axes, firsts: dict, y=None, seen: set | None = None, window=None):
    """Each kind's first on a figure's f1 axes: a vertical line at its f1 on every axes
    of ``axes``, labelled with its f1 on the first; or, with ``y`` (an envelope's row),
    a marker at (f1, y), labelled once per kind over the calls sharing ``seen``, an f1
    outside ``window`` (LO, HI) on its edge."""
    for kind in CRITERIA:
        x = firsts.get(kind)
        if not x:
            continue
        colour, style, marker = MARKS[kind]
        already = " (already at the first point)" if x.get("already_at_first_point") else ""
        for k, ax in enumerate(axes):
            if y is None:
                ax.axvline(x["f1_Hz"], color=colour, ls=style, lw=1.2, label=None if k else
                           f"first {NAMES[kind]}: {x['f1_Hz']:.4g} Hz{already}")
            else:
                # nested sizes: kinds met at one f1 all show; a first just outside the
                # window (the branch's last step overshoots it) on its edge
                f1 = x["f1_Hz"] if window is None else min(max(x["f1_Hz"], window[0]), window[1])
                ax.plot(f1, y, marker, color=colour, ms=11 - 2 * CRITERIA.index(kind),
                        mec="k", zorder=5, clip_on=False,
                        label=None if kind in seen else f"first {NAMES[kind]} (f1 rising)")
                seen.add(kind)


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
            sections = self.m.sections(orbit.X, orbit.f1_Hz, steps=orbit.steps)
            self._blocks[key] = (orbit, point_block(self.params, sections))
        return self._blocks[key][1]

    def entry(self, orbit) -> dict:
        """The orbit's branch entry with its observables, first limit and block."""
        block = self.block(orbit)
        return {**orbit.entry(), **{ob.name: ob.of_orbit(orbit) for ob in self.observables},
                "first_limit": flat(block)["first_limit"], "limits": block}
