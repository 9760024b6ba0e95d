"""The operating point as a relative equilibrium (issue 43, part 2: solvers/
operating_point.py, solvers/rigid_shaft_branch.py) against what does not share its code:

* the rigid-shaft closed form through the full solver (helix torsionally very stiff,
  gravity and drag off, no losses): MPPT at k = 1/2 rho pi R^5 Cp_max / lambda_opt^3 gives
  Omega = lambda_opt V_n / R and P = 1/2 rho pi R^2 V_n^3 Cp_max; any other k the root of
  Cp(lambda) = k lambda^3 / (1/2 rho pi R^5) by scipy on the table itself, to 1e-6;
* the twist end to end: Q L0 / GJ (solid section), and members.py's torque-twist curve
  (tensegrity section carrying the torque), to 1e-4;
* the cost: at most 3 stationary solves a point, with gravity and drag on;
* the continuation: a rotor whose torque coefficient peaks (stall) under a constant
  generator torque has a fold in V, one stable and one unstable branch, both roots
  equal to scipy's; a torque curve with two humps gives two stable points at one wind.

The laws are operation/'s (Cp, CT: monotone cubic in the table); the independent roots
are scipy's (brentq on scipy's PchipInterpolator of the same table).
"""

import math

import numpy as np
import pytest
import scipy.interpolate
import scipy.optimize
from mpi4py import MPI

from rawehelix.operation.generator import GeneratorLaw
from rawehelix.operation.rotor import RotorLaw
from rawehelix.solvers.operating_point import MAX_SOLVES, OperatingPointSolver
from rawehelix.solvers.rigid_shaft_branch import RigidShaftProblem, trace
from rawehelix.solvers.torque_balance import Drive, stable
from rawehelix.studies import scene

RHO, R = 1.225, 1.0
COS45 = math.cos(math.pi / 4)


def TableRotor(lam, cp, ct, R):
    return RotorLaw(lam, cp, ct, radius_m=R, spin_inertia_kgm2=2.0)


def Mppt(k):
    return GeneratorLaw("mppt", mppt_gain_Nms2=k)


def ConstantTorque(torque_Nm):
    return GeneratorLaw("torque", torque_Nm=torque_Nm)


def hump(lam_opt=5.0, cp_max=0.4, n=41):
    """A Cp table peaked at lam_opt (a row): cp_max (2 x - x^2) on x = lam / lam_opt in
    (0, 2), n rows."""
    x = np.linspace(0.05, 1.95, n)
    return x * lam_opt, cp_max * (2 * x - x**2), 0.8 * x / (1 + x)


def cp_of(lam, cp):
    """Cp(lambda) by scipy's monotone cubic interpolant of the table."""
    return scipy.interpolate.PchipInterpolator(lam, cp)


def straight(N=4, model=(), **changes):
    """Table 2's helix with gravity and drag off: straight along its chord at 45 deg, so
    the wind along its end tangent is V cos 45 exactly."""
    return scene.load("stationary_table2", elements=N).replace(
        model={"gravity": False, "drag": False, **dict(model)}, **changes)


def points_at(params, drive, winds):
    """The operating points at ``winds`` on the first branch (the full solver)."""
    q = params.normalised()
    traced = trace(RigidShaftProblem(drive, q.t_scale, q.torque_scale),
                   0.5 * min(winds), max(winds))
    seg = traced.segments[0]
    solver = OperatingPointSolver(lambda V: params.replace(environment={"wind_speed_m_s": V}),
                                  drive, lambda V: V, MPI.COMM_SELF)
    return [solver.solve(V, lambda vn: seg.root(drive, vn)) for V in winds]


def table_root(lam, cp, k):
    """lambda with Cp(lambda) = k lambda^3 / (1/2 rho pi R^5): scipy on the table, not the
    solver's laws."""
    c = 0.5 * RHO * math.pi * R**5
    Cp = cp_of(lam, cp)
    f = lambda x: Cp(x) - k * x**3 / c  # noqa: E731
    x = np.linspace(lam[0], lam[-1], 2001)
    g = f(x)
    i = np.flatnonzero(np.sign(g[:-1]) != np.sign(g[1:]))
    assert i.size == 1
    return scipy.optimize.brentq(f, x[i[0]], x[i[0] + 1], xtol=1e-15)


