"""The cheaper time step (issue 12, docs/speed.md): the quadrature rule and the
reused Jacobian leave the verified numbers where they were."""

import math

import pytest
from mpi4py import MPI

from rawehelix.families import VIBRATIONS
from rawehelix.forms import rod
from rawehelix.solvers.forced import FEBackend
from rawehelix.solvers.modal import ModalSolver
from rawehelix.solvers.periodic import periodic_response
from rawehelix.solvers.stationary import StationarySolver
from rawehelix.studies import scene


def test_quadrature_rule_is_3p():
    assert [rod.quadrature_degree(p) for p in (2, 3, 4)] == [6, 9, 12]
    assert rod.quadrature_degree(3, -1) is None and rod.quadrature_degree(3, 5) == 5


def _table2(quadrature: int, elements=4):
    return scene.load("stationary_table2", elements=elements, degree=3).replace(
        discretisation={"quadrature_degree": quadrature})


def _tension0(params):
    return params.normalised().tension_N(StationarySolver(params, MPI.COMM_SELF).solve().tension[0])


def _lowest_eigenvalue(params):
    modes = ModalSolver.from_stationary(params, MPI.COMM_SELF).solve(
        keep_vectors=False, require_families=False)
    return min(abs(complex(m.eigenvalue)) for m in modes if m.family in VIBRATIONS)


def test_quadrature_rule_keeps_tension_and_eigenvalue():
    """The rule 3p against UFL's estimate (14 and 20 at p = 3): T(0) and the
    slowest vibration agree to 1e-9 (measured 5e-13 at N = 16, docs/speed.md);
    a degree too low for the inertia term (4 < 2p) moves them by far more."""
    rule, ufl_estimate, low = (_table2(q) for q in (0, -1, 4))
    T_rule, T_ufl, T_low = (_tension0(p) for p in (rule, ufl_estimate, low))
    assert T_rule == pytest.approx(T_ufl, rel=1e-9)
    assert abs(T_low - T_ufl) > 1e-7 * T_ufl
    lam_rule, lam_ufl, lam_low = (_lowest_eigenvalue(p) for p in (rule, ufl_estimate, low))
    assert lam_rule == pytest.approx(lam_ufl, rel=1e-9)
    assert abs(lam_low - lam_ufl) > 1e-7 * lam_ufl


TINY = {"lead_in_s": 0.2, "min_periods": 2, "max_periods": 3, "record_periods": 1,
        "periodic_tolerance": 5e-2}


def _tension_max(options):
    params = scene.load("mobile_end", elements=2, degree=2).replace(sweep=TINY, time={"dt_s": 2e-3})
    backend = FEBackend(params, MPI.COMM_SELF, options=options)
    result, _, _ = periodic_response(backend, params.normalised(), 8.0, backend.stationary(), 0.0,
                                     params.sweep, lead_in=True)
    return result, backend.solver


def test_reused_jacobian_gives_the_same_tension_max():
    """Modified Newton (the sweep's default) against full Newton at tight
    tolerance: the same T max at 8 Hz to 5e-5 (measured 1.4e-5; 1.7e-5 at N = 8, p = 3,
    10 Hz, docs/speed.md), with far fewer Jacobians than
    steps, and more (cheaper) Newton iterations."""
    full, full_solver = _tension_max(FEBackend.FULL_NEWTON)
    reused, solver = _tension_max(None)  # the sweep's default
    assert reused.periods == full.periods
    assert reused.tension_max_N == pytest.approx(full.tension_max_N, rel=5e-5)
    assert reused.tension_min_N == pytest.approx(full.tension_min_N, rel=5e-5)
    assert solver.convergence.rebuilds < solver.steps / 10
    assert solver.newton_iterations > full_solver.newton_iterations
    assert math.isfinite(reused.tension_max_N) and not hasattr(full_solver.convergence, "rebuilds")
