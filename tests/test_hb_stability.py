"""Harmonic balance's guarded stability step (issue 46, solvers/harmonic_balance/stability.py):
its rules against multipliers built in closed form (mu = exp(lambda / f1)), and on the
HB s-curve at N = 2 the verdict of every carried point against a full Hill solve at that
point, Hill forced where the fold test function changes sign, and the folds against Hill
at every point."""

import numpy as np
import pytest

import rawehelix as rh
from rawehelix.solvers.harmonic_balance.problem import HarmonicBalance
from rawehelix.solvers.harmonic_balance.stability import (
    D_MAX, EVERY_POINT, GUARDED, K_TOP, SAFETY, HillPoint, Track, log_moduli)

F1 = 10.0  # Hz
X7 = np.zeros(7)  # one unknown at H = 3


def _mu(v, f1=F1):
    """Multipliers of ln|mu| = v (a complex pair each, Im lambda = 3 /s) and a saddle's
    real multiplier 0.5 (no fold near)."""
    lam = f1 * np.asarray(v, dtype=complex) + 3j
    return np.append(np.exp(np.concatenate([lam, lam.conj()]) / f1), 0.5)


def _track(v, secants=(), since=1):
    return Track(HillPoint(_mu(v), F1, X7, 3), since=since,
                 secants=tuple(np.asarray(s, dtype=float) for s in secants))


def test_log_moduli_are_the_distances_to_the_circle():
    assert log_moduli(_mu([-0.01, -0.04])) == pytest.approx([-0.01, -0.01, -0.04])
    assert log_moduli(np.array([1.2, 0.5])).tolist() == [-np.inf] * K_TOP  # fold kind only


STILL = [0.0] * K_TOP


@pytest.mark.parametrize("track, distance, event, due", [
    (None, 0.0, False, True),  # a branch's first point
    (_track([-0.01], [STILL]), 0.01, True, True),  # a fold just passed, the end, a probe
    (_track([-0.01]), 0.99 * D_MAX, False, False),  # one solve yet: the floor only
    (_track([-0.01], [STILL]), D_MAX, False, True),  # the floor
    # ln|mu| = -0.01 moving to the circle at 0.02 a unit: its gap 0.01 - 0.02 d against
    # SAFETY x 0.02 d, reached at d = 0.01 / (0.02 (1 + SAFETY))
    (_track([-0.01], [[0.02] * K_TOP]), 0.99 * 0.5 / (1 + SAFETY), False, False),
    (_track([-0.01], [[0.02] * K_TOP]), 1.01 * 0.5 / (1 + SAFETY), False, True),
    # moving away from it: reached at d = 0.01 / (0.02 (SAFETY - 1))
    (_track([-0.01], [[-0.02] * K_TOP]), 0.99 * min(0.5 / (SAFETY - 1), D_MAX), False, False),
    (_track([-0.01], [[-0.02] * K_TOP, [0.02] * K_TOP]), 1.01 * 0.5 / (1 + SAFETY), False,
     True),  # the older secant moved it to the circle: the worse kept
    (_track([+0.01], [[-0.02] * K_TOP]), 1.01 * 0.5 / (1 + SAFETY), False, True),  # outside
])
def test_hill_is_due_where_a_multiplier_can_reach_the_circle(track, distance, event, due):
    assert GUARDED.due(track, distance, event, False) == due
    assert EVERY_POINT.due(track, distance, event, False)


def test_hill_is_due_where_the_next_step_may_be_natural():
    track = _track([-0.01], [STILL])
    assert not GUARDED.due(track, 0.01, False, False)
    assert GUARDED.due(track, 0.01, False, True)


def test_the_secants_of_the_last_three_solves():
    track = _track([-0.01, -0.05], since=4)
    track.hill(HillPoint(_mu([-0.01, -0.03]), F1, X7, 3), distance=0.5)
    # sorted (-0.01, -0.01, -0.05) -> (-0.01, -0.01, -0.03): secant (0, 0, 0.04)
    assert track.secants[0] == pytest.approx([0.0, 0.0, 0.04]) and track.since == 0
    track.hill(HillPoint(_mu([-0.02, -0.03]), F1, X7, 3), distance=0.25)
    assert np.array(track.secants).ravel() == pytest.approx([-0.04, -0.04, 0.0, 0.0, 0.0, 0.04])
    gap, drift = track.predicted(0.1)  # at (-0.02, -0.02, -0.03)
    assert gap == pytest.approx([0.02 - 0.0, 0.02 - 0.0, 0.03 - 0.004])
    assert drift == pytest.approx([0.004, 0.004, 0.004])
    with pytest.raises(ValueError, match="Hill point"):
        HillPoint(np.ones(2), F1, np.zeros(6), 3)


def test_distance_is_relative_in_x_and_f1():
    track = Track(HillPoint(_mu([-0.01]), F1, np.arange(7.0), 3))
    embed = lambda X, H: np.pad(X, (0, 2 * H + 1 - X.size))  # noqa: E731 (one unknown)
    assert track.distance(np.arange(7.0), 1.2 * F1, 3, embed) == pytest.approx(0.2)
    X = np.arange(11.0)  # at H = 5: 7, 8, 9, 10 more
    expected = np.hypot(np.linalg.norm([7.0, 8.0, 9.0, 10.0]) / np.linalg.norm(np.arange(7.0)),
                        0.2)
    assert track.distance(X, 1.2 * F1, 5, embed) == pytest.approx(expected)


@pytest.fixture(scope="module")
def curves():
    """The s-curve from 11.5 Hz up through both folds to 12.9 Hz at N = 2, traced with
    Hill at every point and with the guarded step (each stability call's event and
    whether it solved Hill recorded)."""
    from rawehelix.studies.orbits import branch
    out = {}
    for step in (EVERY_POINT, GUARDED):
        hb = HarmonicBalance(rh.load_scene("mobile_end", elements=2, degree=3), stability=step)
        calls, stability = [], hb.stability

        def recorded(orbit, event, stability=stability, calls=calls):
            stability(orbit, event)
            calls.append((event, "hill_f1_Hz" not in orbit.accuracy))
        hb.stability = recorded
        traced = branch(hb)
        traced.trace(hb.orbit(hb.X_stationary, 11.5), 12.9)
        out[step.name] = (hb, traced, calls)
    return out


def test_carried_points_keep_the_verdict_of_their_own_hill_solve(curves):
    hb, traced, _ = curves["guarded"]
    carried = [p for p in traced.points if "hill_f1_Hz" in p.accuracy]
    assert 0 < len(carried) < len(traced.points)
    assert {p.stable for p in traced.points} == {True, False}
    for p in carried:
        own = hb.multipliers(p.X, p.f1_Hz, p.steps)
        assert (abs(own[0]) < 1.0) == p.stable, p.f1_Hz


def test_hill_is_forced_where_the_fold_test_function_changes_sign(curves):
    _, traced, calls = curves["guarded"]
    events = [hill for event, hill in calls if event]
    assert len(events) >= 3  # two folds (df1/ds through zero) and the window's end
    assert all(events)


def test_the_folds_are_those_of_hill_at_every_point(curves):
    folds = {k: sorted(f["f1_Hz"] for f in b.folds) for k, (_, b, _) in curves.items()}
    assert len(folds["guarded"]) == 2
    assert folds["guarded"] == pytest.approx(folds["every_point"], abs=1e-3)