def test_rigid_shaft_closed_forms_through_the_full_solver():
    lam, cp, ct = hump()
    i = int(np.argmax(cp))
    k_opt = 0.5 * RHO * math.pi * R**5 * cp[i] / lam[i] ** 3
    p = straight(helix={"GJ_Nm2": 1e6})
    rotor = TableRotor(lam, cp, ct, R)
    for V, pt in zip((6.0, 11.0), points_at(p, Drive(rotor, Mppt(k_opt), RHO), (6.0, 11.0))):
        vn = V * COS45
        assert pt.v_n_m_s == pytest.approx(vn, rel=1e-12)
        assert pt.omega_rad_s == pytest.approx(lam[i] * vn / R, rel=1e-6)
        assert pt.power_W == pytest.approx(0.5 * RHO * math.pi * R**2 * vn**3 * cp[i], rel=1e-6)
        assert pt.torque_ground_Nm == pytest.approx(pt.torque_top_Nm, rel=1e-14)  # no loss
        assert pt.stable
    k = 0.6 * k_opt  # a lighter generator: the rotor runs faster than lambda_opt
    lam_k = table_root(lam, cp, k)
    assert lam_k > lam[i] * 1.05
    for V, pt in zip((5.0, 9.0), points_at(p, Drive(rotor, Mppt(k), RHO), (5.0, 9.0))):
        assert pt.omega_rad_s == pytest.approx(lam_k * V * COS45 / R, rel=1e-6)
        assert pt.tsr == pytest.approx(lam_k, rel=1e-6)


@pytest.mark.parametrize("GJ", [140.0, 600.0])
def test_twist_is_Q_L0_over_GJ_for_the_solid_section(GJ):
    lam, cp, ct = hump()
    p = straight(helix={"GJ_Nm2": GJ})
    (pt,) = points_at(p, Drive(TableRotor(lam, cp, ct, R), ConstantTorque(8.0), RHO), (9.0,))
    assert pt.torque_top_Nm == pytest.approx(8.0, rel=1e-10)
    assert pt.twist_rad == pytest.approx(8.0 * p.helix.length_m / GJ, rel=1e-4)


def test_twist_follows_the_members_torque_twist_curve():
    """The tensegrity section carrying the torque (self-stressed, unlaid): the end-to-end
    twist is L0 tau with members.py's Q(eps, 0, tau) = Q at the FE's (uniform) strain."""
    section = {"law": "tensegrity", "torsion": "members", "self_stress_N": 646.0,
               "bar_EA_N": 2e4}
    p = straight(N=4, model={"kinematics": "extensible"}, section=section)
    lam, cp, ct = hump()
    (pt,) = points_at(p, Drive(TableRotor(lam, cp, ct, R), ConstantTorque(6.0), RHO), (9.0,))
    members = p.model.section.members(p.helix)
    q = p.normalised()
    eps = q.eps0  # straight and weightless: the stretch is the ends' elongation
    tau = scipy.optimize.brentq(lambda t: float(members.resultants(eps, 0.0, t)["Q"]) - 6.0,
                                -1.0, 1.0, xtol=1e-15)
    assert pt.twist_rad == pytest.approx(tau * p.helix.length_m, rel=1e-4)


def test_a_point_costs_at_most_three_stationary_solves():
    """Gravity and drag on: the top tangent turns with the wind's drag, so the axis's
    fixed point takes solves; never more than MAX_SOLVES = 3, and it converges."""
    assert MAX_SOLVES == 3
    lam, cp, ct = hump()
    i = int(np.argmax(cp))
    k_opt = 0.5 * RHO * math.pi * R**5 * cp[i] / lam[i] ** 3
    p = scene.load("stationary_table2", elements=4)
    pts = points_at(p, Drive(TableRotor(lam, cp, ct, R), Mppt(k_opt), RHO), (5.0, 8.0, 11.0))
    assert all(1 <= pt.stationary_solves <= 3 for pt in pts)
    assert max(pt.axis_defect for pt in pts) < 1e-9
    # the sagging helix's top tangent is not the chord's: V_n differs from V cos 45
    assert all(abs(pt.v_n_m_s / (pt.wind_m_s * COS45) - 1) > 1e-4 for pt in pts)


def stall_rotor():
    """Cp = 0.45 (3 x^2 - 2 x^3), x = lambda / 5: the torque coefficient Cp / lambda
    peaks at x = 0.75 (stall below it)."""
    x = np.linspace(0.02, 1.48, 60)
    return 5 * x, 0.45 * (3 * x**2 - 2 * x**3), 0.8 * x / (1 + x)


def scipy_roots(lam, cp, torque_Nm, v_n):
    """The spins [rad/s] with 1/2 rho pi R^3 V_n^2 Cp(lambda)/lambda = torque, scipy on
    the table."""
    c = 0.5 * RHO * math.pi * R**3 * v_n**2
    Cp = cp_of(lam, cp)
    f = lambda x: c * Cp(x) / x - torque_Nm  # noqa: E731
    x = np.linspace(lam[0], lam[-1], 4001)
    g = f(x)
    return [scipy.optimize.brentq(f, x[i], x[i + 1], xtol=1e-15) * v_n / R
            for i in np.flatnonzero(np.sign(g[:-1]) != np.sign(g[1:]))]


