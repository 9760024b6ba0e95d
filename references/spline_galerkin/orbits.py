"""Periodic orbits of the spline-Galerkin scheme (the paper's Fig. 8 method, N = 2), by shooting.

The same shooting problem as :mod:`rawehelix.solvers.orbits` on the state x
of Eq. (61) (positions, velocities, the ground torque m0 and, with k2 > 0,
its rate):

    G(x) = P(x) - x - Delta e_alpha = 0,

P the flow of xdot = f(x, t) over one forcing period T1 (Radau IIA, order 5,
scipy, tolerances tight enough that the flow's error sits far below the
shooting tolerance), e_alpha a uniform unit twist of the alpha nodes (a
uniform twist leaves tau = alpha' and every force unchanged) and Delta the
controller's rotation per period.  The monodromy dP/dx is the solution at T1
of the variational equations Phi' = J(x(t), t) Phi, Phi(0) = I, integrated
along the orbit's dense output by Gauss-Legendre with an error estimate
(J: the exact complex-step Jacobian of f); its eigenvalues
are the Floquet multipliers, and unlike the FE integrator's map there are no
spurious roots: the first-order system has exactly ``size`` multipliers.

Gauge.  In Eq. (61) the controller's integral action is a state: m0' =
mN' + k1 (alpha_0' - alpha_dot*) + ... (Eq. 40).  So c = m0 - mN - k1 (alpha_0
- alpha_dot* t) (- k2 alpha_0') is conserved, and a uniform twist with m0
kept is a symmetry: the full map has a Jordan pair of multipliers at 1 and a
singular shooting matrix.  The FE formulation has m0 = mN + k1 (alpha_0 -
alpha_dot* t) + ... with the constant fixed.  Here the shooting unknown X is
x without m0, and m0 at t = 0 is c0 + mN + k1 alpha_0 (+ k2 alpha_0') with c0
of the stationary start (the constant the brute-force sweep keeps); m0 is
then periodic by itself when Delta = alpha_dot* T1, and the reduced map's
multipliers are the physical ones.

The shooting Newton, the rotation Delta and the orbit's summary are the
scheme-independent ones of :class:`rawehelix.periodic_orbits.floquet.PeriodMap`
(numpy only: no FE code), so :class:`SplineMap` is a periodic-orbit problem
(:class:`rawehelix.periodic_orbits.problem.PeriodicOrbitProblem`) as the FE
shooting is; only the period map is this scheme's own, so the continuation
(:mod:`rawehelix.periodic_orbits.continuation`) traces the paper's N = 2 curve with its
unstable branch as it does the FE's.
"""

from __future__ import annotations

import logging
import math

import numpy as np
from scipy.integrate import solve_ivp

from rawehelix.parameters import Parameters
from rawehelix.errors import SolverError
from rawehelix.periodic_orbits.floquet import PeriodMap
from rawehelix.periodic_orbits.problem import FREE_ROTATION

from . import stationary
from .dynamics import initial_state
from .system import SplineGalerkin

log = logging.getLogger(__name__)
RTOL, ATOL = 1e-10, 1e-12  # the flow's tolerances: far below the shooting's 1e-7
SAMPLES_PER_PERIOD = 256  # tension samples per period for T max and T min
VARIATIONAL_SUBSTEPS = 64  # the monodromy's first substep count per period
VARIATIONAL_TOL = 1e-5  # its estimated error, relative to max |Phi| (a chord Jacobian
# and multipliers to 1e-5; observed order 4: 512 substeps at 10 Hz, N = 2)


