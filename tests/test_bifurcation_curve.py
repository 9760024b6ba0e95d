"""Period-doubling and Neimark-Sacker curves in two parameters
(rawehelix.periodic_orbits.bifurcation_curve), without scenes: the trivial orbit of a
parametrically excited linear system, whose multipliers come from Hill's method
(solvers/harmonic_balance/hill.py), in (f1, eps).

- PD: a damped Mathieu oscillator (5 Hz) excited near twice its frequency: the first
  tongue's boundaries, where a real multiplier passes -1;
- NS: two coupled oscillators (3 and 5 Hz) excited near the sum of their frequencies
  (the combination resonance), where a complex pair leaves the unit circle.

Each traced point is checked against the boundary found independently at its eps: the
monodromy integrated by solve_ivp (rtol 1e-11) and brentq in f1 on its own multipliers."""

import types

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from rawehelix.errors import SolverError
from rawehelix.periodic_orbits import bifurcation_curve as bc
from rawehelix.periodic_orbits.bifurcations import critical
from rawehelix.solvers.harmonic_balance.hill import hill_exponents

SAMPLES = 48  # per period (>= 4H + 1)
H = 8
ZETA = 0.01  # damping ratio of each oscillator


class LinearPeriodic:
    """x'' + 2 zeta W x' + (W^2 + eps cos(2 pi f1 t) B) x = 0: its trivial orbit as a
    periodic-orbit problem (``orbit`` is all the curves ask)."""

    def __init__(self, freqs_Hz, B, eps):
        self.w = 2 * np.pi * np.asarray(freqs_Hz, dtype=float)
        self.B, self.eps = np.asarray(B, dtype=float) * np.outer(self.w, self.w), eps
        self.calls = 0

    def _K(self, t, f1):
        return np.diag(self.w**2) + self.eps * np.cos(2 * np.pi * f1 * t) * self.B

    def orbit(self, X, f1_Hz, steps=None):
        self.calls += 1
        n = self.w.size
        t = np.arange(SAMPLES) / SAMPLES / f1_Hz
        M = np.repeat(np.eye(n)[None], SAMPLES, 0)
        C = np.repeat((2 * ZETA * np.diag(self.w))[None], SAMPLES, 0)
        K = np.array([self._K(tj, f1_Hz) for tj in t])
        mu = hill_exponents(M, C, K, 2 * np.pi * f1_Hz, steps or H).multipliers
        return types.SimpleNamespace(X=np.zeros(2 * n), f1_Hz=f1_Hz, multipliers=mu, steps=steps)

    def monodromy_multipliers(self, f1_Hz):
        """The reference: the monodromy by solve_ivp over one period."""
        n = self.w.size

        def rhs(t, y):
            return np.concatenate([y[n:], -2 * ZETA * self.w * y[n:] - self._K(t, f1_Hz) @ y[:n]])
        cols = [solve_ivp(rhs, (0, 1 / f1_Hz), e, method="DOP853", rtol=1e-11, atol=1e-12).y[:, -1]
                for e in np.eye(2 * n)]
        return np.linalg.eigvals(np.array(cols).T)


SCENES = {  # kind: (frequencies, coupling B / (w w^T), the tongue's middle f1 [Hz])
    "period_doubling": ([5.0], [[1.0]], 10.0),
    "neimark_sacker": ([3.0, 5.0], [[0.0, 1.0], [1.0, 0.0]], 8.0),
}


def _boundary(kind, eps, side):
    """The tongue's boundary at eps on ``side`` (-1 below the middle, +1 above), by brentq
    on the monodromy's multipliers off the positive real axis."""
    freqs, B, middle = SCENES[kind]
    problem = LinearPeriodic(freqs, B, eps)

    def g(f):
        return critical(problem.monodromy_multipliers(f))[0] - 1.0
    outside = middle + side * 0.6
    return brentq(g, middle, outside, xtol=1e-9)


def _first(kind, eps, side, problem):
    return bc.locate(problem, np.zeros(2), _boundary(kind, eps, side) + 3e-3, None, p=eps)


