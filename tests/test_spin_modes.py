"""The linearisation about a relative equilibrium (solvers/spin_modes.py) against
closed forms: a shaft with a tip inertia, and the rigid shaft's real root."""

import functools
import math

import pytest
import scipy.optimize
from mpi4py import MPI

from rawehelix.parameters.checks import ParameterError
from rawehelix.solvers.spin_modes import (EndLoads, RelativeEquilibrium, SpinModalSolver,
                                          stability, stability_at)
from rawehelix.solvers.stationary import StationarySolver
from rawehelix.studies import scene


@functools.lru_cache
def solver_at(N: int, gravity_drag: bool = True):
    """(solver, stationary state) of Table 2 at N elements, p = 3."""
    p = scene.load("stationary_table2", elements=N, degree=3)
    if not gravity_drag:
        p = p.replace(model={"gravity": False, "drag": False})
    stationary = StationarySolver(p, MPI.COMM_SELF)
    result = stationary.solve()
    solver_at.stationary[N, gravity_drag] = stationary
    return SpinModalSolver(p, MPI.COMM_SELF, rod=stationary.rod), result.state


solver_at.stationary = {}


def rod_inertia(params) -> float:
    """J_rod = 2 M EI / EA [kg m^2]: the polar inertia 2 rho I = 2 M EI / (EA L0) (Eq. 27) x L0."""
    h = params.helix
    return 2 * h.mass_kg * h.EI_Nm2 / h.EA_N


def tip_inertia_frequencies_Hz(params, J_tip: float, count: int) -> list[float]:
    """A uniform shaft fixed at s = 0 with a tip inertia J_tip at s = L: the roots of
    beta L tan(beta L) = J_rod / J_tip (scipy), omega = beta sqrt(GJ / rho I_p)."""
    h = params.helix
    ratio = rod_inertia(params) / J_tip
    roots = [scipy.optimize.brentq(lambda x: x * math.tan(x) - ratio, n * math.pi + 1e-12,
                                   n * math.pi + math.pi / 2 - 1e-12) for n in range(count)]
    wave_speed = math.sqrt(h.GJ_Nm2 * h.length_m / rod_inertia(params))  # [m/s]
    return [wave_speed * b / h.length_m / (2 * math.pi) for b in roots]


#: the paper's law's k1 (Eq. 40) that holds the ground's twist: its compliance 1/k1
#: moves the first frequency by 5e-9 (measured at N = 8, 16)
K1_FIXED = 1e8


def torsional_errors(N: int, J_tip: float, count: int = 3) -> list[float]:
    solver, state = solver_at(N, gravity_drag=False)
    solver.linearise_at(RelativeEquilibrium(state, 0.0, EndLoads(rotor_inertia_kgm2=J_tip,
                                                                 k1=K1_FIXED)))
    modes = [m for m in solver.solve(per_family=count, keep_vectors=False)
             if m.family == "torsional"][:count]
    exact = tip_inertia_frequencies_Hz(solver.params, J_tip, count)
    return [abs(m.eigenvalue.imag) / (2 * math.pi * solver.q.t_scale) / f - 1
            for m, f in zip(modes, exact)]


def test_twist_family_equals_a_shaft_with_a_tip_inertia():
    """Solid section, gravity and drag off (a straight rod): the twist family with the
    rotor's inertia lumped at the top and the ground held (k1 = 1e8) is the shaft of
    beta L tan(beta L) = J_rod / J_tip.  Measured (J_tip = 5 J_rod, p = 3), third mode:
    6.7e-3 (N = 2), 6.9e-5 (4), 1.2e-6 (8), 8.5e-9 (16): order 6 = 2p."""
    J_tip = 5 * rod_inertia(solver_at(8, False)[0].params)
    coarse, fine = torsional_errors(4, J_tip), torsional_errors(8, J_tip)
    assert max(abs(e) for e in fine) < 2e-6, fine
    assert abs(coarse[2]) / abs(fine[2]) > 30, (coarse, fine)  # observed 60: p = 3, 2p = 6


@pytest.mark.parametrize("dQ, dtau", [(0.05, 0.01), (0.01, 0.05)])
def test_stability_follows_the_net_damping(dQ, dtau):
    """The rigid shaft's real root lambda = (dQ/dOmega - dtau/dOmega) / (J_tip + J_rod):
    positive (unstable) when the rotor's torque rises faster with the speed than the
    generator's.  Within 5e-4 (measured 1.9e-4: the shaft's flexibility, lambda / omega_1
    = 0.007)."""
    solver, state = solver_at(4)
    J_tip = 0.1
    point = RelativeEquilibrium(state, 12.0, EndLoads(rotor_inertia_kgm2=J_tip,
                                                      rotor_dtorque_domega_Nms=dQ,
                                                      generator_dtorque_domega_Nms=dtau))
    rigid = (dQ - dtau) / (J_tip + rod_inertia(solver.params))  # [1/s]
    stable, growth = stability(point, solver)
    assert stable == (rigid < 0)
    # the same from the stationary solver that found the state (i43-operate's way)
    assert stability_at(solver_at.stationary[4, True], state, 12.0, point.loads) == \
        pytest.approx((stable, growth), rel=1e-9, abs=1e-12)
    modes = solver.solve(per_family=2, keep_vectors=False, require_families=False)
    real = [m.eigenvalue.real / solver.q.t_scale for m in modes if m.eigenvalue.imag == 0
            and abs(m.eigenvalue) > 1e-6]
    assert min(abs(r / rigid - 1) for r in real) < 5e-4, (real, rigid)
    if rigid > 0:
        assert growth >= rigid * (1 - 5e-4)


def test_end_loads_refuse_what_they_cannot_be():
    with pytest.raises(ParameterError, match="rotor_inertia_kgm2"):
        EndLoads(rotor_inertia_kgm2=-1.0)
    with pytest.raises(ParameterError, match="must be finite"):
        EndLoads(generator_dtorque_domega_Nms=math.nan)


class _Rotor:  # the operation.rotor.RotorLaw names the linearisation reads (a stand-in)
    spin_inertia_kgm2 = 2.5

    @staticmethod
    def dtorque_domega(omega, v_n, rho):
        return -0.5 * rho * v_n * omega


class _Generator:
    def __init__(self, holds):
        self.holds_speed = 12.0 if holds else None

    @staticmethod
    def dtorque_domega(omega):
        return 2 * 0.3 * omega  # MPPT k Omega^2, k = 0.3 N m s^2


class _Controller:
    k1, k2 = 4.0, 0.7


@pytest.mark.parametrize("holds", [False, True])
def test_end_loads_of_the_laws(holds):
    """The rotor's J and dQ/dOmega at (Omega, V_n); the generator's dtau/dOmega, or with
    the paper's law holding the speed (Eq. 40, k1 > 0) its k1 and k2 instead."""
    loads = EndLoads.of_laws(_Rotor(), _Generator(holds), 10.0, 8.0, 1.2, _Controller())
    assert loads.rotor_inertia_kgm2 == 2.5
    assert loads.rotor_dtorque_domega_Nms == pytest.approx(-0.5 * 1.2 * 8.0 * 10.0)
    assert loads.generator_dtorque_domega_Nms == (0.0 if holds else pytest.approx(6.0))
    assert (loads.k1, loads.k2) == ((4.0, 0.7) if holds else (0.0, 0.0))
    assert EndLoads.of_laws(_Rotor(), None, 10.0, 8.0, 1.2, _Controller()).k1 == 0.0