class SplineMap(PeriodMap):
    """The period map of the spline-Galerkin scheme at N elements, with its tangent.

    Beyond the problem's declared attributes (``X_stationary``, ``q``, ``q_base``), the
    spline scheme's studies (studies/schemes.py, its driven frequencies) read
    ``system``: the :class:`SplineGalerkin` of the scene at the last f1 evaluated."""

    system: SplineGalerkin

    def __init__(self, params: Parameters, elements: int | None = None):
        self.params = params
        self.q_base = params.normalised().steady_torque()
        self.N = elements or params.discretisation.elements
        self.system = system = SplineGalerkin(self.q_base, self.N)
        self.size = n = system.size
        self.controller = self.q_base.k1 != 0.0
        if not self.controller:
            raise SolverError(f"orbits (spline): {FREE_ROTATION}")
        self.keep = np.delete(np.arange(n), system.i_m0)  # X = x without m0
        # dm0/dX: k1 at alpha_0 (and k2 at alpha_0' with the rate state)
        self.dm0 = np.zeros(n - 1)
        self.dm0[self.keep == system.n_r] = self.q_base.k1
        if system.with_rate:
            self.dm0[self.keep == system.n_q + system.n_r] = self.q_base.k2
        self.E = np.zeros((n, n - 1))  # d x / d X
        self.E[self.keep, np.arange(n - 1)] = 1.0
        self.E[system.i_m0] = self.dm0
        self.e_alpha = np.zeros(n - 1)
        self.e_alpha[(self.keep >= system.n_r) & (self.keep < system.n_q)] = 1.0  # uniform twist
        self.newton_iterations = 0
        start = stationary.chord_nodes(system, 0.0)
        x_s = initial_state(system, stationary.solve(system, start=start).x)
        self.c0 = x_s[system.i_m0] - self.q_base.top_torque(0.0) - self.dm0 @ x_s[self.keep]
        self.X_stationary = x_s[self.keep]
        self.q = self.q_base

    def embed(self, X):
        """The full state x of Eq. (61) from the shooting unknown X (m0 from c0)."""
        x = np.empty(self.size)
        x[self.keep] = X
        x[self.system.i_m0] = self.c0 + self.q_base.top_torque(0.0) + self.dm0 @ X
        return x

    def set_frequency(self, f1_Hz: float):
        self.q = self.q_base.at_frequency(f1_Hz, 0.0)
        self.system = SplineGalerkin(self.q, self.N)

    def steps_per_period(self, f1_Hz: float) -> int:
        """Tension samples per period (the flow itself is adaptive)."""
        return SAMPLES_PER_PERIOD

    def period(self, X, f1_Hz: float, tangent: bool = False, steps: int | None = None):
        """P(X) over one period at f1 (phase 0 at t = 0), the tension at s = 0 at
        ``steps`` equally spaced times and, with ``tangent``, the monodromy dP/dX."""
        self.set_frequency(f1_Hz)
        system, n = self.system, self.size
        x0 = self.embed(X)
        T1 = 2 * math.pi / self.q.omega1
        M = steps or self.steps_per_period(f1_Hz)
        t_out = T1 * np.arange(1, M + 1) / M
        sol = solve_ivp(lambda t, y: system.f(y, t), (0.0, T1), x0, method="Radau",
                        jac=lambda t, y: system.jacobian(y, t), t_eval=t_out,
                        dense_output=tangent, rtol=RTOL, atol=ATOL)
        if not sol.success or not np.all(np.isfinite(sol.y)):
            raise SolverError(f"orbits (spline): the flow failed at f1 = {f1_Hz} Hz: "
                              f"{sol.message}")
        end = sol.y[:, -1]
        tension = np.array([system.tension(y, t, s=np.array([0.0]))[0]
                            for y, t in zip(sol.y.T, sol.t)])
        Phi = self._variational(sol.sol, T1)[self.keep] if tangent else None
        return end[self.keep], tension, Phi

    def _variational(self, x_of_t, T1: float):
        """Phi(T1) of Phi' = J(x(t), t) Phi, Phi(0) = dx0/dX, along the flow's
        dense output: two-stage Gauss-Legendre (order 4, A-stable) on K equal
        substeps, K doubled until two results agree to VARIATIONAL_TOL
        (Richardson: the error of the finer is about 1/15 of their difference);
        returned extrapolated, (16 Phi_2K - Phi_K) / 15, whose error is smaller."""
        previous, K = None, VARIATIONAL_SUBSTEPS
        while K <= 64 * VARIATIONAL_SUBSTEPS:
            Phi = self._gauss_legendre(x_of_t, T1, K)
            if previous is not None:
                change = np.abs(Phi - previous).max() / max(np.abs(Phi).max(), 1.0)
                if change / 15 <= VARIATIONAL_TOL:
                    return (16 * Phi - previous) / 15
            log.debug("monodromy: %d substeps, change %s", K, None if previous is None else change)
            previous, K = Phi, 2 * K
        raise SolverError(f"orbits (spline): the monodromy did not converge to "
                          f"{VARIATIONAL_TOL:g} with {K // 2} substeps")

    def _gauss_legendre(self, x_of_t, T1: float, K: int):
        system, n = self.system, self.size
        r3 = math.sqrt(3.0)
        c = (0.5 - r3 / 6, 0.5 + r3 / 6)
        a = ((0.25, 0.25 - r3 / 6), (0.25 + r3 / 6, 0.25))
        h = T1 / K
        Phi = self.E.copy()
        eye = np.eye(n)
        for k in range(K):
            J = [system.jacobian(x_of_t(t), t) for t in (k * h + c[0] * h, k * h + c[1] * h)]
            # stages S_i = J_i (Phi + h sum_j a_ij S_j)
            L = np.block([[eye - h * a[0][0] * J[0], -h * a[0][1] * J[0]],
                          [-h * a[1][0] * J[1], eye - h * a[1][1] * J[1]]])
            S = np.linalg.solve(L, np.vstack([J[0] @ Phi, J[1] @ Phi]))
            Phi = Phi + 0.5 * h * (S[:n] + S[n:])
        return Phi
