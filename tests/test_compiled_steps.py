"""Issue 46: alpha2's steps compiled (``-rawehelix_ts_compiled 1``,
solvers/compiled_step.py) against PETSc TSALPHA2 and dolfinx's assembly.  The
temporal order and the energy balance run on the compiled path too
(tests/test_dynamics.py, the "compiled" rows)."""

import numpy as np
import pytest
from mpi4py import MPI

from rawehelix.errors import SceneError
from rawehelix.solvers.dynamics import DynamicsSolver
from rawehelix.solvers.forced import FEBackend
from rawehelix.studies import scene, simulate


def test_compiled_forms_equal_dolfinx_assembly():
    """F and J by the FFCx kernels from numba equal dolfinx's assembly at a
    perturbed state (measured: 0.0 relative), and a wrong state is told apart."""
    from rawehelix.solvers.compiled_step import CompiledChordAlpha
    params = scene.load("mobile_end", elements=2, degree=3)
    stepper = CompiledChordAlpha(params)
    op, n = stepper.op, stepper.op.n
    X = op.X_stationary + 1e-3 * np.random.default_rng(1).standard_normal(3 * n)
    op.set_time(0.37)
    err_r, err_j = stepper.forms.check(X, 3.1e3, 7.7e6)
    assert err_r <= 1e-12 and err_j <= 1e-12
    R = stepper.forms.residual(X, stepper.forms.constants())
    op.load(X[:n] + 1e-6, X[n:2 * n], X[2 * n:])
    assert np.abs(op.residual() - R).max() > 1e-9 * np.abs(R).max()


@pytest.mark.parametrize("scene_name, changes", [
    ("mobile_end", {}),  # the circle (70) and the torque ramp (69)
    ("mobile_end", {"circle_frequency_Hz": 3.0}),  # another circle
    ("example", {}),  # a fixed top, the ramp only
])
def test_fitted_time_data_equal_set_time(scene_name, changes):
    """The stretch's time data by the fit of the forcing laws (solvers/compiled_time_data.py)
    equal the formulation's set_time at every stage time to round-off (measured: 2.5e-16
    relative), at a sweep's frequency and phase too (a new q: a new fit), and the form is
    left at the stretch's end."""
    from rawehelix.solvers.compiled_step import CompiledChordAlpha
    params = scene.load(scene_name, elements=2, degree=3)
    params = params.replace(ends=changes) if changes else params
    stepper = CompiledChordAlpha(params)
    op = stepper.op
    for q in (op.form.rod.q, op.form.rod.q.at_frequency(7.0, t_start=0.9)):
        op.form.rod.q = q
        times = 0.37 + np.arange(60) * 0.0137
        fitted = stepper.time_data(times, 1.2)
        assert stepper._fit._map is not None and op.form.time.value == 1.2
        exact = stepper.time_data(times)
        for a, b in zip(fitted, exact):
            assert np.abs(a - b).max() <= 1e-14 * max(1.0, np.abs(b).max())


def test_time_data_not_the_forcing_laws_are_not_fitted():
    """Other time data (a hook: weather, release, end twist) or data that no affine map of
    the forcing laws gives are refused: the caller falls back to set_time."""
    from rawehelix.solvers.compiled_step import CompiledChordAlpha
    from rawehelix.solvers.compiled_time_data import TimeDataFit
    stepper = CompiledChordAlpha(scene.load("mobile_end", elements=2, degree=3))
    times = np.linspace(0.1, 0.2, 5)
    assert stepper._fit(times, 0.2, stepper.forms.constants().size) is not None
    stepper.op.form.time_data.append(lambda t: None)
    assert stepper._fit(times, 0.2, stepper.forms.constants().size) is None
    square = TimeDataFit(stepper.op.form, lambda t: (np.array([t * t]), np.zeros(0)))
    stepper.op.form.time_data.clear()
    assert square(times, 0.2, 1) is None


def test_compiled_steps_equal_petsc_alpha2():
    """200 steps at 10 Hz (N = 4, p = 3, dt = 0.5 ms) from the stationary state
    through the sweep's backend: TSALPHA2 with full Newton against the compiled
    steps (the start by ChordAlpha's half steps, the rest compiled): the state and
    T(0) at every step to the Newton tolerances (as the chord loop's test in
    test_speed.py), with far fewer factorisations than steps."""
    params = scene.load("mobile_end", elements=4, degree=3)
    out = []
    for options in (FEBackend.FULL_NEWTON, {"ts_compiled": 1}):
        backend = FEBackend(params, MPI.COMM_SELF, options=options)
        backend.set_frequency(10.0, 0.0)
        t1 = 200 * backend.dt
        state, tension = backend.advance(backend.stationary(), 0.0, t1, np.linspace(0.0, t1, 201))
        out.append((state, tension, backend.solver))
    (ts, T_ts, _), (fast, T_fast, solver) = out
    assert np.max(np.abs(fast.w - ts.w)) <= 1e-8
    assert np.max(np.abs(fast.w_t - ts.w_t)) <= 1e-5 * np.max(np.abs(ts.w_t))
    assert np.max(np.abs(T_fast - T_ts)) <= 1e-5 * np.max(np.abs(T_ts))
    stepper = solver.compiled.stepper
    assert stepper.steps == 202 and stepper.factorisations < 20


