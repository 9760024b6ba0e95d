"""A step loop of TSALPHA2 without PETSc TS (issue 12): chord Newton on the stage value.

The scheme is :class:`~rawehelix.solvers.generalised_alpha.AlphaStepper`'s, the
generalised-alpha method of TSALPHA2 (same rho_inf), on the rod operator of
:class:`~rawehelix.solvers.rod_operator.RodOperator`: one step solves R(z) =
F(t_n + alpha_f h, z, V_a(z), A_a(z)) = 0 for z = U_{n+alpha_f}, with V_a, A_a
linear in z (``AlphaStepper.newmark``, slopes ``AlphaStepper.shifts``).  What is
new is how (``AlphaStepper.solve_stage`` and ``AlphaStepper.predict``, which the
periodic orbits share at a tighter ``tol``):

- chord (modified) Newton: the dense LU of J = F_U + s_V F_V + s_A F_A is held
  across iterations and steps (one per step size and scheme) and refreshed when
  an iteration contracts dz by less than ``rate`` (theta > 0.03) or diverges;
- the predictor extrapolates the last three stage values (quadratic in t).  It
  is off by ~5e-5 (normalised) at N = 8 whatever the order (1 to 3; the last
  stage value alone: 4e-4): the correction is spatially oscillating r content the
  extrapolation cannot follow, so a step takes 3-3.5 iterations (docs/explanation/speed.md);
- the stopping test is Hairer's (Hairer and Wanner, Solving ODEs II, IV.8):
  eta |dz|_inf <= tol with eta = theta / (1 - theta) from the contraction theta
  = |dz_k| / |dz_{k-1}| measured in this step with this LU (so at least two
  iterations, unless dz is at round-off); eta |dz| bounds the distance to the
  solution of R(z) = 0 while the contraction holds.  Hairer's carry-over of
  eta from the last step (one-iteration steps) is not used: right after a
  refresh it measures the round-off, not the chord's rate, and let steps pass
  with errors ~1e-6 (found in testing).  A step that does not meet the test in
  ``max_it`` iterations, or diverges with a fresh Jacobian (unless |dz| is within
  ``generalised_alpha.STALL`` round-offs: then z is converged), or leaves a
  non-finite state, raises SolverError;
- the Dirichlet rows (35)-(36): z = g(t_n + alpha_f h) is put into the
  predictor, so their rows of R are zero and stay zero; J has unit rows and
  columns there (the formulation's TSALPHA2 Jacobian form, assembled with its
  bcs: one matrix instead of the tangent's three);
- ``tol`` = 1e-11 because T = sigma (|r'| - 1) magnifies errors in z: over
  2000 steps the T(0) series moves by ~5e5 tol (relative) against full Newton;
  at 1e-11, T max at 10 Hz is within 7e-6 of full Newton's (1e-12: 1e-7);
- TSALPHA2's start (``TSAlpha_Restart``): two steps of the scheme (1, 1, 1, 1/2)
  (backward Euler in V) of h/2 from (U_0, V_0, A = 0), then A_0 by backward
  differences of V: so a run of ``advance`` equals PETSc's to the Newton tolerance.

Dense linear algebra on one rank (the stepper's limit: 3 n <= ``generalised_alpha.MAX_STATE``).
"""

from __future__ import annotations

import numpy as np
from mpi4py import MPI

from rawehelix.solvers.generalised_alpha import AlphaStepper
from rawehelix.solvers.rod_operator import RodOperator

BACKWARD_EULER = (1.0, 1.0, 1.0, 0.5)  # (alpha_m, alpha_f, gamma, beta) of TSAlpha_Restart


class ChordAlpha:
    """TSALPHA2's steps by chord Newton with held LU factors (see the module docstring),
    an :class:`AlphaStepper` on the rod's :class:`RodOperator`.

    ``tol``: Hairer's test on the stage value (normalised, max norm); ``rate``:
    the contraction above which the LU is refreshed; ``max_it``: per step."""

    def __init__(self, params, rho_inf: float = 0.9, solver=None, tol: float = 1e-11,
                 rate: float = 0.03, max_it: int = 8, order: int = 2, tension_map: bool = True):
        self.op = RodOperator(params, MPI.COMM_SELF, solver)
        self.solver = self.op.solver
        self.alpha = AlphaStepper(self.op, rho_inf, tol=tol, rate=rate, max_it=max_it,
                                  order=order)
        if tension_map:  # T(0) = sigma (|D U| - 1), the solid's (False: a caller without T(0))
            self.op.tension_map()

    # the stepper's counters and its Newton's limit (the sweep's statistics, the tests)
    iterations = property(lambda self: self.alpha.iterations)
    factorisations = property(lambda self: self.alpha.factorisations)
    steps = property(lambda self: self.alpha.steps)

    @property
    def max_it(self) -> int:
        return self.alpha.max_it

    @max_it.setter
    def max_it(self, value: int):
        self.alpha.max_it = value

    def start(self, t, h, u, v):
        """A_0 as TSALPHA2's restart: two half steps of the scheme (1, 1, 1, 1/2)."""
        a0 = np.zeros_like(u)
        stage = self.alpha.solve_stage
        u1, v1, _, _ = stage(t, h / 2, u, v, a0, u + 0.5 * h * v, BACKWARD_EULER)
        _, v2, _, _ = stage(t + h / 2, h / 2, u1, v1, a0, u1 + 0.5 * h * v1, BACKWARD_EULER)
        return (-3.0 * v + 4.0 * v1 - v2) / (h / 2)

    def tension0(self, u) -> float:
        """T(0) (normalised) of the configuration u (one rank): Eq. (29) at s = 0."""
        return self.op.tension0(u)

    def run(self, t0, h, steps, u, v, a=None):
        """``steps`` steps of h from (u, v) at t0, with alpha2's start (or from the
        acceleration ``a``, a run continued): the final (u, v) and the tension at
        s = 0 after every step (normalised, the start's first); the final
        acceleration is ``self.acceleration``."""
        tension = np.empty(steps + 1)
        tension[0] = self.tension0(u)
        if a is None:
            a = self.start(t0, h, u, v)
        history, alpha = [], self.alpha  # the last stage values, newest first
        for k in range(steps):
            u, v, a, z = alpha.solve_stage(t0 + k * h, h, u, v, a, alpha.predict(history, u, v, a, h))
            history = [z] + history[:alpha.order]
            tension[k + 1] = self.tension0(u)
        self.acceleration = a
        return u, v, tension
