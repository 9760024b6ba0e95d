"""The sweep's periodicity test (solvers/periodic.py, ``settled``; issue 13) on
closed-form transients: the per-period maximum and minimum of T are the
periodic state's plus a transient decaying by a multiplier r a period, so what
remains after period k is known exactly.  The test must never accept a period
whose remainder exceeds its tolerance, and must accept soon after it falls
below (within the three blocks the test looks at, and a factor 1 / (1 - r))."""

import math

import numpy as np
import pytest

from rawehelix.solvers.periodic import ROUNDOFF, settled

T_MEAN, OSCILLATION = 75.25, 0.04  # N: the 1 Hz point of Fig. 8 (oscillation 5e-4 of T)
TOL, BLOCK = 1e-3, 4  # the sweep's defaults: periodic_tolerance, record_periods


def _transient(r, theta, periods, amplitude=0.5 * OSCILLATION):
    """Per-period maximum, minimum and mean of T with the transient
    amplitude r^k cos(theta k) on the maximum and half of it on the minimum."""
    k = np.arange(periods)
    x = amplitude * r ** k * np.cos(theta * k)
    hi = T_MEAN + OSCILLATION / 2 + x
    lo = T_MEAN - OSCILLATION / 2 - 0.5 * x
    return hi, lo, 0.5 * (hi + lo), amplitude * r ** k


def _first_settled(hi, lo, mean):
    for k in range(1, len(hi) + 1):
        if settled(hi[:k], lo[:k], mean[:k], TOL, BLOCK):
            return k
    return None


@pytest.mark.parametrize("theta", [0.0, 0.4, 2.0, math.pi])  # monotone, slow and fast beats, period 2
@pytest.mark.parametrize("r", [0.5, 0.9, 0.964, 0.99])
def test_a_geometric_transient_is_accepted_only_once_its_remainder_is_within_tolerance(r, theta):
    n = 3000
    hi, lo, mean, envelope = _transient(r, theta, n)
    k = _first_settled(hi, lo, mean)
    assert k is not None
    remainder = envelope[k - 1]  # of the maximum; the minimum's is half of it
    assert remainder <= TOL * OSCILLATION
    # not much later than needed: the first period whose remainder is within
    # tolerance, plus the three blocks and the bound's 1 / (1 - r)
    due = int(np.argmax(envelope <= TOL * OSCILLATION))
    slack = 3 * BLOCK + math.log(2.0 / (1.0 - r) / max(abs(math.sin(theta / 2)), 1e-3)) / -math.log(r)
    assert k - 1 <= due + slack + 1


def test_a_small_change_with_a_large_remainder_is_not_settled():
    """The former test (each change within 1e-3 of the oscillation, four in a
    row) accepted this: r = 0.964, changes 0.9e-3 of the oscillation, and 2.4e-2
    of it still to go."""
    r = 0.964
    hi, lo, mean, envelope = _transient(r, 0.0, 400)
    change = np.abs(np.diff(hi)) / OSCILLATION
    k = int(np.argmax(change < 1e-3)) + 2  # the first period after a change below 1e-3
    k += 3 * BLOCK  # with the blocks the new test looks at
    assert envelope[k - 1] > 10 * TOL * OSCILLATION
    assert not settled(hi[:k], lo[:k], mean[:k], TOL, BLOCK)


def test_changes_that_do_not_shrink_are_not_settled_unless_round_off():
    """Noise at 1e-6 of T (the sweep's modified Newton at rtol 1e-6, 1 Hz)
    never settles; noise at the round-off floor does."""
    rng = np.random.default_rng(1)
    for level, expected in ((1e-6, False), (0.5 * ROUNDOFF, True)):
        noise = level * T_MEAN * rng.standard_normal((2, 200))
        hi = T_MEAN + OSCILLATION / 2 + noise[0]
        lo = T_MEAN - OSCILLATION / 2 + noise[1]
        mean = 0.5 * (hi + lo)
        assert (_first_settled(hi, lo, mean) is not None) is expected


def test_a_sustained_beat_is_not_settled():
    k = np.arange(400)
    hi = T_MEAN + OSCILLATION / 2 + 0.01 * OSCILLATION * np.cos(2 * math.pi * k / 37)
    lo = T_MEAN - OSCILLATION / 2 + np.zeros_like(hi)
    assert _first_settled(hi, lo, 0.5 * (hi + lo)) is None
