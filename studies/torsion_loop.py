"""The hysteretic torsion loop of Sec. 4 (Fig. 2c, Fig. 5) on the FE rod, with a
prescribed end twist: ``rh.torsion_loop`` (the static lab tests hold z = 0).

The lab segment of ``rawehelix labtest`` (studies/labtest.py: 6.76 m with the
mass per length and stiffnesses of the Table 2 helix, no wind or drag), its
ends held T_e = 200 N apart (the paper's nominal tension), horizontal; the
end s = 0 is held (alpha = 0), the end s = L0 twisted by theta(t), from 0 to
about 50 degrees and back, four times (:func:`rawehelix.solvers.bouc_wen.torsion_cycle`).
Slow cycles make it quasi-static (the segment's torsional period is 0.17 s).
:func:`run` returns the moment-angle loop; its reference is the Bouc-Wen ODE
of :mod:`rawehelix.solvers.bouc_wen` (scipy), tests/test_hysteresis.py and
benchmarks/hysteresis.py compare the two.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from mpi4py import MPI

from rawehelix.parameters import Parameters, TorsionHysteresis
from rawehelix.solvers import bouc_wen
from rawehelix.studies import labtest, scene

LENGTH_M = labtest.LAB_LENGTH_M  # the segment of Sec. 4
TENSION_N = 200.0  # T_e, Sec. 4: "around 200 N, the nominal tension"
THETA_MAX_RAD = math.radians(50.0)  # Sec. 4: "a maximum torsion angle of about 50 degrees"
HELIX_SCENE = "stationary_table2"  # the Table 2 helix: its mass per length, EA, EI and GJ


def segment(law: TorsionHysteresis, elements: int = 2):
    """The lab segment of :func:`rawehelix.studies.labtest.lab_parameters` (the Table 2
    helix, no wind or drag), both ends at the wall's height and T_e = 200 N apart
    (the end s = L0 held in place), with the torsion law ``law``."""
    params = labtest.lab_parameters(scene.load(HELIX_SCENE), elements)
    return params.replace(ends={"elongation": TENSION_N / params.helix.EA_N, "elevation_deg": 0.0},
                          torsion_hysteresis=dataclasses.asdict(law),
                          time={"dt_s": 0.1}, name="torsion_test")


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
    GJ = scene.load(HELIX_SCENE).helix.GJ_Nm2
    return bouc_wen.moment(law, GJ, LENGTH_M, theta, theta_t, times)
