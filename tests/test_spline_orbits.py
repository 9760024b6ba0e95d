"""Periodic orbits of the paper's spline-Galerkin scheme (issue 13, the spline backend):
the monodromy of the variational equations against finite differences of the flow,
and the orbit against the brute-force periodic response of the same scheme."""

import numpy as np
import pytest

import rawehelix as rh
from rawehelix.solvers.periodic import periodic_response
from rawehelix.references.spline_galerkin.forced import SplineBackend
from rawehelix.references.spline_galerkin.orbits import SplineMap

#: 75 s in all (a shared fixture): make test's 12-minute budget (2026-12-04); make test-long
pytestmark = pytest.mark.long

# the torque ramp (69) short, so that the brute-force run sees the orbits' steady torque
SCENE = {"torque.rise_time_s": 0.05, "sweep.periodic_tolerance": 1e-6, "sweep.lead_in_s": 1.0}


@pytest.fixture(scope="module")
def spline_map():
    return SplineMap(rh.load_scene("mobile_end", scheme="spline", elements=2, overrides=SCENE))


@pytest.fixture(scope="module")
def orbit(spline_map):
    return spline_map.orbit(spline_map.X_stationary, 10.0, lead_in=5)


def test_monodromy_equals_finite_differences_of_the_flow(spline_map, orbit):
    """Gauss-Legendre on the variational equations along the dense output
    against central differences of the Radau flow (tolerance 1e-10) in two
    random directions; the monodromy's stated error is 1e-5."""
    m = spline_map
    _, _, Phi = m.period(orbit.X, 10.0, tangent=True)
    rng = np.random.default_rng(2)
    for _ in range(2):
        d = rng.standard_normal(orbit.X.size)
        d /= np.linalg.norm(d)
        eps = 1e-5
        fd = (m.period(orbit.X + eps * d, 10.0)[0] - m.period(orbit.X - eps * d, 10.0)[0]) / (2 * eps)
        assert np.linalg.norm(Phi @ d - fd) <= 1e-5 * np.linalg.norm(fd)


def test_spline_orbit_is_the_brute_force_periodic_response(spline_map, orbit):
    """At 10 Hz, N = 2: the shooting orbit's T max and T min equal the
    brute-force spline integration's (Radau, run until periodic to 1e-6) to
    1e-3, and the orbit is a fixed point of the period map to the shooting
    tolerance; m0's elimination leaves no multiplier on the unit circle."""
    assert orbit.residual <= 1e-7
    params = spline_map.params
    backend = SplineBackend(params.normalised(), 2)
    point, _, _ = periodic_response(backend, params.normalised(), 10.0, backend.stationary(), 0.0,
                                    params.sweep, True)
    assert point.periodic
    assert orbit.tension_max_N == pytest.approx(point.tension_max_N, rel=1e-3)
    assert orbit.tension_min_N == pytest.approx(point.tension_min_N, rel=1e-3)
    assert orbit.stable and 0.5 < orbit.max_multiplier < 0.99
    assert orbit.multipliers.size == spline_map.size - 1


def test_refuses_without_controller():
    from rawehelix.solvers.snes import SolverError
    with pytest.raises(SolverError, match="controller"):
        SplineMap(rh.load_scene("mobile_end", scheme="spline", elements=2,
                                overrides={**SCENE, "controller.k1": 0.0}))


@pytest.mark.parametrize("scheme, kind", [("spline", "SplineMap"), ("fe", "AlphaMap")])
def test_the_orbits_command_takes_the_scenes_scheme(scheme, kind):
    from rawehelix.studies.orbits import problem
    params = rh.load_scene("mobile_end", scheme=scheme, elements=2, overrides=SCENE)
    assert type(problem(params)).__name__ == kind



@pytest.mark.parametrize("scheme", ["spline", "fe"])
def test_each_scheme_is_a_periodic_orbit_problem(scheme, spline_map, orbit):
    """The shooting of each scheme through the periodic-orbit interface
    (periodic_orbits/problem.py; the spline at N = 2, the FE at N = 4, p = 3): at
    the 10 Hz orbit G is within the shooting's tolerance; the orbit at 10.05 Hz,
    solved by the problem's own Newton, moves X as the interface's two Jacobians
    predict (dX/df1 = -G_X^-1 G_f1, to the step's second order: 2e-2 of the
    change); the multipliers and the samples of one period from X are the
    orbit's (the same periods: to round-off)."""
    from rawehelix.periodic_orbits.problem import PeriodicOrbitProblem
    from rawehelix.solvers.orbits import AlphaMap

    m = spline_map
    if scheme == "fe":
        m = AlphaMap(rh.load_scene("mobile_end", elements=4, degree=3, overrides=SCENE))
        orbit = m.orbit(m.X_stationary, 10.0, lead_in=5)
    assert isinstance(m, PeriodicOrbitProblem) and m.carried.size == 0
    steps = m.resolution(10.0)
    G, samples, J = m.residual(orbit.X, 10.0, jacobian=True, resolution=steps)
    assert m.norm(G, orbit.X) <= 1e-6
    gf = m.residual_f1(orbit.X, 10.0, steps, G)
    df = 0.05
    moved = m.orbit(orbit.X, 10.0 + df, steps=steps)
    predicted = -np.linalg.solve(J, gf) * df
    change = moved.X - orbit.X
    assert np.linalg.norm(predicted - change) <= 2e-2 * np.linalg.norm(change)
    assert np.allclose(m.multipliers(orbit.X, 10.0), orbit.multipliers, rtol=1e-8, atol=1e-10)
    T = m.q.tension_N(m.samples(orbit.X, 10.0))
    assert T.max() == pytest.approx(orbit.tension_max_N, rel=1e-10)
    assert T.min() == pytest.approx(orbit.tension_min_N, rel=1e-10)
