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
