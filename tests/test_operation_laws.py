"""The machine's numpy laws (operation/, issue 43) against independent computations:
scipy's PCHIP and brentq on a fresh interpolant, the closed forms of the rigid shaft
(MPPT at the optimal gain), finite differences, and the illustrative rotor's stated
25 N m at 120 rpm."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator
from scipy.optimize import brentq

from rawehelix.operation import generator as gen_law
from rawehelix.operation import rigid_shaft, wind as wind_law
from rawehelix.operation.rotor import RPM, OutOfTable, RotorLaw, from_params
from rawehelix.studies import scene

RHO = 1.225  # [kg/m^3]
R = 2.0  # [m]


def table():
    """The illustrative rotor's CSV, read by numpy (not the scene loader)."""
    return np.loadtxt(scene.SCENE_DIR / "rotor_example.csv", delimiter=",", comments="#",
                      skiprows=5).T


def rotor() -> RotorLaw:
    tsr, cp, ct = table()
    return RotorLaw(tsr, cp, ct, radius_m=R)


def fresh_cp():
    tsr, cp, _ = table()
    return PchipInterpolator(tsr, cp)


def test_the_interpolant_is_scipys_pchip():
    """The table's interpolant and its derivative are PCHIP's (Fritsch-Carlson), to
    round-off, on the shipped table and on an irregular one with a flat stretch."""
    rng = np.random.default_rng(4)
    tsr, cp, ct = table()
    tables = [(tsr, cp, ct),
              (np.array([0.5, 1.0, 2.5, 2.7, 4.0, 6.5, 7.0]),
               np.array([0.02, 0.1, 0.3, 0.3, 0.45, 0.2, 0.21]),
               np.array([0.1, 0.2, 0.4, 0.45, 0.6, 0.8, 0.79])),
              # the end slopes' two limiters: the three-point slope against the first
              # secant's sign (set to 0), and past 3 times it where the data turns
              (np.array([0.5, 1.5, 1.6, 3.0, 3.5, 4.0]),
               np.array([0.0, 0.1, 0.0, 0.05, 0.45, 0.46]),
               np.array([0.1, 0.2, 0.3, 0.5, 0.6, 0.7]))]
    for x, c, t in tables:
        law = RotorLaw(x, c, t, radius_m=R)
        lam = np.concatenate([x, rng.uniform(x[0], x[-1], 200)])
        for mine, col in ((law.cp, c), (law.ct, t)):
            ref = PchipInterpolator(x, col)
            assert np.allclose(mine(lam), ref(lam), rtol=0, atol=1e-14)
        assert np.allclose(law._cp.derivative(lam), PchipInterpolator(x, c).derivative()(lam),
                           rtol=0, atol=1e-12)
        fine = np.linspace(x[0], x[-1], 20001)  # no overshoot: the largest Cp is a row's
        assert law.cp(fine).max() <= law.cp_max + 1e-15


def test_torque_thrust_and_their_derivative_are_the_closed_forms():
    law = rotor()
    tsr, cp, ct = table()
    v = 7.0
    omega = tsr[6] * v / R  # on a row: Cp and CT are the table's
    area = math.pi * R * R
    assert law.torque(omega, v, RHO) == pytest.approx(0.5 * RHO * area * v**3 * cp[6] / omega,
                                                       rel=1e-14)
    assert law.thrust(omega, v, RHO) == pytest.approx(0.5 * RHO * area * v**2 * ct[6], rel=1e-14)
    h = 1e-6 * omega
    w = omega * 1.037  # between rows
    fd = (law.torque(w + h, v, RHO) - law.torque(w - h, v, RHO)) / (2 * h)
    assert law.dtorque_domega(w, v, RHO) == pytest.approx(fd, rel=1e-7)


