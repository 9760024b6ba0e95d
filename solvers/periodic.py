"""Periodic response to the circular motion of the upper end (Sec. 5.3, Eq. 70).

At one forcing frequency f1, integrate whole forcing periods until the
response is periodic (:func:`settled`, the one definition): what remains of
the transient, bounded from the per-period changes of the maximum and the
minimum of the tension at s = 0 and their rate of decay, is below
``sweep.periodic_tolerance`` times the oscillation T max - T min.  The
oscillation, not T max, is the scale: below 8 Hz it is under 1 % of T, and a
tolerance relative to T max accepted an oscillation still changing by 20 %.
The remainder, not the last change, is judged: below 1.5 Hz a transient
decays by 4 % a period, and a change of 1e-3 of the oscillation left 10-40 %
of it (docs/explanation/orbits.md, "The sweep against the orbits").
A point that reaches ``sweep.max_periods`` first is flagged ``periodic =
False``, never silently accepted.

Time keeps running across frequencies (the torque ramp (69) and the
controller (40) see one clock), and the circle restarts at phase 0 at every
new frequency; since every point ends after whole periods, the upper end
never jumps: continuation as in the paper.

A *backend* integrates the rod, in normalised units: :class:`Backend` declares what
is asked of it (the FE's solvers/forced.py, the spline reference's
references/spline_galerkin/forced.py).  Backends read and write no files: ``pack`` and ``unpack`` convert a state to
and from plain arrays, which the caller may keep where it likes.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from rawehelix.parameters import Normalised, Sweep
from rawehelix.parameters.numerics import periods_to_judge


class Backend(Protocol):
    """What :func:`periodic_response` asks of the scheme that integrates the rod."""

    #: None, or solvers/section_samples.py's SectionSampler: the section along s over
    #: the recorded periods (PointResult.sections)
    section_sampler: object | None

    def stationary(self):
        """The state at t = 0 (stationary, the top at phase 0)."""

    def set_frequency(self, f1_Hz: float, t_start: float) -> None:
        """The circle at f1, phase 0 at t_start (``Normalised.at_frequency``)."""

    def advance(self, state, t0: float, t1: float, t_out):
        """(the state at t1, the tension at s = 0 at the times t_out)."""

    def pack(self, state) -> dict:
        """The state as plain arrays (:meth:`unpack` reads them back)."""

    def unpack(self, data: dict):
        """The state of :meth:`pack`'s arrays."""

    def track_sections(self) -> None:
        """Set ``section_sampler`` (a no-op without fields along s)."""

    def parts(self, state) -> dict | None:
        """The state's parts (name -> array) whose change over a period says what still
        moves (:func:`unsettled`); None: no parts to name (the tension alone is judged)."""


@dataclass
class PointResult:
    """The periodic response at one f1, in SI units."""

    f1_Hz: float
    tension_max_N: float
    tension_min_N: float
    tension_mean_N: float
    periods: int  # periods integrated at this f1 (lead-in not counted)
    periodic: bool
    wall_s: float
    start: str  # "stationary" (with lead-in) or "continuation"
    period_maxima_N: list = field(default_factory=list)
    period_minima_N: list = field(default_factory=list)
    series_t_s: np.ndarray | None = None  # tension at s = 0 over the recorded periods
    series_tension_N: np.ndarray | None = None
    slack: bool = False  # the tension at s = 0 fell to <= 0 in a judged period
    #: [(t, Probes.section() dict)] (normalised) over the recorded periods; None: the
    #: backend has no section sampler (not in the entry: studies/sweep_limits.py)
    sections: list | None = None
    #: why the point is not periodic (:func:`unsettled`); None: it is
    unsettled: dict | None = None

    def entry(self) -> dict:
        """The summary.json entry."""
        return {"f1_Hz": self.f1_Hz, "tension_max_N": self.tension_max_N,
                "tension_min_N": self.tension_min_N, "tension_mean_N": self.tension_mean_N,
                "periods": self.periods, "periodic": self.periodic, "slack": self.slack,
                "wall_s": self.wall_s, "start": self.start,
                **({"not_periodic": self.unsettled} if self.unsettled else {})}


#: names the test of :func:`settled` in a sweep checkpoint's fingerprint: a
#: checkpoint judged by another test (T max relative to T max, or the changes
#: of the extremes without the transient's remainder) is refused
CRITERION = "remainder of a geometric transient relative to the oscillation"

