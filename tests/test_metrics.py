"""Time-series metrics (studies.analysis.metrics) on synthetic signals with known answers.

A piecewise-linear signal is reproduced exactly by the linear interpolation
that locates the last exit from the band: its settling time is exact at any
sampling interval, not rounded up to the next sample.
"""

import numpy as np
import pytest

from rawehelix.studies.analysis import metrics


def ramps(t, target, ends):
    """One column per end time T: target * t / T up to T, then the target."""
    return np.column_stack([target * np.minimum(t / T, 1.0) for T in ends])


@pytest.mark.parametrize("dt", [0.1, 0.03, 0.007])
def test_settling_time_of_ramps_is_exact(dt):
    """Three spins ramping to 120 rpm by 1, 2 and 3 s: the slowest enters the
    2 % band at 0.98 * 3 s = 2.94 s, between samples for every dt here."""
    t = np.arange(0.0, 5.0 + dt / 2, dt)
    assert metrics.settling_time(t, ramps(t, 120.0, (1.0, 2.0, 3.0)), 120.0) \
        == pytest.approx(0.98 * 3.0, rel=1e-12)


def test_settling_time_from_above_and_overshoot():
    """From 1.5 x the target down to it by t = 1 s: the band (2 %) is entered at
    (1.5 - 1.02) / 0.5 = 0.96 s; the overshoot is 0.5 x the target."""
    t = np.linspace(0.0, 2.0, 11)
    v = 100.0 * (1.5 - 0.5 * np.minimum(t, 1.0))
    assert metrics.settling_time(t, v, 100.0) == pytest.approx(0.96, rel=1e-12)
    assert metrics.overshoot(v, 100.0) == pytest.approx(50.0)
    assert metrics.overshoot(ramps(t, 100.0, (1.0,)), 120.0) == pytest.approx(-20.0)


def test_settling_time_band_and_edge_cases():
    t = np.linspace(0.0, 1.0, 5)
    inside = np.full((5, 3), 101.0)
    assert metrics.settling_time(t, inside, 100.0) == 0.0  # never outside: from the start
    assert metrics.settling_time(t, inside, 100.0, band=0.005) is None  # ends outside
    assert metrics.settling_time(t, inside, 0.0) is None  # no band about 0
    assert metrics.settling_time([], np.zeros((0, 3)), 100.0) is None
    assert metrics.SETTLING_BAND == 0.02
