"""Hysteretic torsion ([torsion_hysteresis], forms/hysteresis.py): the Bouc-Wen twist z.

The torsion test of Sec. 4 (Fig. 2c, Fig. 5) run on the FE rod: a 6.76 m
segment with the mass per length of the Table 2 helix, stretched to 200 N,
twisted at its end from 0 to 50 degrees and back four times (alpha(0) = 0,
alpha(L0) = theta(t), slow: quasi-static).  The moment at the end against
the same Bouc-Wen law integrated by scipy's solve_ivp for the same twist
history (solvers/bouc_wen.py, which shares no code with the forms): the
energy dissipated per cycle to 1 %, and the order of alpha2 on z.  The
tangent is checked against the residual's difference quotient; the default
and the refusals as for every switch.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from mpi4py import MPI

import dolfinx.fem
import dolfinx.fem.petsc

import rawehelix as rh
from rawehelix import compat
from rawehelix.errors import SceneError
from rawehelix.parameters import ParameterError, TorsionHysteresis
from rawehelix.solvers import bouc_wen
from rawehelix.solvers.discrete import RodDiscretisation
from rawehelix.solvers.dynamics import DynamicsSolver
from rawehelix.solvers.modal import ModalSolver
from rawehelix.studies import scene
from rawehelix.studies.torsion_loop import LENGTH_M, reference, run, segment

LAW = TorsionHysteresis(rho=0.5, A=1.0, beta_m_n=10.0, gamma_m_n=10.0, n=1.0)


def test_torsion_cycle_dissipates_as_the_scipy_bouc_wen():
    """Four cycles 0 -> 50 deg -> 0 over 20 s each (the segment's torsional period
    is 0.17 s: quasi-static), N = 2, 100 steps a cycle: the energy dissipated per
    cycle equals the scipy reference's within 1 % (measured 0.1 %), and a
    reference with rho 0.05 off misses it by more than 1 %."""
    period, cycles = 20.0, 4
    loop = rh.torsion_loop(dataclasses.asdict(LAW), period, cycles, 100, elements=2,
                           comm=MPI.COMM_SELF)  # the API: studies/torsion_loop.py
    t, theta, M = loop["t_s"], loop["theta_rad"], loop["moment_Nm"]
    E = bouc_wen.cycle_energies(t, theta, M, period, cycles)
    E_ref = bouc_wen.cycle_energies(t, theta, loop["reference_moment_Nm"], period, cycles)
    error = np.abs(E / E_ref - 1)
    print("dissipated per cycle [J]: FE", E, "scipy", E_ref, "relative", error)
    assert np.all(E_ref > 0.1)  # a loop, clockwise: energy is dissipated
    assert np.all(error < 0.01)
    other = TorsionHysteresis(rho=LAW.rho + 0.05, A=LAW.A, beta_m_n=LAW.beta_m_n,
                              gamma_m_n=LAW.gamma_m_n, n=LAW.n)
    E_other = bouc_wen.cycle_energies(t, theta, reference(other, t, period), period, cycles)
    assert np.all(np.abs(E / E_other - 1) > 0.01)
    # the elastic rod (Eq. 65) dissipates nothing over the same cycle
    elastic = segment(LAW).helix.GJ_Nm2 * theta / LENGTH_M
    assert np.all(np.abs(bouc_wen.cycle_energies(t, theta, elastic, period, cycles))
                  < 1e-3 * E_ref)


def test_alpha2_integrates_the_internal_twist_to_second_order():
    """One slow cycle (200 s: inertia below 1e-6 of the moment) at 25, 50 and 100
    steps: the largest moment error against scipy falls by 4 per halving
    (measured orders 1.97 and 2.00)."""
    period = 200.0
    errors = []
    for steps in (25, 50, 100):
        t, _, M = run(segment(LAW), period, 1, steps)
        errors.append(np.max(np.abs(M - reference(LAW, t, period))))
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    print("max |M - M_ref| [Nm]:", errors, "orders", orders)
    assert np.all(orders > 1.8)


@pytest.mark.parametrize("gamma", ["off", "regularised"])
def test_tangent_is_the_derivative_of_the_residual(gamma):
    """J = dF/dU + v_shift dF/dV + a_shift dF/dA against the central difference of F
    along (U + e dU, V + v_shift e dU, A + a_shift e dU), at a twisted, moving
    state with z on the loop (no kink of |tau_t| or |z| at the quadrature points);
    with the Frenet torsion on, tau_t has its rate too."""
    params = segment(TorsionHysteresis(rho=0.4, A=1.3, beta_m_n=8.0, gamma_m_n=-3.0, n=1.5))
    params = params.replace(model={"gamma": gamma})
    solver = DynamicsSolver.from_stationary(params, MPI.COMM_WORLD)
    form = solver.form
    rng = np.random.default_rng(3)
    u0 = form.u.x.array.copy()
    form.u.sub(1).interpolate(lambda x: 0.3 * x[0] + 0.05 * np.sin(3 * x[0]))
    form.u.sub(2).interpolate(lambda x: 0.2 + 0.1 * x[0])
    form.v.sub(1).interpolate(lambda x: 0.7 * x[0] ** 2 + 0.1 * x[0])
    form.v.sub(2).interpolate(lambda x: 0.3 - 0.2 * x[0])
    form.v.sub(0).interpolate(lambda x: np.vstack([0.01 * x[0], 0.02 * x[0] ** 2, 0 * x[0]]))
    form.u.sub(0).interpolate(  # out of plane: a centre line with curvature and torsion
        lambda x: np.vstack([-x[0], 0.01 * np.sin(np.pi * x[0]), 0.02 * np.sin(2 * np.pi * x[0])]))
    form.a.x.array[:] = rng.normal(0, 0.1, form.a.x.array.size)
    base = [f.x.array.copy() for f in (form.u, form.v, form.a)]
    du = rng.normal(0, 1, u0.size) * 1e-3
    form.shift_v.value, form.shift_a.value = 7.0, 30.0
    shifts = (1.0, 7.0, 30.0)

    def F_at(e):
        for f, b, s in zip((form.u, form.v, form.a), base, shifts):
            f.x.array[:] = b + e * s * du
        b_ = compat.create_vector(form.F)
        dolfinx.fem.petsc.assemble_vector(b_, form.F)
        return b_.getArray().copy()

    eps = 1e-5
    fd = (F_at(eps) - F_at(-eps)) / (2 * eps)
    F_at(0.0)
    A = compat.create_matrix(form.J)
    dolfinx.fem.petsc.assemble_matrix(A, form.J)
    A.assemble()
    x = A.createVecRight()
    x.getArray()[:] = du
    y = A.createVecLeft()
    A.mult(x, y)
    err = np.linalg.norm(y.getArray() - fd) / np.linalg.norm(fd)
    print("|J du - FD| / |FD| =", err)
    assert err < 1e-6


def test_default_is_the_paper_model_and_its_fingerprint():
    """Off by default: no key in the fingerprints, no z field, the same description."""
    p = segment(TorsionHysteresis())
    assert "torsion_hysteresis" not in p.as_dict()["model"]
    assert not p.normalised().hysteretic and "hysteresis" not in p.model.describe()
    rod_off = RodDiscretisation(p, MPI.COMM_WORLD)
    rod_on = RodDiscretisation(segment(LAW), MPI.COMM_WORLD)
    N, deg = p.discretisation.elements, p.discretisation.degree
    assert rod_on.dof_count() - rod_off.dof_count() == N * deg  # DG_(p-1): p dofs a cell
    assert "torsion hysteresis: Bouc-Wen rho = 0.5" in segment(LAW).model.describe()
    assert "torsion_hysteresis" in segment(LAW).as_dict()["model"]


def test_scene_section_and_refusals(tmp_path):
    from tests_util import write_scene
    path = write_scene(tmp_path / "bw.toml", {"torsion_hysteresis": {
        "rho": 0.5, "A": 2.39, "beta_m_n": 4.78, "gamma_m_n": 4.78, "n": 1.0}},
        name="nominal_operation")
    p = scene.load(path)
    assert p.model.torsion_hysteresis.A == 2.39 and p.model.torsion_hysteresis.active
    assert math.isclose(p.normalised().bw_beta, 4.78 / 16.12)  # beta / L0^n
    for bad in ({"rho": 0.0}, {"rho": 0.5, "beta_m_n": 0.0},
                {"rho": 0.5, "beta_m_n": 1.0, "gamma_m_n": 2.0}, {"n": 0.5}, {"A": -1.0},
                {"unknown": 1.0}):
        with pytest.raises(SceneError, match="torsion_hysteresis"):
            scene.load(write_scene(tmp_path / "bad.toml", {"torsion_hysteresis": bad},
                                   name="nominal_operation"))
    with pytest.raises(ParameterError, match="torsion_hysteresis"):
        p.replace(discretisation={"bending": "mixed"})
    small = segment(LAW)
    with pytest.raises(SceneError, match="second-order integrator"):
        DynamicsSolver(small, MPI.COMM_WORLD, options={"ts_type": "beuler"})
    with pytest.raises(SceneError, match="modal solver"):
        ModalSolver(small, MPI.COMM_WORLD)
    from rawehelix.studies import labtest
    with pytest.raises(SceneError, match="static"):
        labtest.compute(p, "torsion")
    with pytest.raises(ValueError, match="alpha2 only"):
        DynamicsSolver(segment(TorsionHysteresis()), MPI.COMM_WORLD,
                       options={"ts_type": "beuler"}, end_twist=lambda t: 0.0)


@pytest.mark.mpi
def test_same_torsion_loop_on_one_and_two_ranks():
    """z's DG dofs and their error tolerances are per rank: the loop (one cycle of
    20 s, N = 4, 50 steps) on COMM_WORLD equals the serial one."""
    params = segment(LAW, elements=4)
    loops = [run(params, 20.0, 1, 50, comm=comm)[2] for comm in (MPI.COMM_SELF, MPI.COMM_WORLD)]
    assert np.max(np.abs(loops[0] - loops[1])) < 1e-9 * np.max(np.abs(loops[0]))


@pytest.mark.long  # make test's 12-minute budget (2026-12-04); make test-long runs it
def test_orbit_is_the_sweeps_periodic_point_with_z_carried():
    """Fig. 8 by the orbits with the Fig. 5 law (mobile_end, N = 4, dt = 0.5 ms,
    11.5 Hz; about 12 s).  z and its alpha2 rate and acceleration are carried
    along by the shooting (periodic_orbits/floquet.py, "Carried entries"), Newton on the
    rod: T max equals the brute-force sweep's periodic point (rh.sweep, same
    scene, N, dt) within 1e-3 (measured 1.5e-5); z drifts by < Z_TOL of itself
    over a period; z's multipliers, one per z dof, are within 1e-6 of 1 (the
    twist hardly travels: measured 1 - 1e-8) and set aside from the
    stability.  The orbit is the integrator's, z free: three more periods of
    the full state keep the rod periodic and z still (a z reset, lost or
    mis-carried breaks this).  Newton on the whole state, z solved for, finds
    no orbit (the diagnosis: M - I nearly singular in z, kinks in |dtau|)."""
    import rawehelix as rh
    from rawehelix.solvers.orbits import CARRIED_TOL, Z_TOL, AlphaMap
    from rawehelix.solvers.snes import SolverError

    fig5 = {"rho": 0.5, "A": 2.39, "beta_m_n": 4.78, "gamma_m_n": 4.78, "n": 1.0}
    sc = rh.load_scene("mobile_end", elements=4).replace(torsion_hysteresis=fig5)
    (point,) = rh.sweep(sc, [11.5]).points
    assert point["periodic"]
    m = AlphaMap(sc)
    o = m.orbit(m.X_stationary, 11.5, lead_in=5)
    print("orbit", o.tension_max_N, "sweep", point["tension_max_N"], o.defects,
          o.internal_multipliers)
    assert o.residual <= 1e-7
    assert o.tension_max_N == pytest.approx(point["tension_max_N"], rel=1e-3)
    assert o.defects["z"] <= Z_TOL and o.defects["carried"] <= CARRIED_TOL
    z = m.z_dofs
    assert np.linalg.norm(o.X[z]) > 0.1  # z remembers the lead-in: not the virgin 0
    mu = o.internal_multipliers
    assert mu.size == z.size and np.all(np.abs(mu - 1.0) < 1e-6)
    assert o.stable and o.max_multiplier < 0.99 and o.entry()["defects"] == o.defects
    X = o.X
    for _ in range(3):
        PX, _, _ = m.period(X, 11.5)
        G = PX - X - o.delta * m.e_alpha
        assert m.shooting_norm(G, X) <= CARRIED_TOL
        assert np.linalg.norm(G[z]) <= Z_TOL * max(1.0, np.linalg.norm(X[z]))
        X = PX - o.delta * m.e_alpha
    m.carried = np.zeros(0, dtype=int)  # z, V_z, A_z solved for by the Newton
    with pytest.raises(SolverError, match="orbits: shooting"):
        m.orbit(m.X_stationary, 11.5, lead_in=5)