def test_simulate_with_compiled_steps_equals_ts():
    """`rawehelix simulate` with -rawehelix_ts_compiled 1 writes the TS run's time
    series (N = 2, 0.05 s at 10 Hz, output every 2 ms) to the Newton tolerance."""
    params = scene.load("mobile_end", elements=2, degree=3)
    rows = [simulate.compute(params, until_s=0.05, options=o, progress=False).rows
            for o in ({}, {"ts_compiled": 1})]
    assert rows[0].shape == rows[1].shape == (26, len(simulate.COLUMNS))
    assert np.allclose(rows[0][:, 0], rows[1][:, 0], rtol=1e-12, atol=1e-12)
    scale = np.abs(rows[0]).max(axis=0) + 1e-12
    assert np.max(np.abs(rows[1] - rows[0]) / scale) <= 1e-6


@pytest.mark.parametrize("options, allowed", [
    ({"ts_adapt_type": "basic"}, "fixed steps"),
    ({"ts_type": "cn", "ts_adapt_type": "none"}, "alpha2 only")])
def test_compiled_steps_refuse_what_they_do_not_step(options, allowed):
    """Adaptive steps or another TS type: refused before any step, naming the option."""
    params = scene.load("mobile_end", elements=2, degree=3)
    with pytest.raises(SceneError, match=f"-rawehelix_ts_compiled: .*{allowed}"):
        DynamicsSolver(params, MPI.COMM_SELF, options={"ts_compiled": 1, **options})



@pytest.mark.mpi
def test_compiled_steps_refuse_two_ranks():
    """MPI: the compiled steps are one rank's; on 2 ranks every rank refuses alike
    (no rank left waiting), naming the option."""
    comm = MPI.COMM_WORLD
    if comm.size == 1:
        pytest.skip("refuses on 2 ranks: run under mpirun -n 2")
    params = scene.load("mobile_end", elements=2, degree=3)
    with pytest.raises(SceneError, match="-rawehelix_ts_compiled: the compiled steps run on one rank"):
        DynamicsSolver(params, comm, options={"ts_compiled": 1})


def test_compiled_steps_not_loaded_say_so():
    """The steps register themselves when solvers/compiled_step.py is imported
    (simulate and the sweep's backend import it); a registry without them refuses
    with the option's name instead of running PETSc TS silently."""
    from rawehelix.errors import SolverError
    from rawehelix.solvers import compiled_dynamics, compiled_step, dynamics
    assert dynamics.ADVANCES["compiled"] is compiled_step.CompiledAdvance
    with pytest.raises(SolverError, match="-rawehelix_ts_compiled: the compiled steps are not loaded"):
        compiled_dynamics.check_loaded({})


def test_a_failure_inside_a_batch_runs_the_outputs_before_it(monkeypatch):
    """Several outputs' stretches run in one compiled call (compiled_step.BATCH); a step
    failing after the 10th (inside the first call, after the outputs of steps 4 and 8)
    writes those two outputs from their kept states, then stops there, naming the time
    of the last good output and the option."""
    from rawehelix.solvers import compiled_step
    real = compiled_step._steps

    def fails_after_10(*args):
        args = list(args)
        args[9], args[12] = args[9][:10], args[12][:10]  # 10 steps of the stretch's data
        real(*args)
        return compiled_step.NO_CONVERGENCE, 10, 1.0, 0.5

    params = scene.load("mobile_end", elements=2, degree=3)
    full = simulate.compute(params, until_s=0.02, options={"ts_compiled": 1}, progress=False).rows
    monkeypatch.setattr(compiled_step, "_steps", fails_after_10)
    with pytest.raises(simulate.SimulationError,
                       match=r"stopped at t = 0.004 s .*no convergence.*-rawehelix_ts_compiled") as err:
        simulate.compute(params, until_s=0.02, options={"ts_compiled": 1}, progress=False)
    rows = err.value.partial.rows
    assert rows.shape[0] == 3 and np.allclose(rows[:, 0], [0.0, 0.002, 0.004])
    assert np.array_equal(rows, full[:3])  # the kept states are the outputs' states