@pytest.mark.parametrize("v", [3.0, 6.0, 11.0])
def test_mppt_at_the_optimal_gain_runs_at_the_best_tip_speed_ratio(v):
    """k = 1/2 rho pi R^5 Cp_max / tsr_opt^3: Omega = tsr_opt V / R and
    P = 1/2 rho pi R^2 V^3 Cp_max, to 1e-6; the only operating point, stable."""
    law = rotor()
    cp_max, tsr_opt = 0.4, 5.5  # the CSV's header: Cp = 0.4 x^2 (3 - 2x), x = tsr / 5.5
    assert law.cp_max == pytest.approx(cp_max, abs=1e-6) and law.tsr_opt == tsr_opt
    k = 0.5 * RHO * math.pi * R**5 * law.cp_max / law.tsr_opt**3
    points = rigid_shaft.operating_points(law, gen_law.GeneratorLaw("mppt", mppt_gain_Nms2=k),
                                          v, RHO)
    assert len(points) == 1 and points[0].stable
    p = points[0]
    assert p.omega_rad_s == pytest.approx(tsr_opt * v / R, rel=1e-6)
    assert p.power_W == pytest.approx(0.5 * RHO * math.pi * R**2 * v**3 * law.cp_max, rel=1e-6)
    assert p.power_W == pytest.approx(p.rotor_power_W, rel=1e-12)


@pytest.mark.parametrize("factor", [0.6, 1.4, 3.0])
def test_mppt_at_any_gain_is_the_root_scipy_finds(factor):
    """Any other k: the roots of Cp(tsr) = k tsr^3 / (1/2 rho pi R^5), by brentq on
    scipy's own PCHIP of the CSV, bracketed on a fine grid."""
    law = rotor()
    k = factor * 0.5 * RHO * math.pi * R**5 * law.cp_max / law.tsr_opt**3
    cp = fresh_cp()
    a = k / (0.5 * RHO * math.pi * R**5)
    f = lambda lam: cp(lam) - a * lam**3  # noqa: E731
    grid = np.linspace(cp.x[0], cp.x[-1], 5001)
    roots = [brentq(f, x0, x1, xtol=1e-15) for x0, x1 in zip(grid[:-1], grid[1:])
             if f(x0) * f(x1) < 0]
    v = 8.0
    points = rigid_shaft.operating_points(law, gen_law.GeneratorLaw("mppt", mppt_gain_Nms2=k),
                                          v, RHO)
    assert [p.tsr for p in points] == pytest.approx(roots, rel=1e-9)
    for p in points:  # stable: the net torque falls through the root
        h = 1e-5 * p.omega_rad_s
        net = [law.torque(w, v, RHO) - k * w * w for w in (p.omega_rad_s - h, p.omega_rad_s + h)]
        assert p.stable == (net[1] < net[0])


def test_rated_power_caps_the_generator():
    """Above P_rated the generator takes P_rated / Omega: the operating points are the
    roots of 1/2 rho pi R^2 V^3 Cp(tsr) = min(k Omega^3, P_rated) (scipy's brentq on its
    own PCHIP), each stable where the net torque falls through it."""
    law = rotor()
    k = 0.5 * RHO * math.pi * R**5 * law.cp_max / law.tsr_opt**3
    rated, v = 800.0, 10.0  # 1/2 rho pi R^2 V^3 Cp_max = 3079 W: capped
    g = gen_law.GeneratorLaw("mppt", mppt_gain_Nms2=k, rated_power_W=rated)
    assert g.torque(1.0) == pytest.approx(k)  # below: k Omega^2
    assert g.torque(40.0) == pytest.approx(rated / 40.0)  # k 40^3 = 9476 W above it
    assert g.dtorque_domega(40.0) == pytest.approx(-rated / 1600.0)
    cp = fresh_cp()
    f = lambda lam: (0.5 * RHO * math.pi * R**2 * v**3 * cp(lam)  # noqa: E731
                     - min(k * (lam * v / R) ** 3, rated))
    grid = np.linspace(cp.x[0], cp.x[-1], 5001)
    roots = [brentq(f, x0, x1, xtol=1e-15) for x0, x1 in zip(grid[:-1], grid[1:])
             if f(x0) * f(x1) < 0]
    points = rigid_shaft.operating_points(law, g, v, RHO)
    assert roots and [p.tsr for p in points] == pytest.approx(roots, rel=1e-9)
    for p in points:
        h = 1e-5 * p.omega_rad_s
        net = [law.torque(w, v, RHO) - g.torque(w) for w in (p.omega_rad_s - h, p.omega_rad_s + h)]
        assert p.stable == (net[1] < net[0])
    # one point, on the cap past Cp's peak (tsr 7.90), stable
    assert len(points) == 1 and points[0].stable and points[0].tsr > law.tsr_opt
    assert points[0].power_W == pytest.approx(rated, rel=1e-12)


