"""The illustrative rotor's steady points on the lifted helix (docs/explanation/lifter.md).

rotor_example (MPPT, a 1.5 kg rotor) lifted by 200 N at 45 deg, at N = 8: at each wind
speed the rotor's thrust acts along the helix's end tangent (inside Newton, as a
follower force: solvers/lifted.py's tangent_thrust_N) and its size, the rotor's speed
and torque come from the rigid shaft (operation/rigid_shaft.py) at V_n = V |t_x|, until
the thrust changes by less than 1e-9 of itself.  Prints the table's rows.

    .venv/bin/python scripts/lifted_rotor_points.py
"""
import math

import numpy as np
from mpi4py import MPI

import rawehelix as rh
from rawehelix.operation import generator as generator_law, rigid_shaft, rotor as rotor_law
from rawehelix.solvers import lifted

for V in (5.0, 6.6131, 8.0):
    p = rh.load_scene("rotor_example", elements=8, overrides={
        "lifter.top": "lifted", "lifter.force_N": 200.0, "lifter.elevation_deg": 45.0})
    rotor, gen = rotor_law.from_params(p), generator_law.from_params(p)
    rho, q = p.environment.air_density_kg_m3, p.normalised()
    t = np.array(p.lifter.direction())  # the first axis: the lifter's
    solver, thrust = None, 0.0
    for solves in range(1, 21):
        v_n = rotor.normal_speed(V, t)
        point = [x for x in rigid_shaft.operating_points(rotor, gen, v_n, rho) if x.stable][0]
        solver, out = lifted.stationary(p, comm=MPI.COMM_SELF, tangent_thrust_N=point.thrust_N,
                                        top_torque_Nm=point.rotor_torque_Nm, solver=solver)
        t, change, thrust = out.end_tangent, abs(point.thrust_N - thrust), point.thrust_N
        if change < 1e-9 * thrust:
            break
    T = q.tension_N(out.result.tension)
    x, y, z = out.top_m
    tangent_deg = math.degrees(math.atan2(-t[2], math.hypot(t[0], t[1])))
    print(f"| {V:.4g} | {v_n:.3f} | {point.rotor_rpm:.2f} | {point.rotor_torque_Nm:.2f} | "
          f"{thrust:.2f} | ({x:.3f}, {y:.4f}, {z:.3f}) | {out.chord_elevation_deg:.2f} | "
          f"{tangent_deg:.2f} | {T[0]:.1f} | {T[-1]:.1f} | {solves} solves")