@pytest.mark.parametrize("kind", sorted(SCENES))
def test_a_crossing_is_the_monodromys(kind):
    """At fixed eps regula falsi on Hill's multipliers lands on the solve_ivp boundary
    within 1e-5 Hz (both boundaries of the tongue), from 3 mHz off."""
    freqs, B, _ = SCENES[kind]
    problem = LinearPeriodic(freqs, B, 0.15)
    for side in (-1, 1):
        c = bc.locate(problem, np.zeros(2), _boundary(kind, 0.15, side) + 3e-3, None, p=0.15)
        assert c.kind == kind and c.p == 0.15
        assert c.side == -side  # g rises into the tongue: +1 on its lower boundary
        assert c.f1_Hz == pytest.approx(_boundary(kind, 0.15, side), abs=1e-5)
        assert abs(c.multiplier) == pytest.approx(1.0, abs=1e-6)
        assert (abs(c.multiplier.imag) < 1e-9 and c.multiplier.real < 0) == (kind == "period_doubling")


@pytest.mark.parametrize("kind", [pytest.param(k, marks=pytest.mark.long) if k == "neimark_sacker"
                                  else k for k in sorted(SCENES)])  # NS: 7 s, make test-long
def test_the_curve_in_two_parameters_is_the_monodromys(kind):
    """Traced from eps = 0.12 to 0.20 in natural steps of 0.02 at most, both boundaries
    (the first step halved: 0.02 moves the boundary by about JUMP_HZ): every point
    within 1e-5 Hz of the boundary brentq finds at its eps, and the tongue widens."""
    freqs, B, _ = SCENES[kind]
    for side in (-1, 1):
        first = _first(kind, 0.12, side, LinearPeriodic(freqs, B, 0.12))
        points, why = bc.trace(lambda e: LinearPeriodic(freqs, B, e), first, 0.20, 0.02)
        assert why == "reached the end of the window"
        p = [c.p for c in points]
        assert p[0] == 0.12 and p[-1] == pytest.approx(0.20, abs=1e-12) and np.all(np.diff(p) > 0)
        for c in points:
            assert c.f1_Hz == pytest.approx(_boundary(kind, c.p, side), abs=1e-5)
        assert side * (points[-1].f1_Hz - points[0].f1_Hz) > 0


def test_the_curve_turns_round_the_tongues_tip():
    """Traced down in eps from the lower boundary at 0.15 toward 0 past the damped
    tongue's tip (about eps = 0.04 for zeta = 0.01, where the two PD boundaries meet): the
    local parametrisation turns round the tip (the corrector in eps at fixed f1 there) and
    comes back up the upper boundary to eps = 0.15, where it lands on that boundary within
    1e-5 Hz.  Every point is on the monodromy's boundary (|max |mu| - 1| below 1e-5), and
    below the tip there is none (brentq finds no sign change at eps = 0.03)."""
    freqs, B, _ = SCENES["period_doubling"]
    first = _first("period_doubling", 0.15, -1, LinearPeriodic(freqs, B, 0.15))
    points, why = bc.trace(lambda e: LinearPeriodic(freqs, B, e), first, 0.0, 0.03)
    assert why.startswith("came back to p = 0.15"), why
    assert points[-1].p == 0.15
    assert points[-1].f1_Hz == pytest.approx(_boundary("period_doubling", 0.15, 1), abs=1e-5)
    tip = min(c.p for c in points)
    assert 0.03 < tip < 0.06
    for c in points:
        g = critical(LinearPeriodic(freqs, B, c.p).monodromy_multipliers(c.f1_Hz))[0] - 1.0
        assert abs(g) <= 1e-5, (c.p, c.f1_Hz, g)
    with pytest.raises(ValueError):  # below it no boundary at all: brentq has no sign change
        _boundary("period_doubling", 0.03, -1)


def test_no_crossing_nearby_is_an_error():
    """Far from the tongue (9 Hz at eps = 0.15) there is no zero within JUMP_HZ."""
    freqs, B, _ = SCENES["period_doubling"]
    with pytest.raises(SolverError, match="no crossing"):
        bc.locate(LinearPeriodic(freqs, B, 0.15), np.zeros(2), 9.0, None)


