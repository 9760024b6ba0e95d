"""The virtual lab tests' numbers in docs/explanation/labtest.md that no single command prints.

1. The load dependence of the bending test with the EI law in the rod
   (helix.EI_law, extensible kinematics): the secant EI = F_N L0^3 / (3 y_e)
   at each load and the wall's tension T = EA eps, for the law ``--law a,b``
   (default: the one `rawehelix labtest bending --fit` identifies).  The
   energy 1/2 EI(eps) kappa^2 gives the axial force N.t = T + 1/2 a EA kappa^2
   (forms/extensible.py), so at the dead end tension T_e the wall's T falls as
   the curvature grows, EI with it; the energy stops being convex at
   kappa^2 = EI / (a^2 EA), where Newton finds no equilibrium.
2. What feeding Eq. (64) straight into the Table 2 helix does: the modes
   (Table 3, N = 16) with EI = Eq. (64) at 200 N against the intrinsic law's
   EI at 200 N, as constants in the paper's kinematics, and as the EI law
   in the extensible kinematics.

    .venv/bin/python benchmarks/labtest.py [--law 34.88,2302.9] [--elements 16]

Serial (COMM_SELF); a benchmark, not a test.
"""

from __future__ import annotations

import argparse

import numpy as np
from mpi4py import MPI

import rawehelix as rh
from rawehelix.solvers.cantilever import CantileverSolver
from rawehelix.studies import labtest

LOADS_N = (0.25, 1.0, 2.5, 5.0, 6.0, 7.5, 10.0)


def softening(law):
    base = rh.load_scene("stationary_table2")
    solver = CantileverSolver(labtest.lab_parameters(base, law=True), MPI.COMM_SELF)
    solver.set_bending_law(*law)
    L0 = labtest.LAB_LENGTH_M
    print("| T_e [N] | Eq. (64) | " + " | ".join(f"F_N = {F:g} N" for F in LOADS_N) + " |")
    print("|---" * (len(LOADS_N) + 2) + "|")
    for T in labtest.PAPER_BENDING_TENSIONS_N:
        solver.reset()
        zero = solver.solve(T * solver.axis).position_m[2]
        cells = []
        for F in LOADS_N:
            try:
                tip = solver.solve(T * solver.axis + F * labtest.NORMAL)
            except rh.SolverError:
                cells.append("no equilibrium")
                break
            cells.append(f"{F * L0**3 / (3 * (tip.position_m[2] - zero)):.0f} "
                         f"(T(0) {tip.tension_wall_N:.0f} N)")
        cells += [""] * (len(LOADS_N) - len(cells))
        print(f"| {T:g} | {labtest.eq64(T):.0f} | " + " | ".join(cells) + " |")


def modes(law, elements):
    EI_64, EI_law = float(labtest.eq64(200.0)), law[0] * 200.0 + law[1]
    cases = {f"paper, EI = {EI_64:.0f} (Eq. 64 at 200 N)": {"helix.EI_Nm2": EI_64},
             f"paper, EI = {EI_law:.0f} (intrinsic law at 200 N)": {"helix.EI_Nm2": EI_law},
             "extensible, EI law Eq. (64)": {
                 "model.kinematics": "extensible",
                 "helix.EI_law": {"a_Nm2_per_N": labtest.EQ64[0], "b_Nm2": labtest.EQ64[1]}},
             "extensible, intrinsic EI law": {
                 "model.kinematics": "extensible",
                 "helix.EI_law": {"a_Nm2_per_N": law[0], "b_Nm2": law[1]}}}
    print("\n| rod | lateral 1 [Hz] | lateral 2 [Hz] | lateral 3 [Hz] | torsional 1 [Hz] |")
    print("|---|---|---|---|---|")
    for name, over in cases.items():
        scene = rh.load_scene("stationary_table2", elements=elements, overrides=over)
        found = rh.modes(scene, comm=MPI.COMM_SELF)
        lateral = sorted(m.frequency_Hz for m in found if m.family == "lateral_in_plane")
        torsion = sorted(m.frequency_Hz for m in found if m.family == "torsional")
        print(f"| {name} | " + " | ".join(f"{f:.3f}" for f in lateral[:3])
              + f" | {torsion[0]:.3f} |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--law", default="34.88,2302.9", help="a,b of EI = a T + b")
    parser.add_argument("--elements", type=int, default=16)
    args = parser.parse_args()
    law = tuple(float(v) for v in args.law.split(","))
    softening(law)
    modes(law, args.elements)


if __name__ == "__main__":
    main()
