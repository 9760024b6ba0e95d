"""The FE time loop allocates nothing per step that outlives the step.

A petsc4py Vec made and dropped in a callback is only freed by
PETSc.garbage_cleanup; one copy of the state per step grew the resident
memory by 9.1 kB a step (N = 4), 24 GB over an N = 16 sweep."""

import math
import os

import numpy as np
from mpi4py import MPI

from rawehelix.solvers.forced import FEBackend
from rawehelix.studies import scene

#: bytes per step: far above the noise of the measurement (a 4 kB page over
#: thousands of steps: about 1 B a step), far below the 9.1 kB of the leak
GROWTH_BOUND_B = 500.0


def resident_bytes() -> int:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def test_sweep_backend_step_memory_is_bounded():
    params = scene.load("mobile_end", elements=4)
    backend = FEBackend(params, MPI.COMM_SELF)
    f1 = 10.0
    backend.set_frequency(f1, 0.0)
    period = 2 * math.pi / params.normalised().at_frequency(f1, 0.0).omega1
    state, t = backend.stationary(), 0.0

    def periods(n):
        nonlocal state, t
        for _ in range(n):
            state, tension = backend.advance(state, t, t + period, np.array([t + period]))
            assert np.isfinite(tension).all()
            t += period

    periods(3)  # warm-up: caches, the LU, the allocator's first arenas
    before, steps = resident_bytes(), backend.solver.steps
    periods(20)
    steps = backend.solver.steps - steps
    growth = (resident_bytes() - before) / steps
    assert steps >= 3000
    assert growth < GROWTH_BOUND_B, f"{growth:.0f} B per step over {steps} steps"