def test_a_torque_table_and_a_constant_torque():
    g = gen_law.GeneratorLaw("torque", table_rpm=[0.0, 60.0, 120.0],
                             table_torque_Nm=[0.0, 10.0, 25.0])
    assert g.torque(90 * RPM) == pytest.approx(17.5, rel=1e-14)
    assert g.torque(200 * RPM) == 25.0  # its last row beyond the table
    assert g.dtorque_domega(90 * RPM) == pytest.approx(15.0 / (60 * RPM))
    assert gen_law.GeneratorLaw("torque", torque_Nm=12.0).torque(3.0) == 12.0


def test_the_paper_law_holds_its_target_spin():
    """Eq. (40) with k1 > 0: one point at the target spin, its torque the rotor's;
    stable when the gain K2 exceeds dQ/dOmega."""
    law = rotor()
    v = 6.0
    target = 5.0 * v / R
    for K2, stable in ((0.5, True), (1e-3, True)):
        g = gen_law.GeneratorLaw("paper", target_rad_s=target, integral_Nm=2.0, damping_Nms=K2)
        (p,) = rigid_shaft.operating_points(law, g, v, RHO)
        assert p.omega_rad_s == target and p.generator_torque_Nm == p.rotor_torque_Nm
        h = 1e-6 * target
        dQ = (law.torque(target + h, v, RHO) - law.torque(target - h, v, RHO)) / (2 * h)
        assert p.stable == (dQ - K2 < 0)
    # beyond Cp's peak dQ/dOmega > 0 there: a small K2 cannot hold it
    stall = 2.0 * v / R
    dQ = law.dtorque_domega(stall, v, RHO)
    assert dQ > 0
    for K2 in (0.5 * dQ, dQ - 1e-3):  # net slope dQ - K2 > 0, however small: unstable
        g = gen_law.GeneratorLaw("paper", target_rad_s=stall, integral_Nm=2.0, damping_Nms=K2)
        (p,) = rigid_shaft.operating_points(law, g, v, RHO)
        assert p.slope_Nms == pytest.approx(dQ - K2, rel=1e-9) and not p.stable
    with pytest.raises(ValueError, match="holds the rotor at its target spin"):
        g.torque(stall)


def test_a_speed_outside_the_table_names_the_wind_and_rotor_speed():
    law = rotor()
    with pytest.raises(OutOfTable) as err:
        law.torque(50.0, 4.0, RHO)  # tsr 25
    text = str(err.value)
    assert "wind 4 m/s" in text and f"{50.0 / RPM:.4g} rpm" in text and "[1, 8]" in text
    g = gen_law.GeneratorLaw("paper", target_rad_s=120 * RPM, integral_Nm=1.0)
    with pytest.raises(OutOfTable, match="wind 1 m/s and rotor speed 120 rpm"):
        rigid_shaft.operating_points(law, g, 1.0, RHO)


