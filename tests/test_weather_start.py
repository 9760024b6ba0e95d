"""Issue 44, where a run in moving wind starts and where it stops (studies/machine.py).

* a turbulent run starts at the operating point of its mean wind, the one ``rawehelix
  operate`` finds at that wind (the relative equilibrium of the helix, an independent
  solve), not at the rigid-shaft root of the record's gust at t = 0;
* a wind that drops under the spinning rotor (a step down) drives its tip-speed ratio
  past the table: the run stops with exit 1 naming the time, the wind and the rotor
  speed, never extrapolating Cp."""

from __future__ import annotations

import re

import numpy as np
import pytest

from rawehelix import api
from rawehelix.operation.rigid_shaft import operating_points
from rawehelix.operation.rotor import RPM
from rawehelix.solvers import end_torques
from rawehelix.studies import scene, simulate

MEAN = 5.0  # the run's mean wind [m/s]


def test_a_turbulent_run_starts_at_its_mean_winds_operating_point():
    """turbulent_rated, seed 3 at 5 m/s (N = 2): the record's hub wind at t = 0 is 4.41
    m/s, 12 % under the mean; the run's start (summary machine block, and the first
    output's rotor_rpm) is operate's point at 5 m/s to 1e-9 (its tip-speed ratio, and its
    speed at simulate's V_n), and 10 % off the rigid-shaft
    point of the wind at t = 0 (which the start took before: seeds then started 20 %
    off their mean's speed)."""
    p = scene.load("turbulent_rated", elements=2, overrides={
        "wind.seed": 3, "wind.speed_m_s": MEAN, "wind.duration_s": 60.0, "time.until_s": 60.0})
    m = end_torques.machine_of(p)
    assert abs(m.wind_hub_m_s / MEAN - 1) > 0.1  # the gust at t = 0: the test can fail
    at_zero = max((q for q in operating_points(m.rotor, m.generator, m.wind_n_m_s,
                                               m.air_density_kg_m3) if q.stable),
                  key=lambda q: q.omega_rad_s)
    (point,) = [q for q in api.operate(p, [MEAN]).points if q.stable]
    want = point.omega_rad_s / RPM  # [rpm]
    series = simulate.compute(p, until_s=0.05, progress=False)
    start = series.summary["machine"]
    print(f"\nstart {start['start_rotor_rpm']:.9f} rpm at {start['wind_hub_m_s']:.6f} m/s; "
          f"operate {want:.9f} rpm; the t = 0 wind's {at_zero.rotor_rpm:.6f} rpm")
    assert start["wind_hub_m_s"] == pytest.approx(MEAN, rel=1e-12)
    # simulate's V_n takes the [ends] chord as the rotor's axis, operate the solved top's
    # tangent (weather.md, "Not modelled yet"): 0.34 % apart here, so Omega compares at
    # operate's tip-speed ratio and simulate's V_n (the MPPT law's root is one tsr)
    assert start["tsr"] == pytest.approx(point.tsr, rel=1e-9)
    axis = start["wind_n_m_s"] / point.v_n_m_s
    assert start["start_rotor_rpm"] == pytest.approx(want * axis, rel=1e-9)
    assert series.rows[0, 8] == pytest.approx(want * axis, rel=1e-9)
    assert abs(axis - 1) < 5e-3
    assert abs(at_zero.rotor_rpm / want - 1) > 0.1


def test_a_wind_that_drops_under_the_rotor_stops_the_run_with_its_time():
    """rotor_example (table tsr 1 to 8) with the wind stepping from 6.61 to 2.5 m/s at
    t = 0.2 s (no rise): the rotor at 120 rpm would turn at tip-speed ratio 14 in it; the
    step that meets the drop stops the run with SimulationError (exit 1) naming the
    table, the wind along the axis and the rotor speed of that moment (tsr = Omega R / V_n
    of those two) and the simulated time it stopped at, just before 0.2 s, its series
    kept to there (measured: tsr 8.056 at 2.794 m/s and 107.5 rpm, t = 0.1294 s)."""
    p = scene.load("rotor_example", elements=2).replace(
        wind={"kind": "step", "step_to_m_s": 2.5, "step_time_s": 0.2, "rise_time_s": 0.0})
    with pytest.raises(simulate.SimulationError, match=r"is outside its table \[1, 8\]: extend "
                       r"the rotor's table") as err:
        simulate.compute(p, until_s=0.5, progress=False)
    text = str(err.value)
    found = re.search(r"tip-speed ratio ([\d.]+) at wind ([\d.]+) m/s and rotor speed ([\d.]+) "
                      r"rpm.*the run stopped at t = ([\d.]+) s \(simulated\)", text)
    tsr, v_n, rpm, stopped = map(float, found.groups())
    assert tsr > 8 and 2.5 * 0.7071 * 0.999 < v_n < 6.6131 * 0.7071
    assert tsr == pytest.approx(rpm * RPM * 2.0 / v_n, rel=2e-3)  # R = 2 m; 4 digits shown
    assert 0.1 < stopped < 0.21
    partial = err.value.partial
    assert partial.summary["complete"] is False and partial.rows[-1, 0] <= stopped + 1e-12