def test_the_other_boundary_is_refused():
    """Asked for a lower boundary (g rising with f1) in a bracket around the upper one:
    refused (a trace's step then halves instead of jumping across a narrow band); from
    inside the tongue next to the upper boundary, the search for a lower one goes down,
    away from it, and finds none within JUMP_HZ."""
    freqs, B, _ = SCENES["period_doubling"]
    upper = _boundary("period_doubling", 0.15, 1)
    problem = LinearPeriodic(freqs, B, 0.15)
    with pytest.raises(SolverError, match="other boundary"):
        bc.locate(problem, np.zeros(2), upper, None, side=1.0, bracket=(upper - 0.01, upper + 0.01))
    with pytest.raises(SolverError, match="no crossing"):
        bc.locate(problem, np.zeros(2), upper - 3e-3, None, side=1.0)
    assert bc.locate(problem, np.zeros(2), upper - 3e-3, None, side=-1.0).f1_Hz == \
        pytest.approx(upper, abs=1e-5)


def _envelope_curves(values, with_crossings, twice=False):
    """studies/analysis/envelope_curves.py on the Mathieu tongue: ticks at ``values`` of eps, those
    in ``with_crossings`` starting from its two PD boundaries (brentq on the monodromy)
    with a bracket around each, as the envelope's branches would (``twice``: each
    boundary met twice, as by a branch that passes the band twice)."""
    from rawehelix.studies.analysis import envelope_curves

    freqs, B, _ = SCENES["period_doubling"]
    found = {e: [_boundary("period_doubling", e, side) for side in (-1, 1)]
             for e in with_crossings}
    starts = [[{"kind": "period_doubling", "f1_Hz": f, "X": np.zeros(2), "resolution": None,
                "bracket_Hz": (f - 0.01, f + 0.02)} for f in found.get(e, [])] * (1 + twice)
              for e in values]
    return envelope_curves.bifurcation_curves(lambda e: LinearPeriodic(freqs, B, e), "eps",
                                              values, starts)


def test_the_envelope_traces_each_crossing_forward_and_back_where_it_is_new():
    """studies/analysis/envelope_curves.py on the Mathieu tongue in (f1, eps), ticks at eps = 0.03
    (below the tip: no PD), 0.10 and 0.15 (two PD each, as a branch would report them):
    the 0.10 crossings go forward and end on 0.15's own within 1e-5 Hz (``check_Hz``);
    one goes back toward 0.03, turns round the tip and comes back to 0.10's other
    crossing (checked), which is then not traced again, nor are 0.15's."""
    from rawehelix.studies.analysis import envelope_curves

    curves = _envelope_curves([0.03, 0.10, 0.15], with_crossings=(0.10, 0.15))
    forward = [c for c in curves if c["to_value"] == 0.15]
    back = [c for c in curves if c["to_value"] == 0.10]
    assert len(curves) == 3 and len(forward) == 2 and len(back) == 1
    for c in forward:
        assert c["from_value"] == 0.10 and abs(c["check_Hz"]) <= 1e-5
    loop = back[0]  # round the tip below 0.10, back to its other boundary
    assert loop["from_value"] == 0.10 and "came back to p = 0.1 " in loop["end"]
    assert abs(loop["check_Hz"]) <= 1e-5
    assert 0.03 < min(p["value"] for p in loop["points"]) < 0.06
    assert envelope_curves.worst_check(curves) <= 1e-5


def test_a_tick_that_stepped_over_the_band_is_passed_through():
    """Ticks at eps = 0.10, 0.125 and 0.15 where the middle one reports no PD (its branch
    stepped over the tongue, as a coarse branch does over a narrow band): the 0.10
    crossings go on through 0.125 to 0.15's own (within 1e-5 Hz), saying so."""
    curves = _envelope_curves([0.10, 0.125, 0.15], with_crossings=(0.10, 0.15))
    assert len(curves) == 2
    twice = _envelope_curves([0.10, 0.125, 0.15], with_crossings=(0.10, 0.15), twice=True)
    assert [c["points"] for c in twice] == [c["points"] for c in curves]  # traced once each
    for c in curves:
        assert (c["from_value"], c["to_value"]) == (0.10, 0.15)
        assert abs(c["check_Hz"]) <= 1e-5
        assert "eps = 0.125 has no period-doubling or Neimark-Sacker near" in c["end"]
        assert any(p["value"] == 0.125 for p in c["points"])
