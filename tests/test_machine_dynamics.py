"""Issue 43, simulate with the machine: the rotor at the top (its table's aerodynamic
torque Q(Omega, V_n) and its spin inertia) and the generator at the ground (MPPT,
constant torque, rated-power cap, or Eq. 40), in the TS forms (solvers/end_torques.py).

* the UFL tables reproduce numpy's / scipy's interpolation, and the UFL generator its
  numpy law, at many speeds;
* simulated = solved: started near the rigid-shaft operating point (scipy's root of
  Q = tau, independent of the FE), the run settles to it (Omega to 1e-6) and to the
  stationary state twisted by that torque (tension to 1e-5 N, twist end to end);
* the energy balance: work in = generator work + dissipation + change in stored energy
  (with the rotor's spin), to 1e-4 of the work in, in both TS forms;
* the paper's ground law (Eq. 40) through the machine's path reproduces
  nominal_operation to 1e-10.

The laws are operation/'s (rotor.py, generator.py); the references are scipy's
(PchipInterpolator, brentq), numpy's interp and the stationary solver."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator
from scipy.optimize import brentq

import dolfinx.fem
import dolfinx.mesh
import ufl
from mpi4py import MPI
from petsc4py import PETSc

from rawehelix.forms import end_torques as forms
from rawehelix.operation.generator import GeneratorLaw
from rawehelix.operation.rotor import RotorLaw
from rawehelix.solvers import end_torques
from rawehelix.solvers.dynamics import DynamicsSolver
from rawehelix.solvers.energy_account import EnergyAccount
from rawehelix.solvers.stationary import StationarySolver
from rawehelix.studies import scene

RHO = 1.225  # [kg/m^3]
V_N = 4.47  # the hub's wind along the rotor's axis [m/s]: ~120 rpm at MPPT


def rotor(J=2.0):
    """A small rotor: R = 2.135 m, Cp_max 0.4 at lambda 6 (25 N m at 120 rpm under MPPT
    at V_n = 4.47 m/s), its table interpolated by operation/rotor.py (PCHIP)."""
    tsr = np.linspace(2.0, 10.0, 9)
    return RotorLaw(tsr, 0.4 * (1 - ((tsr - 6.0) / 4.5) ** 2), 0.3 + 0.06 * tsr, radius_m=2.135,
                    spin_inertia_kgm2=J)


def mppt(law):
    """k = 1/2 rho pi R^5 Cp_max / lambda_opt^3 (the issue's MPPT gain)."""
    return GeneratorLaw("mppt", 0.5 * RHO * math.pi * law.radius_m**5 * law.cp_max
                        / law.tsr_opt**3)


class _Evaluator:
    """A UFL scalar of one Constant x evaluated by assembling it over the unit interval."""

    def __init__(self, build):
        mesh = dolfinx.mesh.create_unit_interval(MPI.COMM_SELF, 1)
        self.x = dolfinx.fem.Constant(mesh, PETSc.ScalarType(1.0))
        self.form = dolfinx.fem.form(build(self.x) * ufl.dx(domain=mesh))

    def __call__(self, x):
        self.x.value = x
        return dolfinx.fem.assemble_scalar(self.form)


def test_tables_in_ufl_are_the_rotors_and_scipys_interpolation():
    """Cp in UFL at 400 tip-speed ratios across the table (its rows too) equals the rotor
    law's (operation/rotor.py, PCHIP) and scipy's PchipInterpolator to 1e-13; a
    piecewise-linear table equals numpy's interp to 1e-14."""
    law = rotor()
    lam = np.concatenate([np.linspace(2.0, 10.0, 397), law.table_tsr[[1, 4, 7]]])
    ufl_cp = _Evaluator(end_torques.cp_polynomial(law))
    got = np.array([ufl_cp(x) for x in lam])
    assert np.abs(got - law.cp(lam)).max() < 1e-13
    assert np.abs(got - PchipInterpolator(law.table_tsr, law.table_cp)(lam)).max() < 1e-13
    linear = forms.PiecewisePolynomial.linear(law.table_tsr, law.table_ct)
    ufl_ct = _Evaluator(linear)
    want = np.interp(lam, law.table_tsr, law.table_ct)
    assert np.abs(np.array([ufl_ct(x) for x in lam]) - want).max() < 1e-14


@pytest.mark.parametrize("law", [
    GeneratorLaw("mppt", mppt_gain_Nms2=0.16),
    GeneratorLaw("torque", torque_Nm=20.0),
    GeneratorLaw("mppt", mppt_gain_Nms2=0.16, rated_power_W=250.0),
    GeneratorLaw("torque", table_rpm=[0.0, 50.0, 140.0], table_torque_Nm=[0.0, 10.0, 30.0],
                 rated_power_W=400.0)],
    ids=["mppt", "constant", "mppt-rated", "table-rated"])
def test_generator_in_ufl_is_its_law(law):
    """The UFL generator torque (normalised) times GJ/L0 at 60 spins from 1 to 20 rad/s
    equals the numpy law's, the rated cap, the table's kinks and its flat end included."""
    q = scene.load("nominal_operation", elements=2).normalised()
    tau = end_torques.generator_torque(end_torques.Machine(generator=law), q)
    ufl_tau = _Evaluator(tau)
    omega = np.linspace(1.0, 20.0, 60)
    got = np.array([ufl_tau(w * q.t_scale) for w in omega]) * q.torque_scale
    want = law.torque(omega)
    assert np.abs(got - want).max() < 1e-12 * np.abs(want).max()


def machine_scene(elements=4, torsion_s=0.1):
    """nominal_operation without its ramp and controller, with torsional Kelvin-Voigt
    damping (tau_t = 0.1 s: the generator's 4 N m s on the ground end's small inertia
    nearly clamps it, and the helix's torsional modes would ring for minutes)."""
    return scene.load("nominal_operation", elements=elements, degree=3).replace(
        torque={"top_Nm": 0.0}, controller={"k1": 0.0, "k2": 0.0, "target_rpm": 0.0},
        damping={"torsion_s": torsion_s})


def rigid_shaft(law, gen):
    """scipy's root of Q(Omega, V_n) = tau(Omega) inside the table [rad/s]."""
    lo, hi = np.array(law.tsr_range) * V_N / law.radius_m
    return brentq(lambda w: law.torque(w, V_N, RHO) - gen.torque(w), lo * 1.0001, hi * 0.9999,
                  xtol=1e-14)


def run(until_s, ts_type="alpha2", start_torque=0.0, spin_factor=1.01, options=None,
        dt_s=1e-3):
    """The machine scene started untwisted (``start_torque`` 0) at spin_factor x the
    rigid-shaft spin, run to ``until_s`` with the energy account at every step."""
    p, law = machine_scene().replace(time={"dt_s": dt_s}), rotor()
    gen = mppt(law)
    omega = rigid_shaft(law, gen)
    q = p.normalised()
    solver = DynamicsSolver.spinning(p, end_torques.Machine(law, gen, V_N, RHO),
                                     spin_factor * omega * q.t_scale, start_torque / q.torque_scale,
                                     options={"ts_type": ts_type, **(options or {})})
    account = EnergyAccount()
    account(solver)
    solver.advance(until_s / q.t_scale, on_step=account)
    return solver, account, omega, law.torque(omega, V_N, RHO)


#: the settling run's steps: fixed 50 ms (400 steps, ~1.5 s).  Adaptive steps control
#: the error relative to |alpha|, which grows as Omega t in a spinning run: at the
#: default 1e-4 they grew until the end spins stalled 8e-6 off the root at 20 s, and a
#: tighter tolerance took 2000-4000 steps
SETTLE = {"ts_adapt_type": "none"}
SETTLE_DT_S = 0.05


@pytest.fixture(scope="module")
def settled():
    return run(20.0, options=SETTLE, dt_s=SETTLE_DT_S)


@pytest.fixture(scope="module")
def transients():
    """2 s from the same start with adaptive steps, alpha2 and Crank-Nicolson (the
    first-order form: the rotor's -J alpha_tt from the rates' rates)."""
    return {ts: run(2.0, ts) for ts in ("alpha2", "cn")}


def test_simulated_settles_to_the_solved_operating_point(settled):
    """From the untwisted stationary state spinning 1 % fast, 20 s (N = 4, alpha2 at
    fixed 50 ms steps): the spin at both ends equals scipy's rigid-shaft root to 1e-6
    (measured 1.8e-13 and 1.4e-13), and the tension at s = 0 and the twist end to end
    equal the stationary state's under that torque (set_end_torques) to 1e-5 N (the start
    is 1.05e-5 N off) and 1e-6 (the twist is Q L0 / GJ, the solid section's)."""
    solver, _, omega, torque = settled
    q = solver.q
    v = solver.probes.values()
    for end in ("spin0", "spin1"):
        assert abs(v[end] / q.t_scale / omega - 1) < 1e-6
    stationary = StationarySolver(solver.params)
    stationary.set_end_torques(ground=torque / q.torque_scale, top=torque / q.torque_scale)
    result = stationary.solve()
    fields = solver.probes.fields()
    assert abs(q.tension_N(v["tension0"] - result.tension[0])) < 1e-5
    twist = fields["alpha"][np.argmax(fields["s"])] - fields["alpha"][np.argmin(fields["s"])]
    assert twist == pytest.approx(torque / q.torque_scale, rel=1e-6)  # Q L0 / GJ, solid section
    assert abs(q.torque_Nm(v["m0"]) - torque) < 1e-6 * torque  # the generator holds Q


@pytest.mark.parametrize("ts_type", ["alpha2", "cn"])
def test_energy_balance_with_the_rotor(transients, ts_type):
    """work in = generator work + dissipation + change in stored energy (rod + rotor
    spin) to 1e-4 of the work in, over the 2 s transient from the untwisted start (the
    twist's 1/2 Q^2 L0 / GJ goes into the stored energy), in both TS forms."""
    solver, account, _, torque = transients[ts_type]
    block = account.summary(solver.q)
    print(f"\n{ts_type}: {block}")
    assert block["work_in_J"] > 500 and block["stored_change_J"] > 10
    assert block["damping_dissipated_J"] > 1
    assert block["balance_of_work_in"] < 1e-4


def test_first_order_form_carries_the_rotor_inertia(transients):
    """Crank-Nicolson on the first-order form and alpha2 on the second-order one agree
    on the top spin after the 2 s transient to 1e-5 (each has its own time error)."""
    s1, s2 = (transients[ts][0].probes.values()["spin1"] for ts in ("cn", "alpha2"))
    print(f"\ncn against alpha2: {abs(s1 - s2) / abs(s2):.2e}")
    assert abs(s1 - s2) < 1e-5 * abs(s2)


def test_simulate_with_the_rotor_example_keeps_its_operating_point(tmp_path):
    """`simulate rotor_example` (N = 4, 1 s): it starts at the rigid-shaft point of
    operation/rigid_shaft.py (120.0005 rpm, 25.0002 N m at 6.6131 m/s) and keeps it
    (rotor_rpm to 1e-6), writes the machine's columns (power_W = tau Omega at the ground,
    thrust_N the law's at that speed, the hub's wind), and its summary's energy block
    closes to 1e-4 of the work in (measured 2e-9: it is at rest in the rotating sense).
    The paper's scene keeps its 8 columns and has no energy block."""
    from rawehelix.operation.rigid_shaft import operating_points
    from rawehelix.studies import simulate
    p = scene.load("rotor_example", elements=4)
    series = simulate.compute(p, until_s=1.0, progress=False)
    m = end_torques.machine_of(p)
    (point,) = operating_points(m.rotor, m.generator, m.wind_n_m_s, m.air_density_kg_m3)
    out = series.write(tmp_path, pictures=False)
    header = (out / "time_series.csv").read_text().splitlines()[0].split(",")
    assert header[-4:] == ["rotor_rpm", "power_W", "thrust_N", "wind_hub_m_s"]
    rows = series.rows
    assert np.abs(rows[:, 8] / point.rotor_rpm - 1).max() < 1e-6
    omega0 = rows[:, 1] * 2 * math.pi / 60
    assert np.allclose(rows[:, 9], rows[:, 4] * omega0, rtol=1e-12)
    assert rows[-1, 9] == pytest.approx(point.power_W, rel=1e-6)
    assert rows[-1, 10] == pytest.approx(point.thrust_N, rel=1e-9)
    assert np.all(rows[:, 11] == 6.6131)
    energy = series.summary["energy"]
    assert energy["work_in_J"] == pytest.approx(point.rotor_power_W * 1.0, rel=1e-5)
    assert energy["balance_of_work_in"] < 1e-4
    assert "energy: work in" in simulate.report(series)
    from test_docs import undocumented  # docs/reference/summary.md has every new field
    assert undocumented(series.summary) == []
    paper = simulate.compute(scene.load("nominal_operation", elements=2), until_s=0.02,
                             progress=False)
    assert paper.rows.shape[1] == len(simulate.COLUMNS) and "energy" not in paper.summary


def test_a_rotor_whose_torque_is_the_papers_ramp_reproduces_nominal_operation(monkeypatch):
    """nominal_operation (N = 4, 3 s: the ramp (69) to 69 % of its 25 N m under the
    controller (40)) against the same scene with torque.top_Nm = 0 and a rotor whose
    torque is the ramp in time (forms.RampTorque, no inertia) on the machine's path
    (the ends' laws behind their end indicators, Eq. 40 as the ground's law): spins,
    ground torque and tension agree to 1e-10 of their size at every 0.1 s (fixed 10 ms
    steps: an adaptive step that flips on round-off would part them by its time error;
    measured 5e-13)."""
    p = scene.load("nominal_operation", elements=4, degree=3).replace(time={"dt_s": 0.01})
    q = p.normalised()
    fixed = {"ts_adapt_type": "none"}

    def series(params, machine=None):
        sv = DynamicsSolver.from_stationary(params, options=fixed) if machine is None else \
            DynamicsSolver(params, options=fixed, machine=machine)
        if machine is not None:
            sv.set_state(StationarySolver(params).solve().state)
        rows = []
        sv.advance(3.0 / q.t_scale, output_every=0.1 / q.t_scale, on_output=lambda s: rows.append(
            [s.probes.values()[k] for k in ("spin0", "spin1", "m0", "tension0")]))
        return np.array(rows), sv

    paper, _ = series(p)
    ramp = forms.RampTorque(q.mN0, q.t0)
    monkeypatch.setattr(end_torques.EndTorques, "of",
                        classmethod(lambda cls, q_, m: cls(m, rotor=ramp)))
    machine = end_torques.Machine(rotor="the paper's ramp", wind_n_m_s=1.0)
    rotor_run, solver = series(p.replace(torque={"top_Nm": 0.0}), machine)
    assert solver.form.end_torques is not None  # the machine's path, not the paper's
    assert len(paper) == 31 and paper[-1, 2] > 15 / q.torque_scale
    scale = np.abs(paper).max(axis=0)
    print(f"\nramp rotor against nominal_operation: {np.abs(rotor_run - paper).max(axis=0) / scale}")
    assert np.all(np.abs(rotor_run - paper) <= 1e-10 * scale)


def test_simulate_with_the_papers_ground_law_holds_its_target():
    """rotor_example with generator.law = "paper" (Eq. 40, k1 = k2 = 0.5, 110 rpm; N = 4,
    1 s): it starts at the target spin twisted by Q(110 rpm) (Eq. 40's C balancing it),
    holds 110 rpm to 1e-6 with the ground torque Q(110 rpm) of the rotor law, and the
    energy block closes to 1e-4 (measured 3e-8; 4e-2 before the account set the step's
    own time: Eq. 40's k1 (alpha - alpha_dot* t) read at alpha2's t_{n + alpha_f})."""
    from rawehelix.studies import simulate
    p = scene.load("rotor_example", elements=4).replace(
        generator={"law": "paper", "mppt_gain_Nms2": 0.0},
        controller={"k1": 0.5, "k2": 0.5, "target_rpm": 110.0})
    series = simulate.compute(p, until_s=1.0, progress=False)
    m = end_torques.machine_of(p)
    omega = 110 * 2 * math.pi / 60
    torque = m.rotor.torque(omega, m.wind_n_m_s, m.air_density_kg_m3)
    assert np.abs(series.rows[:, [1, 3, 8]] / 110 - 1).max() < 1e-6
    assert np.abs(series.rows[:, 4] / torque - 1).max() < 1e-6
    assert series.summary["energy"]["balance_of_work_in"] < 1e-4


def test_a_rotor_leaving_its_table_stops_the_run(monkeypatch):
    """rotor_example started at tip-speed ratio 9, past its table's 8 (the start point
    forced there): the first step stops the run with SimulationError naming the wind and
    the rotor speed (the command line's exit 1, the partial series kept), never a silent
    extrapolation of Cp."""
    import dataclasses

    from rawehelix.operation.rigid_shaft import operating_points
    from rawehelix.studies import machine, simulate
    p = scene.load("rotor_example", elements=2)
    m = end_torques.machine_of(p)
    (point,) = operating_points(m.rotor, m.generator, m.wind_n_m_s, m.air_density_kg_m3)
    fast = dataclasses.replace(point, omega_rad_s=9.0 * m.wind_n_m_s / m.rotor.radius_m)
    monkeypatch.setattr(machine, "start_point", lambda params, ends: fast)
    with pytest.raises(simulate.SimulationError, match=r"tip-speed ratio 9 at wind 4\.676 m/s "
                       r"and rotor speed 200\.9 rpm") as err:
        simulate.compute(p, until_s=0.5, progress=False)
    assert "the run stopped at t = 0 s" in str(err.value)
    assert err.value.partial.summary["complete"] is False


def test_a_stiff_helix_spins_down_like_the_rigid_shaft():
    """rotor_example with GJ x 1000 (a rigid shaft), started 1e-4 fast at its operating
    point, fixed 5 ms steps for 1 s: the top's spin excess decays as exp(s t) with the
    rigid shaft's rate s = d(Q - tau)/dOmega / (J + 2 M EI / EA) (operation/rigid_shaft's
    slope; the rotor's J = 1.2 kg m^2 and the rod's own spin inertia 0.36 kg m^2, Eq. 27's
    rotational inertia): fitted to 1e-3 (measured 1e-4; without the rotor's inertia the
    rate would be 4.3 x).  It checks J's place and scale in the top's torque."""
    from rawehelix.operation.rigid_shaft import operating_points
    p = scene.load("rotor_example", elements=4).replace(helix={"GJ_Nm2": 1.4e5},
                                                         time={"dt_s": 0.005})
    m = end_torques.machine_of(p)
    (point,) = operating_points(m.rotor, m.generator, m.wind_n_m_s, m.air_density_kg_m3)
    q = p.normalised()
    solver = DynamicsSolver.spinning(p, m, point.omega_rad_s * (1 + 1e-4) * q.t_scale,
                                     point.rotor_torque_Nm / q.torque_scale,
                                     options={"ts_adapt_type": "none"})
    rows = []
    solver.advance(1.0 / q.t_scale, output_every=0.1 / q.t_scale, on_output=lambda s: rows.append(
        (q.time_s(s.t), s.probes.values()["spin1"] / q.t_scale / point.omega_rad_s - 1)))
    t, excess = np.array(rows).T
    inertia = m.rotor.spin_inertia_kgm2 + 2 * p.helix.mass_kg * p.helix.EI_Nm2 / p.helix.EA_N
    rate = point.slope_Nms / inertia  # [1/s]
    fitted = np.polyfit(t, np.log(excess), 1)[0]
    print(f"\nrigid shaft: rate {rate:.6f} 1/s, fitted {fitted:.6f} 1/s")
    assert fitted == pytest.approx(rate, rel=1e-3)


def test_simulate_with_a_wind_profile_runs_and_closes_its_energy():
    """`simulate rotor_example --set wind.profile="power"` (N = 2, 1 s): the energy
    account's drag power reads the wind at each point's height (solvers/ts_forms.py passed
    no r, and the power-law profile refused to be built without it); the run finishes and
    its energy block closes to 1e-4 of the work in."""
    from rawehelix.studies import simulate
    p = scene.load("rotor_example", elements=2, overrides={"wind.profile": "power"})
    series = simulate.compute(p, until_s=1.0, progress=False)
    assert series.rows[-1, 0] == pytest.approx(1.0)
    assert series.summary["energy"]["balance_of_work_in"] < 1e-4