def test_the_fold_in_wind_speed_is_stepped_past_and_marked():
    lam, cp, ct = stall_rotor()
    drive = Drive(TableRotor(lam, cp, ct, R), ConstantTorque(20.0), RHO)
    traced = trace(RigidShaftProblem(drive, 1.0, 1.0), 3.0, 14.0)
    # the fold: where Q's largest value over Omega meets 20 N m (Cq = Cp / lambda is
    # largest at x = 0.75)
    cq_max = 0.45 * (3 * 0.75**2 - 2 * 0.75**3) / (5 * 0.75)
    v_fold = math.sqrt(20.0 / (0.5 * RHO * math.pi * R**3 * cq_max))
    assert len(traced.folds) == 1
    assert traced.folds[0] == pytest.approx(v_fold, rel=2e-3)  # the table's interpolant
    assert sorted(s.stable for s in traced.segments) == [False, True]
    for v_n in (11.0, 13.5):
        want = scipy_roots(lam, cp, 20.0, v_n)
        got = sorted(s.root(drive, v_n) for s in traced.segments if s.covers(v_n))
        assert got == pytest.approx(want, rel=1e-10)
        slow, fast = (next(s for s in traced.segments if s.covers(v_n) and
                           abs(s.root(drive, v_n) - w) < 1e-6 * w) for w in want)
        assert not slow.stable and fast.stable  # d(Q - tau)/dOmega: > 0 below stall


def two_hump_rotor():
    """A torque coefficient Cp / lambda with two humps (a rotor whose blades stall in two
    stages): under a constant torque, three roots at one wind, the outer two stable."""
    lam = np.linspace(0.5, 10.0, 200)
    cq = 0.03 + 0.012 * np.sin(lam * 2 * np.pi / 4.0) - 0.002 * lam
    return lam, np.clip(cq * lam, 0.0, None), 0.5 + 0 * lam


def test_two_stable_points_at_one_wind_each_with_its_branch():
    lam, cp, ct = two_hump_rotor()
    assert cp.max() < 16 / 27
    drive = Drive(TableRotor(lam, cp, ct, R), ConstantTorque(12.0), RHO)
    v_n = 14.0
    want = scipy_roots(lam, cp, 12.0, v_n)
    traced = trace(RigidShaftProblem(drive, 1.0, 1.0), 10.0, 18.0)
    here = [(s.root(drive, v_n), s) for s in traced.segments if s.covers(v_n)]
    assert sorted(w for w, _ in here) == pytest.approx(want, rel=1e-10)
    steady = [s.index for w, s in here if s.stable]
    assert len(steady) >= 2 and len(set(steady)) == len(steady)
    assert len(traced.folds) >= 2


def test_stability_is_one_function_that_takes_eigenvalues():
    assert stable(-1.0) and not stable(2.0)
    assert not stable(-1.0, eigenvalues=[-1.0, 0.5 + 3j])  # the full linearisation decides
    assert stable(2.0, eigenvalues=[-1.0, -0.1 + 3j])


def test_the_papers_law_holds_the_speed_and_its_torque_balances_the_rotors():
    """Eq. (40) with its integral action: Omega = the target at every wind, the ground's
    torque = Q (no loss), the twist Q L0 / GJ; stable where its speed gain K2 exceeds
    dQ/dOmega (operation/rigid_shaft.py's criterion)."""
    lam, cp, ct = hump()
    target = 120 * math.pi / 30
    law = GeneratorLaw("paper", target_rad_s=target, integral_Nm=5.0, damping_Nms=3.0)
    drive = Drive(TableRotor(lam, cp, ct, R), law, RHO)
    p = straight()
    for pt in points_at(p, drive, (8.0, 12.0)):
        vn = pt.wind_m_s * COS45
        assert pt.omega_rad_s == target
        Q = 0.5 * RHO * math.pi * R**3 * vn**2 * float(cp_of(lam, cp)(target * R / vn)) / (
            target * R / vn)
        assert pt.torque_top_Nm == pytest.approx(Q, rel=1e-12)
        assert pt.torque_ground_Nm == pt.torque_top_Nm
        assert pt.twist_rad == pytest.approx(Q * p.helix.length_m / p.helix.GJ_Nm2, rel=1e-4)
        assert pt.stable == (drive.rotor.dtorque_domega(target, vn, RHO) - 3.0 < 0)