def test_the_illustrative_rotor_gives_25_Nm_at_120_rpm_at_its_stated_wind():
    """rotor_example.toml's header: 25 N m at 120 rpm at V = 6.6131 m/s (V_n = V cos 45
    deg along the chord).  The wind that gives 25 N m at 120 rpm, by brentq on scipy's
    PCHIP of the CSV, is the scene's to 1e-4; and at the scene's wind its generator's
    operating point is 120 rpm and 25 N m to 1e-4."""
    p = scene.load("rotor_example")
    law, g = from_params(p), gen_law.from_params(p)
    w = 120 * RPM
    cp = fresh_cp()
    torque = lambda vn: 0.5 * RHO * math.pi * R**2 * vn**3 * cp(w * R / vn) / w - 25.0  # noqa: E731
    vn = brentq(torque, w * R / 8.0, w * R / 1.0, xtol=1e-14)
    wind = wind_law.from_params(p)
    tangent = (math.cos(math.radians(45.0)), 0.0, math.sin(math.radians(45.0)))
    assert vn / tangent[0] == pytest.approx(p.wind.speed_m_s, rel=1e-4)
    assert wind.hub_speed == p.wind.speed_m_s  # uniform
    (point,) = rigid_shaft.operating_points(law, g, law.normal_speed(wind.hub_speed, tangent),
                                            wind_law.air_density(p))
    assert point.rotor_rpm == pytest.approx(120.0, rel=1e-4)
    assert point.generator_torque_Nm == pytest.approx(25.0, rel=1e-4) and point.stable


def test_the_wind_profiles_are_their_closed_forms():
    power = wind_law.WindProfile(8.0, 10.0, "power", shear_exponent=0.2)
    assert power.speed_at(25.0) == pytest.approx(8.0 * 2.5**0.2, rel=1e-15)
    assert power.speed_at(-1.0) == power.speed_at(wind_law.FLOOR_M)  # the floor
    log = wind_law.WindProfile(8.0, 10.0, "log", roughness_m=0.1)
    assert log.speed_at(25.0) == pytest.approx(8.0 * math.log(250.0) / math.log(100.0), rel=1e-15)
    assert log.speed_at(0.05) == 0.0
    assert wind_law.WindProfile(8.0).speed_at(123.0) == 8.0


def test_the_scene_without_the_machine_has_no_laws():
    p = scene.load("stationary_table2")
    assert from_params(p) is None and gen_law.from_params(p) is None
    assert wind_law.from_params(p).speed_m_s == p.environment.wind_speed_m_s
    assert wind_law.air_density(p) == p.environment.air_density_kg_m3


def test_the_tables_top_row_is_not_left_by_round_off():
    """A table tsr = linspace(0.5, 10, 96), R = 0.8 m, at V_n = 3.44893 m/s: the grid's
    first spin 0.5 V_n / R gave back a ratio 1 ulp below 0.5 and raised OutOfTable
    ("tip-speed ratio 0.5 ... outside"; the same at the top row for other R, V_n).  The
    roots are found, and agree with scipy's roots of Q = k Omega^2 on the table."""
    lam = np.linspace(0.5, 10.0, 96)
    cp = 0.45 * np.sin(np.pi * (lam - 0.5) / 9.5) ** 2 + 0.01
    R = 0.8
    law = RotorLaw(lam, cp, 0.8 * lam / (1 + lam), radius_m=R)
    v, rho = 3.44893, 1.225
    k = 0.002  # [N m s^2]: near the optimal gain of this R
    points = rigid_shaft.operating_points(law, gen_law.GeneratorLaw("mppt", mppt_gain_Nms2=k),
                                          v, rho)
    Cp = PchipInterpolator(lam, cp)
    f = lambda x: 0.5 * rho * math.pi * R**2 * v**3 * Cp(x) / (x * v / R) - k * (x * v / R) ** 2  # noqa: E731
    x = np.linspace(0.5, 10.0, 20001)
    g = f(x)
    roots = [brentq(f, x[i], x[i + 1], xtol=1e-15)
             for i in np.flatnonzero(np.sign(g[:-1]) != np.sign(g[1:]))]
    assert roots and [p.tsr for p in points] == pytest.approx(roots, rel=1e-9)