#: the smallest oscillation the test measures against, relative to the mean
#: tension: a response that hardly oscillates (no forcing) is judged on 1e-6 T
OSCILLATION_FLOOR = 1.0e-6

#: changes of the extremes at or below this, relative to the mean tension, are
#: round-off, not a transient.  (The sweep's Newton at rtol 1e-8 leaves changes
#: of ~8e-9 T a period at 1 Hz, N = 4; that noise is judged like a transient, so
#: a tolerance finer than it ends at max_periods, flagged.)
ROUNDOFF = 1.0e-10


@dataclass
class Transient:
    """What :func:`settled` measured over its last 3 blocks of periods (in the units of
    the tension it was given): the largest per-period change of T max or T min over
    the last block, its decay a period ``ratio`` (None: not measurable, a block without
    change), the bound on what remains ``remainder`` (None: not decaying, r >= 1), and
    what the tolerance allows."""

    change: float
    ratio: float | None
    remainder: float | None
    allowed: float
    settled: bool

    def periods_to_settle(self) -> int | None:
        """More periods until the remainder, decaying by ``ratio`` a period, is within
        the allowance (None: not decaying, or already within)."""
        if self.settled or self.remainder is None or not self.ratio or self.allowed <= 0:
            return None
        return math.ceil(math.log(self.allowed / self.remainder) / math.log(self.ratio))


def transient(maxima, minima, means, tolerance: float, periods: int) -> Transient | None:
    """The periodicity test's measure (:func:`settled`); None: fewer than its
    3 ``periods`` + 1 periods."""
    need = periods_to_judge(periods)
    if len(maxima) < need:
        return None
    hi, lo, mean = (np.asarray(v[-need:], dtype=float) for v in (maxima, minima, means))
    allowed = tolerance * max(hi[-1] - lo[-1], OSCILLATION_FLOOR * abs(mean[-1]))
    change = np.maximum(np.abs(np.diff(hi)), np.abs(np.diff(lo)))
    block = change.reshape(3, periods).max(axis=1)
    last = float(block[-1])
    if last <= ROUNDOFF * abs(mean[-1]):
        return Transient(last, None, 0.0, allowed, True)
    if block[0] == 0.0 or block[1] == 0.0:
        return Transient(last, None, None, allowed, False)
    r = float(max(block[1] / block[0], block[2] / block[1]) ** (1.0 / periods))
    remainder = last * r / (1.0 - r) if r < 1.0 else None
    return Transient(last, r, remainder, allowed,
                     bool(remainder is not None and remainder <= allowed))


def settled(maxima, minima, means, tolerance: float, periods: int) -> bool:
    """True if what remains of the transient after the last period is at most
    ``tolerance`` x max(T max - T min, OSCILLATION_FLOOR x |mean T|).

    A transient decays by its slowest Floquet multiplier r a period, and so do
    the changes d_k of the per-period maximum and minimum of T from one period
    to the next; what remains after the last one is then at most d r / (1 - r).
    A change alone does not bound it: at 1 Hz (r = 0.964) a change of 1e-3 of
    the oscillation leaves 2.7e-2 of it.  Over the last 3 ``periods`` + 1
    periods, d is the largest change of the last ``periods`` of them and r^periods
    the larger of the two ratios of the largest changes of successive blocks of
    ``periods`` (several periods a block: one small change alone can be the flat
    top of a slow beat).  A response whose changes do not shrink (r >= 1) has
    not settled, unless they are round-off (at most ROUNDOFF x |mean T|)."""
    measure = transient(maxima, minima, means, tolerance, periods)
    return measure is not None and measure.settled


def moving_parts(before: dict, after: dict) -> list[tuple[str, float]]:
    """The parts of the state (a backend's ``parts``: name -> array) by their change
    over the last period relative to their size, largest first."""
    changes = []
    for name, x1 in after.items():
        x0 = before[name]
        size = max(float(np.max(np.abs(x1), initial=0.0)), 1e-300)
        changes.append((name, float(np.max(np.abs(x1 - x0), initial=0.0)) / size))
    return sorted(changes, key=lambda c: -c[1])


