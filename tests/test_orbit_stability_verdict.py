"""An orbit's stability verdict at the unit circle (the tester's D2): an undamped orbit's
multipliers sit on the circle to rounding and are neutral, not unstable; a multiplier
outside it by more than the tolerance is unstable, and the bifurcation counts agree."""

import numpy as np
import pytest

from rawehelix.periodic_orbits.bifurcations import _unstable
from rawehelix.periodic_orbits.problem import UNIT_CIRCLE_TOL, Orbit


def _orbit(mu):
    mu = np.asarray(mu, dtype=complex)
    return Orbit(f1_Hz=1.0, X=np.zeros(3), delta=0.0, tension_max_N=1.0, tension_min_N=1.0,
                 multipliers=mu[np.argsort(-np.abs(mu))], newton_iterations=1, residual=0.0,
                 steps=1, wall_s=0.0)


@pytest.mark.parametrize("mu, stable", [
    ([1.0 + 4e-16, 0.5], True),  # undamped: on the circle to rounding
    ([np.exp(0.3j) * (1 + 1e-12), np.exp(-0.3j) * (1 + 1e-12)], True),
    ([0.999, -0.2], True),
    ([1.0 + 10 * UNIT_CIRCLE_TOL, 0.5], False),
    ([-1.001, 0.3], False),
])
def test_stable_is_no_multiplier_outside_the_circle(mu, stable):
    orbit = _orbit(mu)
    assert orbit.stable is stable
    assert orbit.entry()["stable"] is stable
    # the bifurcation counts see the same circle: no unstable multiplier iff stable
    assert (sum(_unstable(orbit.multipliers).values()) == 0) is stable


def test_a_crawling_shooting_branch_is_told_to_try_hb():
    """The tester's D3: shooting on an undamped helix stepped about 0.001 Hz a point and
    nothing suggested harmonic balance; the report now does, for a method that steps in
    time only, and not for a branch with ordinary steps."""
    from rawehelix.studies.present import orbits_report

    from rawehelix.studies.orbit_method import HB, SHOOTING

    def branch(step, points=40):
        return [{"f1_Hz": 10.0 - k * step} for k in range(points)]
    hint = orbits_report.crawl_hint(branch(0.001), SHOOTING.steps_in_time)
    assert hint and "median 0.001 Hz over 40 points" in hint and "--method hb" in hint
    assert orbits_report.crawl_hint(branch(0.001), HB.steps_in_time) is None  # already HB
    assert orbits_report.crawl_hint(branch(0.05), True) is None  # ordinary steps
    assert orbits_report.crawl_hint(branch(0.001, points=5), True) is None  # short
