"""The torsion test of Sec. 4 (Fig. 2c, Fig. 5) on the FE rod, with a prescribed end twist.

A 6.76 m segment with the mass per length of the Table 2 helix, stretched to
T_e = 200 N (the paper's nominal tension), horizontal and without wind; the
end s = 0 is held (alpha = 0), the end s = L0 twisted by theta(t), from 0 to
about 50 degrees and back, four times (:func:`rawehelix.solvers.bouc_wen.torsion_cycle`).
Slow cycles make it quasi-static (the segment's torsional period is 0.17 s).
:func:`run` returns the moment-angle loop; its reference is the Bouc-Wen ODE
of :mod:`rawehelix.solvers.bouc_wen` (scipy), tests/test_hysteresis.py and
benchmarks/hysteresis.py compare the two.
"""

from __future__ import annotations

import math

import numpy as np
from mpi4py import MPI

from rawehelix.parameters import (Discretisation, Ends, Environment, Helix, Model, Parameters,
                                  Time, TorsionHysteresis)
from rawehelix.solvers import bouc_wen

LENGTH_M = 6.76  # the segment of Sec. 4
MASS_PER_M = 0.51 / 16.12  # Table 2: M / L0 [kg/m]
EA_N, EI_NM2, GJ_NM2 = 3.64e4, 1.28e4, 140.0  # Tables 1 and 2
TENSION_N = 200.0  # T_e, Sec. 4
THETA_MAX_RAD = math.radians(50.0)  # Sec. 4: "a maximum torsion angle of about 50 degrees"


def segment(law: TorsionHysteresis, elements: int = 2) -> Parameters:
    """The test's segment at T_e = 200 N with the torsion law ``law``."""
    return Parameters(
        helix=Helix(LENGTH_M, MASS_PER_M * LENGTH_M, EA_N, EI_NM2, GJ_NM2),
        ends=Ends(TENSION_N / EA_N, 0.0), environment=Environment(wind_speed_m_s=0.0),
        model=Model(torsion_hysteresis=law), discretisation=Discretisation(elements=elements),
        time=Time(dt_s=0.1), name="torsion_test")


def run(params: Parameters, period_s: float, cycles: int, steps_per_cycle: int,
        comm=MPI.COMM_WORLD):
    """(times [s], theta [rad], end moment [Nm]) at every step: alpha2 at fixed steps,
    from the stationary state (straight, untwisted, z = 0)."""
    from rawehelix.solvers.dynamics import DynamicsSolver

    q = params.normalised()
    theta, _ = bouc_wen.torsion_cycle(THETA_MAX_RAD, period_s)
    solver = DynamicsSolver.from_stationary(
        params, comm, options={"ts_adapt_type": "none"}, scene=params.name,
        end_twist=lambda t: float(theta(q.time_s(t))))
    dt = period_s / steps_per_cycle / q.t_scale
    solver.ts.setTimeStep(dt)
    times, moments = [], []

    def record(s):
        times.append(float(q.time_s(s.t)))
        moments.append(float(q.torque_Nm(s.end_moment())))

    solver.advance(cycles * period_s / q.t_scale, on_output=record, output_every=dt)
    times = np.array(times)
    return times, theta(times), np.array(moments)


def reference(law: TorsionHysteresis, times, period_s: float):
    """The scipy Bouc-Wen moment [Nm] of the same segment and twist history."""
    theta, theta_t = bouc_wen.torsion_cycle(THETA_MAX_RAD, period_s)
    return bouc_wen.moment(law, GJ_NM2, LENGTH_M, theta, theta_t, times)