def periodic_response(backend: Backend, q_base: Normalised, f1_Hz: float, state,
                      t_start: float, sweep: Sweep, lead_in: bool, progress=None):
    """Integrate at f1 from ``state`` at normalised time ``t_start``; ``progress(k,
    measure)`` after each judged period k (``measure``: :func:`transient`'s, or None).

    Returns (PointResult, final state, final normalised time); a point that is not
    periodic carries the measure that refused it (``PointResult.unsettled``)."""
    start_wall = time.perf_counter()
    q = q_base.at_frequency(f1_Hz, t_start)
    backend.set_frequency(f1_Hz, t_start)
    period = 2 * math.pi / q.omega1
    n = sweep.samples_per_period
    t = t_start
    if lead_in and sweep.lead_in_s > 0:
        n_lead = math.ceil(sweep.lead_in_s / q.t_scale / period)
        for _ in range(n_lead):
            state, _ = backend.advance(state, t, t + period, np.array([t + period]))
            t += period
    maxima, minima, means, history = [], [], [], []
    sampler = backend.section_sampler
    periodic = slack = False
    measure = before = None
    for k in range(1, sweep.max_periods + 1):
        if k == sweep.max_periods:  # the last period's start, if it is not periodic
            before = backend.parts(state)  # the parts, to say what still moves
        t_out = t + period * np.arange(1, n + 1) / n
        state, tension = backend.advance(state, t, t + period, t_out)
        if not np.all(np.isfinite(tension)):
            raise FloatingPointError(f"f1 = {f1_Hz} Hz: the tension is not finite at "
                                     f"t = {q.time_s(t):.3f} s")
        t += period
        maxima.append(float(np.max(tension)))
        minima.append(float(np.min(tension)))
        means.append(float(np.mean(tension)))
        slack = slack or minima[-1] <= 0
        history.append((t_out, tension, sampler.take() if sampler is not None else None))
        history = history[-sweep.record_periods:]
        measure = transient(maxima, minima, means, sweep.periodic_tolerance, sweep.record_periods)
        if progress:
            progress(k, measure)
        if k >= sweep.min_periods and measure is not None and measure.settled:
            periodic = True
            break
    t_rec = np.concatenate([h[0] for h in history])
    T_rec = q.tension_N(np.concatenate([h[1] for h in history]))
    result = PointResult(
        f1_Hz=f1_Hz, tension_max_N=float(T_rec.max()), tension_min_N=float(T_rec.min()),
        tension_mean_N=float(T_rec.mean()), periods=len(maxima), periodic=periodic,
        wall_s=time.perf_counter() - start_wall,
        start="stationary" if lead_in else "continuation", slack=slack,
        period_maxima_N=[float(v) for v in q.tension_N(np.array(maxima))],
        period_minima_N=[float(v) for v in q.tension_N(np.array(minima))],
        series_t_s=q.time_s(t_rec), series_tension_N=T_rec,
        sections=None if sampler is None else sampler.sections(
            [kept for h in history for kept in h[2]]))
    if not periodic:
        ends = (before, backend.parts(state)) if before is not None else None
        result.unsettled = unsettled(q, measure, ends, sweep, result.periods)
    return result, state, t


def unsettled(q: Normalised, measure: Transient | None, ends, sweep: Sweep,
              periods: int) -> dict:
    """Why a point is not periodic, in SI: the periodicity test's measure on the
    tension at s = 0 (the part it judges), the state's parts by how much they still
    move a period (``ends``: their values at the last period's start and end, or None),
    and the periods the transient would still need at its decay rate."""
    scale = float(q.tension_N(1.0))
    out = {"judged": "T max and T min at s = 0, from one period to the next",
           "periods": periods, "tolerance": sweep.periodic_tolerance}
    if measure is None:
        out["periods_to_judge"] = sweep.periods_to_judge
        out["reason"] = (f"too few periods to judge: the test needs 3 x sweep.record_periods "
                         f"+ 1 = {out['periods_to_judge']}")
    else:
        out.update({"change_N": measure.change * scale, "allowed_N": measure.allowed * scale,
                    "decay_per_period": measure.ratio,
                    "remainder_N": None if measure.remainder is None
                    else measure.remainder * scale,
                    "periods_to_settle": measure.periods_to_settle()})
        out["reason"] = ("not decaying" if measure.remainder is None else "decaying too slowly")
    if ends is not None:
        out["moving"] = [{"part": name, "change_per_period": change}
                         for name, change in moving_parts(*ends)]
    return out
