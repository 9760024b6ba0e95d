"""Issue 46 for the weather's runs (issue 44): the compiled steps
(``-rawehelix_ts_compiled 1``, solvers/compiled_step.py) with a rotor and a generator,
the wind in time, a start-up's release and a lifted top, against PETSc TSALPHA2 with
the same fixed step: `simulate`'s time series (rotor_rpm, power_W, the end tensions)
to the Newton tolerance, and the energy account closing as on TS.  What the compiled
steps still do not run (adaptive steps, the weather scenes' default) is refused before
any step, naming the option.  N = 2, p = 3, fixed steps, a fraction of a second."""

import numpy as np
import pytest
from mpi4py import MPI

from rawehelix.errors import SceneError
from rawehelix.solvers.dynamics import DynamicsSolver
from rawehelix.studies import scene, simulate

FIXED = {"ts_adapt_type": "none"}
COMPILED = {**FIXED, "ts_compiled": 1}
#: the columns a designer reads of a machine's run
MACHINE_COLUMNS = ("rotor_rpm", "power_W", "tension_s0_N", "tension_L0_N", "ground_torque_Nm")


def both(params, until_s):
    """(TS's series, the compiled steps' series) of ``params`` to ``until_s`` [s]."""
    return [simulate.compute(params, until_s=until_s, comm=MPI.COMM_SELF, options=o,
                             progress=False) for o in (FIXED, COMPILED)]


def assert_same_series(ts, fast, rtol):
    """The same output times, and each machine column within ``rtol`` of its largest
    magnitude on TS."""
    assert ts.rows.shape == fast.rows.shape and ts.rows.shape[0] > 10
    assert np.allclose(ts.rows[:, 0], fast.rows[:, 0], rtol=1e-12, atol=1e-12)
    columns = list(ts.columns)
    for name in MACHINE_COLUMNS:
        a, b = ts.rows[:, columns.index(name)], fast.rows[:, columns.index(name)]
        assert np.max(np.abs(b - a)) <= rtol * np.max(np.abs(a)), name
    assert fast.summary["complete"] and fast.summary["steps"] >= ts.summary["steps"]


def test_steady_wind_machine_on_compiled_steps_equals_ts():
    """rotor_example (a rotor at its operating point, the MPPT generator, steady wind):
    0.1 s at 2 ms, the series to 1e-9 (measured 2e-12: a relative equilibrium, one
    Newton iteration a step)."""
    params = scene.load("rotor_example", elements=2, degree=3).replace(
        time={"dt_s": 0.002, "output_every_s": 0.01})
    ts, fast = both(params, 0.1)
    assert_same_series(ts, fast, 1e-9)


def test_turbulent_wind_on_compiled_steps_equals_ts_and_closes_the_energy_balance():
    """turbulent_rated (Kaimal turbulence moving the helix's drag and the rotor's wind
    at each stage time): 0.3 s at 3 ms, the series to 1e-7 of each column; the energy
    account (work in = generator + dissipated + stored) closes on the compiled path as
    on TS (measured 2.04e-6 of the work in on both: the trapezoidal account at 3 ms),
    its terms equal to 1e-6 of the work in (measured 2e-10)."""
    params = scene.load("turbulent_rated", elements=2, degree=3).replace(
        wind={"duration_s": 10.0}, time={"until_s": 0.3, "dt_s": 0.003, "output_every_s": 0.015})
    ts, fast = both(params, 0.3)
    assert_same_series(ts, fast, 1e-7)
    columns = list(ts.columns)
    wind = ts.rows[:, columns.index("wind_hub_m_s")]
    assert np.ptp(wind) > 1e-2  # the wind moved
    e_ts, e_fast = ts.summary["energy"], fast.summary["energy"]
    assert e_ts["balance_of_work_in"] <= 1e-4
    assert e_fast["balance_of_work_in"] <= 2 * e_ts["balance_of_work_in"] + 1e-9
    for key in ("work_in_J", "generator_work_J", "drag_dissipated_J", "stored_change_J"):
        assert abs(e_fast[key] - e_ts[key]) <= 1e-6 * abs(e_ts["work_in_J"]), key


