"""Metrics of a time series: settling time and overshoot (numpy only).

Used by ``rawehelix simulate`` (its summary) and ``rawehelix converge`` (the
``settling_time`` and ``spin_overshoot`` quantities of Sec. 5.2), so that
both report the same number for the same run.
"""

from __future__ import annotations

import numpy as np

#: the settling band: within 2 % of the target (Sec. 5.2, Fig. 6)
SETTLING_BAND = 0.02


def settling_time(t_s, values, target, band: float = SETTLING_BAND) -> float | None:
    """The time [s] after which every column of ``values`` stays within
    ``band * |target|`` of ``target``.

    The last exit from the band is located by linear interpolation between
    the two samples around it (of the largest deviation of the columns), so
    the result does not move with the sampling interval.  ``t_s[0]`` if the
    series never leaves the band; None if it ends outside it (not settled
    within the record), if it is empty, or if ``target`` is 0 (no band).

    ``values``: one column per signal (the spins at s = 0, L0/2 and L0), or a
    1-D array for one signal.
    """
    t = np.asarray(t_s, dtype=float)
    v = np.asarray(values, dtype=float)
    if target == 0 or len(t) == 0:
        return None
    if v.ndim == 1:
        v = v[:, None]
    dev = np.max(np.abs(v - target), axis=1) - band * abs(target)  # > 0: outside
    outside = np.nonzero(dev > 0)[0]
    if len(outside) == 0:
        return float(t[0])
    k = outside[-1]
    if k + 1 >= len(t):
        return None
    return float(t[k] + (t[k + 1] - t[k]) * dev[k] / (dev[k] - dev[k + 1]))


def overshoot(values, target) -> float:
    """The largest value above ``target``: max(values) - target (negative when
    the signal stays below the target)."""
    return float(np.max(values) - target)


def run_statistics(rows, columns, slack: float | None) -> dict:
    """The run's statistics over its outputs (a seed study's quantities, issue 44): the
    mean generator power (with a machine), the largest tension at each end, and
    ``slack``, the fraction of the limits block's times at which any member was slack
    (structure_limits.Tracker.slack_time_fraction)."""
    col = {name: i for i, name in enumerate(columns)}
    power = rows[:, col["power_W"]] if "power_W" in col else None
    return {"power_mean_W": None if power is None else float(np.mean(power)),
            "tension_s0_max_N": float(rows[:, 5].max()), "tension_L0_max_N": float(rows[:, 6].max()),
            "slack_time_fraction": slack}