def test_energy_balance_in_turbulence():
    """turbulent_rated (N = 2, seed 1 at its rated 6.61 m/s, 2 s of its record): work in
    = generator work + dissipation (the drag's power of the moving air included) + change
    of stored energy, to 1e-3 of the work in (the step's and the gust's: test_weather.py::
    test_energy_balance_in_moving_wind; the start-up's: test_startup.py)."""
    p = scene.load("turbulent_rated", elements=2, overrides={"wind.duration_s": 60.0,
                                                             "time.until_s": 60.0})
    series = simulate.compute(p, until_s=2.0, progress=False)
    energy = series.summary["energy"]
    print(f"\nturbulent: {energy}")
    assert series.rows[-1, 0] == pytest.approx(2.0)
    assert energy["work_in_J"] > 100
    assert abs(energy["stored_change_J"]) > 1e-3 * energy["work_in_J"]  # the wind moves it
    assert energy["balance_of_work_in"] < 1e-3


@pytest.mark.mpi
def test_moving_wind_on_two_ranks_equals_one():
    """turbulent_rated at N = 2, 0.3 s at fixed 20 ms steps, on the 2 ranks of mpirun
    and on rank 0 alone: every column of the time series (the helix's, the rotor's and
    the hub's wind) the same to the solver's tolerance (rtol 1e-8, as
    test_dynamics.py::test_same_numbers_on_one_and_two_ranks); each rank generates the
    record itself (test_wind_series.py::test_the_same_seed_on_one_and_two_ranks: bit for
    bit)."""
    from mpi4py import MPI
    comm = MPI.COMM_WORLD
    if comm.size == 1:
        pytest.skip("compares 1 and 2 ranks: run under mpirun -n 2")
    p = scene.load("turbulent_rated", elements=2, overrides={
        "wind.duration_s": 30.0, "time.until_s": 30.0, "time.dt_s": 0.02,
        "time.output_every_s": 0.1})
    fixed = {"ts_adapt_type": "none"}
    parallel = simulate.compute(p, until_s=0.3, options=fixed, progress=False, comm=comm).rows
    if comm.rank == 0:
        serial = simulate.compute(p, until_s=0.3, options=fixed, progress=False,
                                  comm=MPI.COMM_SELF).rows
        assert parallel.shape == serial.shape and len(serial) == 4
        assert np.ptp(serial[:, 11]) > 0.05  # the wind moves
        scale = np.abs(serial).max(axis=0)  # each column's own size
        worst = (np.abs(parallel - serial) / np.maximum(scale, 1e-300)).max()
        print(f"\n2 ranks against 1: largest difference {worst:.2e} of a column's size")
        assert worst < 1e-8


@pytest.mark.mpi
def test_operate_logs_its_points_on_rank_0_only(caplog):
    """`mpirun -n 2 rawehelix operate` printed each point's log line once a rank; now rank
    0 logs it, and the other ranks nothing (rotor_example at N = 2, one wind)."""
    import logging

    from mpi4py import MPI
    comm = MPI.COMM_WORLD
    if comm.size == 1:
        pytest.skip("the ranks' logs: run under mpirun -n 2")
    p = scene.load("rotor_example", elements=2)
    with caplog.at_level(logging.INFO, logger="rawehelix"):
        api.operate(p, [6.0], comm=comm)
    lines = [r.getMessage() for r in caplog.records if r.getMessage().startswith("operate: 6 m/s")]
    counts = comm.allgather(len(lines))
    assert counts == [1] + [0] * (comm.size - 1), counts


def test_a_wind_reversed_along_the_rotor_stops_the_run_with_its_time():
    """The full-size seeds study (turbulent_rated, 10 min, 5 m/s, seed 4): the wind along
    the rotor's axis reached -7.4e-5 m/s at the hub and the point failed with a bare
    ValueError and no time.  Now a history whose hub wind crosses zero gives a
    SimulationError-class stop naming the wind and the simulated time."""
    import dataclasses
    from rawehelix.operation.wind import WindProfile
    from rawehelix.operation.wind_series import sampled
    from rawehelix.solvers.end_torques import WindBelowRotor, machine_of
    from rawehelix.solvers.snes import SolverError
    from rawehelix.studies import machine as studies_machine
    machine = machine_of(scene.load("rotor_example", elements=2))
    history = sampled(WindProfile(6.6131), [0.0, 1.0, 2.0], reference_m_s=[6.0, 1.0, -1.0])
    moving = dataclasses.replace(machine, history=history)
    assert moving.at(0.5).wind_hub_m_s == pytest.approx(3.5)  # inside: the wind of 0.5 s
    with pytest.raises(WindBelowRotor, match=r"wind along the rotor's axis is -0\.\d+ m/s"):
        moving.at(1.9)
    with pytest.raises(SolverError, match=r"has no such wind; the run stopped at t = 1\.9 s"):
        studies_machine.at(moving, 1.9)
