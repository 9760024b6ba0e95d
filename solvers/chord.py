"""A step loop of TSALPHA2 without PETSc TS (issue 12): chord Newton on the stage value.

The scheme is :class:`~rawehelix.solvers.orbits.AlphaMap`'s, the generalised-alpha
method of TSALPHA2 (same rho_inf): one step solves R(z) = F(t_n + alpha_f h, z,
V_a(z), A_a(z)) = 0 for z = U_{n+alpha_f}, with V_a, A_a linear in z
(``AlphaMap.newmark``, slopes ``AlphaMap.shifts``).  What is new is how
(``AlphaMap.solve_stage`` and ``AlphaMap.predict``, which the periodic orbits
share at a tighter ``tol``):

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
  ``orbits.STALL`` round-offs: then z is converged), or leaves a
  non-finite state, raises SolverError;
- the Dirichlet rows (35)-(36): z = g(t_n + alpha_f h) is put into the
  predictor, so their rows of R are zero and stay zero; J has unit rows and
  columns there (the formulation's TSALPHA2 Jacobian form, assembled with its
  bcs: one matrix instead of AlphaMap's three);
- ``tol`` = 1e-11 because T = sigma (|r'| - 1) magnifies errors in z: over
  2000 steps the T(0) series moves by ~5e5 tol (relative) against full Newton;
  at 1e-11, T max at 10 Hz is within 7e-6 of full Newton's (1e-12: 1e-7);
- TSALPHA2's start (``TSAlpha_Restart``): two steps of the scheme (1, 1, 1, 1/2)
  (backward Euler in V) of h/2 from (U_0, V_0, A = 0), then A_0 by backward
  differences of V: so a run of ``advance`` equals PETSc's to the Newton tolerance.

Dense linear algebra on one rank (AlphaMap's limit: 3 n <= ``orbits.MAX_STATE``).
"""

from __future__ import annotations

import math

import numpy as np

import dolfinx.fem
import ufl

from rawehelix import compat
from rawehelix.forms import kinematics
from rawehelix.solvers.orbits import AlphaMap

BACKWARD_EULER = (1.0, 1.0, 1.0, 0.5)  # (alpha_m, alpha_f, gamma, beta) of TSAlpha_Restart


class ChordAlpha(AlphaMap):
    """TSALPHA2's steps by chord Newton with held LU factors (see the module docstring).

    ``tol``: Hairer's test on the stage value (normalised, max norm); ``rate``:
    the contraction above which the LU is refreshed; ``max_it``: per step."""

    def __init__(self, params, rho_inf: float = 0.9, solver=None, tol: float = 1e-11,
                 rate: float = 0.03, max_it: int = 8, order: int = 2):
        super().__init__(params, rho_inf, solver=solver, tol=tol, rate=rate, max_it=max_it,
                         order=order)
        self._tension_map()

    def start(self, t, h, u, v):
        """A_0 as TSALPHA2's restart: two half steps of the scheme (1, 1, 1, 1/2)."""
        a0 = np.zeros_like(u)
        u1, v1, _, _ = self.solve_stage(t, h / 2, u, v, a0, u + 0.5 * h * v, BACKWARD_EULER)
        _, v2, _, _ = self.solve_stage(t + h / 2, h / 2, u1, v1, a0, u1 + 0.5 * h * v1,
                                       BACKWARD_EULER)
        return (-3.0 * v + 4.0 * v1 - v2) / (h / 2)

    def _tension_map(self):
        """T(0) = sigma (|r'(0)| - 1) (29) with r'(0) = D U linear in the dofs: D's
        rows assembled once, checked against the probe's point form."""
        rod, u = self.solver.rod, self.form.u
        s = ufl.SpatialCoordinate(rod.mesh)[0]
        r = ufl.split(u)[0]
        rows = [dolfinx.fem.form(ufl.derivative(kinematics.d(r)[i] * (1 - s) * ufl.ds(domain=rod.mesh),
                                                u, rod.test)) for i in range(3)]
        self._D = np.array([compat.assemble_vector_array(np.zeros(self.n), f) for f in rows])
        self._sigma = float(self.solver.q.sigma)
        probe = self.solver.probes.value("tension0")
        if not abs(self.tension0(u.x.array) - probe) <= 1e-9 * abs(probe):
            raise RuntimeError(f"chord alpha2: T(0) from r'(0) = D U ({self.tension0(u.x.array)}) "
                               f"is not the probe's ({probe})")

    def tension0(self, u) -> float:
        """T(0) (normalised) of the configuration u (one rank): Eq. (29) at s = 0."""
        return self._sigma * (math.sqrt(float(np.dot(d := self._D @ u, d))) - 1.0)

    def run(self, t0, h, steps, u, v, a=None):
        """``steps`` steps of h from (u, v) at t0, with alpha2's start (or from the
        acceleration ``a``, a run continued): the final (u, v) and the tension at
        s = 0 after every step (normalised, the start's first); the final
        acceleration is ``self.acceleration``."""
        tension = np.empty(steps + 1)
        tension[0] = self.tension0(u)
        if a is None:
            a = self.start(t0, h, u, v)
        history = []  # the last stage values, newest first
        for k in range(steps):
            u, v, a, z = self.solve_stage(t0 + k * h, h, u, v, a, self.predict(history, u, v, a, h))
            history = [z] + history[:self.order]
            tension[k + 1] = self.tension0(u)
        self.acceleration = a
        return u, v, tension

