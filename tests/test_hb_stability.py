"""Harmonic balance's guarded stability step (issue 46, solvers/harmonic_balance/stability.py):
its rules, and on the HB s-curve at N = 2 the verdict of every carried point against a
full Hill solve at that point, and the folds against Hill at every point."""

import numpy as np
import pytest

import rawehelix as rh
from rawehelix.solvers.harmonic_balance.problem import HarmonicBalance
from rawehelix.solvers.harmonic_balance.stability import (EDGE, EVERY_POINT, FOLD_GUARD,
                                                          GUARDED, STRIDE)

INSIDE = np.array([0.9 + 0.3j, 0.9 - 0.3j, 0.5])  # every multiplier well inside the circle


@pytest.mark.parametrize("last, since, event, due", [
    (None, 0, False, True),  # a branch's first point
    (INSIDE, 1, True, True),  # a fold just passed, the window's end, a probe
    (INSIDE, STRIDE, False, True),  # the stride
    (INSIDE, STRIDE - 1, False, False),
    (np.array([1.0 + FOLD_GUARD / 2, 0.5]), 1, False, True),  # a fold near
    (np.array([1.0 - FOLD_GUARD / 2, 0.5]), 1, False, True),
    (np.array([1.3, 0.5]), 1, False, False),  # a saddle's multiplier, no fold near
    (np.array([-(1.0 - EDGE / 2), 0.5]), 1, False, True),  # a period doubling near
    (np.array([(1.0 - EDGE / 2) * np.exp(2j), 0.5]), 1, False, True),  # a Neimark-Sacker
])
def test_hill_is_due_where_the_verdict_can_change(last, since, event, due):
    assert GUARDED.due(last, since, event) == due
    assert EVERY_POINT.due(last, since, event)


@pytest.fixture(scope="module")
def curves():
    """The s-curve from 11.5 Hz up through both folds to 12.9 Hz at N = 2, traced with
    Hill at every point and with the guarded step."""
    from rawehelix.studies.orbits import branch
    out = {}
    for step in (EVERY_POINT, GUARDED):
        hb = HarmonicBalance(rh.load_scene("mobile_end", elements=2, degree=3), stability=step)
        traced = branch(hb)
        traced.trace(hb.orbit(hb.X_stationary, 11.5), 12.9)
        out[step.name] = (hb, traced)
    return out


def test_carried_points_keep_the_verdict_of_their_own_hill_solve(curves):
    hb, traced = curves["guarded"]
    carried = [p for p in traced.points if "hill_f1_Hz" in p.accuracy]
    assert 0 < len(carried) < len(traced.points)
    assert {p.stable for p in traced.points} == {True, False}
    for p in carried:
        own = hb.multipliers(p.X, p.f1_Hz, p.steps)
        assert (abs(own[0]) < 1.0) == p.stable, p.f1_Hz


def test_the_folds_are_those_of_hill_at_every_point(curves):
    folds = {k: sorted(f["f1_Hz"] for f in b.folds) for k, (_, b) in curves.items()}
    assert len(folds["guarded"]) == 2
    assert folds["guarded"] == pytest.approx(folds["every_point"], abs=1e-3)
