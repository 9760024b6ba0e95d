"""Timing: 20 eigenpairs of the Table 2 helix at N = 2000, p = 3 (a benchmark, not a test).

    .venv/bin/python benchmarks/modal_n2000.py [PETSc options]
    mpirun -n 2 .venv/bin/python benchmarks/modal_n2000.py

Prints the times of the stationary Newton solve, the assembly of K, C, M and
the SLEPc solve (PEP/TOAR, shift-and-invert, MUMPS), and the eigenvalues.

At this resolution the Newton residual has a round-off floor (~3.7, growing
like N^3), so the step test is relaxed to -rawehelix_snes_stol 1e-8 unless
given.  The lateral eigenvalues are then ~15 % off (round-off in the
fourth-order operator, see docs/explanation/modal_convergence.md): this measures time,
not accuracy.
"""

from __future__ import annotations

import logging
import sys
import time

import petsc4py

petsc4py.init(sys.argv)
logging.disable(logging.INFO)

from mpi4py import MPI  # noqa: E402

from rawehelix.solvers.modal import ModalSolver  # noqa: E402
from rawehelix.solvers.stationary import StationarySolver  # noqa: E402
from rawehelix.studies import modes as study  # noqa: E402
from rawehelix.studies import scene  # noqa: E402

N, P, NEV = 2000, 3, 20


def main():
    from petsc4py import PETSc
    if not PETSc.Options().hasName("rawehelix_snes_stol"):
        PETSc.Options()["rawehelix_snes_stol"] = 1e-8
    comm = MPI.COMM_WORLD
    log = print if comm.rank == 0 else (lambda *a: None)
    params = scene.load("stationary_table2", elements=N, degree=P)
    t0 = time.perf_counter()
    stationary = StationarySolver(params, comm, scene="stationary_table2")
    solver = ModalSolver(params, comm, scene="stationary_table2", rod=stationary.rod)
    t1 = time.perf_counter()
    solver.stationary_result = stationary.solve()
    t2 = time.perf_counter()
    solver.linearise(solver.stationary_result.state)
    t3 = time.perf_counter()
    found = solver.solve(nev=NEV, keep_vectors=False)
    t4 = time.perf_counter()
    log(f"N = {N}, p = {P}: {solver.rod.dof_count()} dofs, {comm.size} rank(s), nev = {NEV}")
    log(f"  set-up (mesh, spaces, JIT) {t1 - t0:6.2f} s")
    log(f"  stationary Newton          {t2 - t1:6.2f} s "
        f"({solver.stationary_result.newton_iterations} iterations)")
    log(f"  assembly of K, C, M        {t3 - t2:6.2f} s")
    log(f"  SLEPc PEP solve            {t4 - t3:6.2f} s ({len(found)} modes from {NEV} eigenpairs)")
    log(f"  total                      {t4 - t0:6.2f} s")
    log(study.format_table([study.ModeResult.of(m.eigenvalue, m.family, m.dominant, m.fractions,
                                                solver.q) for m in found]))


if __name__ == "__main__":
    main()
