"""Issue 44, start-up from rest (generator.release_rpm, solvers/release.py): the helix
untwisted at rest in the wind, the rotor spinning up unloaded until the ground end
reaches the release speed, the generator then ramped in over RELEASE_RAMP_S.

* a torsionally stiff helix (GJ x 1000) follows scipy's rigid-shaft ODE with the same
  release, J dOmega/dt = Q(Omega, V_n) - e(t) tau(Omega), e the ramp from the run's
  release time, Q from scipy's own PCHIP of the table (Q(0) from its slope at 0), to
  1e-3 of the operating speed; the release is the first step at the release speed;
* the shipped ``startup`` scene (N = 2, 4 s) reaches its operating point and says so,
  the energy balance closing to 1e-3 of the work in;
* a table that does not start at tsr 0 with Cp 0 is refused (test_faults.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.interpolate import PchipInterpolator

from rawehelix.operation.generator import RELEASE_RAMP_S
from rawehelix.operation.rotor import RPM
from rawehelix.solvers import end_torques
from rawehelix.studies import scene, simulate


def test_a_stiff_helix_starts_up_like_the_rigid_shaft():
    """startup with GJ x 1000, N = 4, fixed 10 ms steps, 3 s: Omega(t) of the rotor
    equals the ODE's to 1e-3 of the operating speed at every 50 ms output, from rest
    (0 rpm at t = 0) through the release at 60 rpm to near 120 rpm."""
    p = scene.load("startup", elements=4).replace(
        helix={"GJ_Nm2": 1.4e5}, time={"dt_s": 0.01, "output_every_s": 0.05})
    series = simulate.compute(p, until_s=3.0, options={"ts_adapt_type": "none"},
                              progress=False)
    t, rpm, rpm0 = series.rows[:, 0], series.rows[:, 8], series.rows[:, 1]
    block = series.summary["startup"]
    released = block["released_at_s"]
    assert rpm[0] == 0.0 and released is not None
    m = end_torques.machine_of(p)
    law, gen, rho, v = m.rotor, m.generator, m.air_density_kg_m3, m.wind_n_m_s
    cp = PchipInterpolator(law.table_tsr, law.table_cp)  # scipy's, not the rotor law's
    slope0 = cp.derivative()(0.0)
    a = 0.5 * rho * math.pi * law.radius_m**3 * v**2  # Q = a Cp(lambda) / lambda [N m]
    inertia = law.spin_inertia_kgm2 + 2 * p.helix.mass_kg * p.helix.EI_Nm2 / p.helix.EA_N

    def rate(s, y):
        lam = y[0] * law.radius_m / v
        q = a * (cp(lam) / lam if lam > 0 else slope0)
        e = min(max((s - released) / RELEASE_RAMP_S, 0.0), 1.0)
        return [(q - e * gen.k * y[0] ** 2) / inertia]
    sol = solve_ivp(rate, (0.0, t[-1]), [0.0], method="LSODA", rtol=1e-10, atol=1e-12,
                    t_eval=t, max_step=0.005)
    want = sol.y[0] / RPM
    error = np.abs(rpm - want).max() / block["operating_rpm"]
    print(f"\nstart-up: released at {released:.3f} s, {rpm[-1]:.3f} rpm at 3 s (ODE "
          f"{want[-1]:.3f}); largest difference {error:.2e} of the operating speed")
    assert error < 1e-3
    # the latch: the ground crossed 60 rpm in the step ending at the release (10 ms)
    crossing = np.interp(60.0, rpm0, t)
    assert released - 0.01 - 1e-9 <= crossing <= released + 1e-9
    assert rpm[-1] > 100


def test_the_startup_scene_reaches_its_operating_point():
    """`simulate startup` at N = 2 for 4 s: from 0 rpm it is released at 60 rpm, reaches
    the rigid-shaft point (120.0005 rpm, within 1 %) and stays; the report says it; the
    energy balance closes to 1e-3 of the work in."""
    p = scene.load("startup", elements=2)
    series = simulate.compute(p, until_s=4.0, progress=False)
    block = series.summary["startup"]
    print(f"\n{simulate.report(series)}")
    assert series.rows[0, 8] == 0.0
    assert block["operating_rpm"] == pytest.approx(120.0005, rel=1e-5)
    assert block["released_at_s"] is not None and block["reached_at_s"] is not None
    assert block["released_at_s"] < block["reached_at_s"] < 4.0
    assert abs(series.rows[-1, 8] / block["operating_rpm"] - 1) < 0.01
    assert "start-up: generator released at 60 rpm" in simulate.report(series)
    assert series.summary["energy"]["balance_of_work_in"] < 1e-3
    from test_docs import undocumented  # docs/reference/summary.md has the startup block
    assert undocumented(series.summary) == []


def test_a_startup_cut_short_says_it_did_not_reach_the_point():
    """The same scene stopped at 1 s: released (0.93 s) but not at the operating point;
    the summary's reached_at_s is None and the report says so, with the members' line
    naming the first limit (none met here)."""
    series = simulate.compute(scene.load("startup", elements=2), until_s=1.0, progress=False)
    block = series.summary["startup"]
    text = simulate.report(series)
    assert block["released_at_s"] == pytest.approx(0.93, abs=0.01)
    assert block["reached_at_s"] is None
    assert "did not reach the operating point 120.00 rpm by t = 1.000 s" in text
    assert "first limit: none" in text
