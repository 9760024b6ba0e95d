"""The envelope's two-parameter curves (issue 31), traced on rank 0 from the gathered
ticks (studies/envelope.py):

- fold curves: each tick's folds continued in KEY to the next tick by the minimally
  augmented system (periodic_orbits/fold_curve.py); the band between two of them is
  where two stable responses coexist;
- period-doubling and Neimark-Sacker curves: each tick's PD and NS where the orbit loses
  or regains stability continued in KEY by the stability test function
  (periodic_orbits/bifurcation_curve.py) forward, and, for one no earlier tick's curve
  reached, back (an unstable band that opens between two ticks: the trace back ends
  where it closes); on through a tick whose branch has none near (a narrow band between
  two of its points) to the next that has it.

SUBSTEPS natural steps a tick.  A curve that reaches a tick with its partner (that tick's
own fold, or PD or NS of either kind: a boundary may turn from NS into PD, nearer than
MATCH_HZ) is checked against it (``fold_check_Hz``, ``check_Hz``: asked within
CHECK_HZ), and one that does not reach one says where and why.
"""

from __future__ import annotations

import numpy as np

from rawehelix.errors import SolverError

SUBSTEPS = 4  # natural steps in KEY from one tick to the next
CHECK_HZ = 1e-3  # a curve's end and the next tick's own event agree within this
MATCH_HZ = 0.05  # the next tick's event nearer than this is the same one (checked)
SAME_HZ = 1e-5  # two boundaries of one tick this close are one (located to 1e-6 Hz)


class Problems:
    """The periodic-orbit problem at a value of KEY, ``make(value)``, one at a time (each
    holds a rod)."""

    def __init__(self, make):
        self.make, self.value, self.problem = make, None, None

    def __call__(self, v):
        if v != self.value:
            self.value, self.problem = v, None
            self.problem = self.make(v)
        return self.problem


def _checked(curve, end_value, end_f1, to_value, partners, key, what, check="check_Hz"):
    """The curve's check against the events of the tick at ``to_value``, as
    ``curve[check]`` (in place)."""
    near = min(partners, key=lambda f: abs(f - end_f1)) if partners else None
    if end_value != to_value:
        return
    if near is not None and abs(near - end_f1) <= MATCH_HZ:
        curve[check] = end_f1 - near
    else:  # the next tick's branch has none here: it left the window there
        curve["end"] += (f"; the branch at {key} = {to_value:g} has no {what} near "
                         f"{end_f1:.4f} Hz (outside the f1 window, or not traced"
                         + ("" if what == "fold" else ", or an unstable band between two "
                            "of its points") + ")")


def fold_curves(problem_at, key, values, ticks, starts, substeps=SUBSTEPS) -> list:
    """Each tick's folds continued to the next tick."""
    from rawehelix.periodic_orbits import fold_curve
    curves = []
    for k in range(len(values) - 1):
        v0, v1 = values[k], values[k + 1]
        for s in starts[k]:
            d = s["Xb"] - s["Xa"]
            d /= max(np.linalg.norm(d), 1e-300)
            curve = {"from_value": v0, "to_value": v1, "points": [], "end": None,
                     "fold_check_Hz": None}
            try:
                first = fold_curve.locate(problem_at(v0), 0.5 * (s["Xa"] + s["Xb"]),
                                          s["f1_Hz"], s["resolution"], d, d, p=v0)
            except SolverError as err:
                curve["end"] = f"not located at the tick: {err}"
                curves.append(curve)
                continue
            curve["tick_fold_Hz"] = s["f1_Hz"]
            folds, curve["end"] = fold_curve.trace(problem_at, first, v1, (v1 - v0) / substeps)
            curve["points"] = [{"value": f.p, "f1_Hz": f.f1_Hz} for f in folds]
            _checked(curve, folds[-1].p, folds[-1].f1_Hz, v1,
                     [f["f1_Hz"] for f in ticks[k + 1]["folds"]], key, "fold", "fold_check_Hz")
            curves.append(curve)
    return curves