def test_startup_release_on_compiled_steps_at_ts_step():
    """startup (from rest, the generator released at a rotor speed, then ramped): the
    release latches after the same step on both paths (the compiled steps end a stretch
    at every step while a release is pending), the series to 1e-5 (measured 1e-6 over
    6 s at 5 ms)."""
    params = scene.load("startup", elements=2, degree=3).replace(
        generator={"release_rpm": 2.0}, time={"dt_s": 0.005, "output_every_s": 0.02})
    ts, fast = both(params, 0.4)
    released = [s.summary["startup"]["released_at_s"] for s in (ts, fast)]
    assert released[0] is not None and 0.0 < released[0] < 0.3
    assert released[1] == pytest.approx(released[0], abs=1e-9)
    assert_same_series(ts, fast, 1e-5)


def test_lifted_top_in_a_step_of_the_wind_on_compiled_steps_equals_ts():
    """step_rated with the lifted top (r(L0) free under the lifter, the top's mass and the
    rotor's thrust: end-facet terms of the same forms), the step at once, 0.6 s at 20 ms:
    the series to 1e-6 (measured 9e-9) and the top's motion (0.10 m) to 1e-9 m (1e-12)."""
    params = scene.load("step_rated", elements=2, degree=3).replace(
        lifter={"top": "lifted", "force_N": 300.0, "elevation_deg": 50.0},
        wind={"step_time_s": 0.0, "rise_time_s": 0.3}, time={"dt_s": 0.02, "output_every_s": 0.04})
    ts, fast = both(params, 0.6)
    assert_same_series(ts, fast, 1e-6)
    moved = [s.summary["lifter"]["moved_m"] for s in (ts, fast)]
    assert moved[0] > 1e-4 and abs(moved[1] - moved[0]) <= 1e-9


TENSEGRITY = {"section": {"law": "tensegrity"}, "model": {"kinematics": "extensible"}}


def test_tensegrity_section_in_turbulence_on_compiled_steps_equals_ts():
    """The tensegrity's own law (its T(0) is not the solid's linear map, so the compiled
    loop's is NaN and every T(0) comes from the probe): turbulent_rated at N = 2, 0.2 s at
    4 ms, the series to 1e-7."""
    params = scene.load("turbulent_rated", elements=2, degree=3).replace(
        wind={"duration_s": 10.0}, time={"until_s": 0.2, "dt_s": 0.004, "output_every_s": 0.02},
        **TENSEGRITY)
    ts, fast = both(params, 0.2)
    assert_same_series(ts, fast, 1e-7)


def test_sweep_backend_with_the_tensegrity_takes_the_probes_tension():
    """The sweep's backend with the tensegrity on the compiled steps: T(0) by the probe
    after each compiled step (the loop's would be the solid's map), TS's to 1e-6 over
    100 steps at 10 Hz (N = 2)."""
    from rawehelix.solvers.forced import FEBackend
    params = scene.load("mobile_end", elements=2, degree=3).replace(**TENSEGRITY)
    out = []
    for options in (FEBackend.FULL_NEWTON, {"ts_compiled": 1}):
        backend = FEBackend(params, MPI.COMM_SELF, options=options)
        backend.set_frequency(10.0, 0.0)
        t1 = 100 * backend.dt
        out.append(backend.advance(backend.stationary(), 0.0, t1, np.linspace(0.0, t1, 11))[1])
    assert np.all(np.isfinite(out[1]))
    assert np.max(np.abs(out[1] - out[0])) <= 1e-6 * np.max(np.abs(out[0]))


ADAPTIVE = "take fixed steps: add -rawehelix_ts_adapt_type none"


@pytest.mark.parametrize("name, overrides, options, allowed", [
    ("turbulent_rated", {"wind": {"duration_s": 1.0}, "time": {"until_s": 1.0}}, {}, ADAPTIVE),
    ("startup", {}, {}, ADAPTIVE)])
def test_what_the_compiled_steps_do_not_run_is_refused_before_any_step(name, overrides, options,
                                                                       allowed):
    """Adaptive steps (a weather scene's default) are refused when the solver is built, in
    one line naming the option and what to give instead."""
    params = scene.load(name, elements=2, degree=3).replace(**overrides)
    with pytest.raises(SceneError, match=f"-rawehelix_ts_compiled: the compiled steps {allowed}"):
        DynamicsSolver(params, MPI.COMM_SELF, options={"ts_compiled": 1, **options})