def _boundaries(problem_at, value, starts) -> list:
    """The tick's stability boundaries (other than folds), as (start, Crossing or the
    error): each located by regula falsi between the two branch points whose stability
    differs; one the branch met before (it passes a band twice, as an S-curve through it
    does) is kept once."""
    from rawehelix.periodic_orbits import bifurcation_curve
    out = []
    for s in starts:
        try:
            c = bifurcation_curve.locate(problem_at(value), s["X"], s["f1_Hz"],
                                         s["resolution"], p=value, bracket=s["bracket_Hz"])
        except SolverError as err:
            out.append((s, f"not located at the tick: {err}"))
            continue
        if not any(not isinstance(o, str) and abs(o.f1_Hz - c.f1_Hz) <= SAME_HZ for _, o in out):
            out.append((s, c))
    return out


def _trace_crossing(problem_at, first, path, substeps, key) -> dict:
    """The crossing ``first`` continued along ``path``, [(value, that tick's located
    boundaries [Hz])] from its own tick on: tick to tick until one has its partner
    (checked), the curve ends or comes back to the tick it left (round a band's tip
    between the two: checked against that tick's other boundary), or the path does (a
    tick with none near: its branch stepped over the band, said so)."""
    from rawehelix.periodic_orbits import bifurcation_curve
    curve = {"kind": first.kind, "from_value": path[0][0], "to_value": path[1][0],
             "tick_Hz": first.f1_Hz, "points": [], "end": None, "check_Hz": None}
    points, notes = [first], ""
    for (v0, here), (v1, partners) in zip(path, path[1:]):
        more, why = bifurcation_curve.trace(problem_at, points[-1], v1, (v1 - v0) / substeps)
        points += more[1:]
        back = len(more) > 1 and more[-1].p == v0
        curve.update(to_value=v0 if back else v1, end=why + notes,
                     points=[c.entry() for c in points])
        if back:  # the partner is the tick's other boundary
            others = [f for f in here if abs(f - more[0].f1_Hz) > 1e-9]
            _checked(curve, v0, points[-1].f1_Hz, v0, others, key,
                     "other period-doubling or Neimark-Sacker")
            break
        _checked(curve, points[-1].p, points[-1].f1_Hz, v1, partners, key,
                 "period-doubling or Neimark-Sacker")
        if curve["check_Hz"] is not None or points[-1].p != v1:
            break
        notes = curve["end"][len(why):]
    return curve


def bifurcation_curves(problem_at, key, values, starts, substeps=SUBSTEPS) -> list:
    """Each tick's stability boundaries other than folds (``starts``: the brackets
    between branch points) located, then continued forward, and back where no curve
    reached them, each to the nearest tick that has it (:func:`_trace_crossing`)."""
    pairs = [_boundaries(problem_at, v, row) for v, row in zip(values, starts)]
    located = [[c for _, c in row] for row in pairs]
    found = [[c.f1_Hz for c in row if not isinstance(c, str)] for row in located]
    curves = [{"kind": s["kind"], "from_value": values[k], "to_value": values[k],
               "tick_Hz": s["f1_Hz"], "points": [], "end": c, "check_Hz": None}
              for k, row in enumerate(pairs) for s, c in row if isinstance(c, str)]

    def reached(k, c, loops_only):
        """Whether a curve ended on the crossing c of tick k (checked against it)."""
        return any(r["to_value"] == values[k] and r["check_Hz"] is not None
                   and abs(r["points"][-1]["f1_Hz"] - r["check_Hz"] - c.f1_Hz) <= 1e-9
                   and (not loops_only or r["from_value"] == values[k]) for r in curves)

    for k in range(len(values) - 1):
        for c in located[k]:
            if not isinstance(c, str) and not reached(k, c, loops_only=True):
                curves.append(_trace_crossing(problem_at, c, [(values[j], found[j]) for j in
                                              range(k, len(values))], substeps, key))
    for k in range(len(values) - 1, 0, -1):
        for c in located[k]:
            if not isinstance(c, str) and not reached(k, c, loops_only=False):
                curves.append(_trace_crossing(problem_at, c, [(values[j], found[j]) for j in
                                              range(k, -1, -1)], substeps, key))
    return curves


def worst_check(curves, check="check_Hz") -> float | None:
    """The largest |curve[check]| (None: no curve was checked)."""
    checks = [abs(c[check]) for c in curves if c.get(check) is not None]
    return max(checks) if checks else None
