"""The spline-Galerkin scheme as a backend of :mod:`rawehelix.solvers.periodic`.

The paper's method for Fig. 8: N = 2 elements, Radau (see :mod:`.dynamics`)."""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp

from rawehelix.parameters import Normalised

from . import stationary
from .dynamics import initial_state
from .system import SplineGalerkin


class SplineBackend:
    scheme = "spline"
    section_sampler = None  # no fields along s to sample (solvers/periodic.py)

    def track_sections(self) -> None:
        """Nothing to track: the spline state has no section along s (the limits block)."""

    @staticmethod
    def parts(x) -> None:
        """No parts to name: the spline state's coefficients mix the centre line and the
        twist (solvers/periodic.py judges its tension alone)."""
        return None

    def __init__(self, q: Normalised, N: int, rtol: float = 1e-7, atol: float = 1e-9):
        self.q, self.N, self.rtol, self.atol = q, N, rtol, atol
        self.q_now = q

    def stationary(self) -> np.ndarray:
        """Stationary state with the top at its position at t = 0 (phase 0)."""
        system = SplineGalerkin(self.q, self.N)
        start = stationary.chord_nodes(system, 0.0)
        return initial_state(system, stationary.solve(system, start=start).x)

    def set_frequency(self, f1_Hz: float, t_start: float):
        """The circle of Eq. (70) at f1, at phase 0 at the normalised time t_start."""
        self.q_now = self.q.at_frequency(f1_Hz, t_start)

    def advance(self, x, t0: float, t1: float, t_out):
        system = SplineGalerkin(self.q_now, self.N)
        sol = solve_ivp(lambda t, y: system.f(y, t), (t0, t1), x, method="Radau",
                        t_eval=np.asarray(t_out), jac=lambda t, y: system.jacobian(y, t),
                        rtol=self.rtol, atol=self.atol)
        if not sol.success:
            raise RuntimeError(f"spline reference: time integration failed at "
                               f"t~ = {sol.t[-1]:.4f}: {sol.message}")
        tension = np.array([system.tension(y, tk, s=np.array([0.0]))[0]
                            for y, tk in zip(sol.y.T, sol.t)])
        # the state at t1 (t_out ends at t1 in a sweep; integrate again otherwise)
        if not np.isclose(sol.t[-1], t1, rtol=0, atol=1e-12 * max(1.0, abs(t1))):
            end = solve_ivp(lambda t, y: system.f(y, t), (t0, t1), x, method="Radau",
                            jac=lambda t, y: system.jacobian(y, t), rtol=self.rtol, atol=self.atol)
            return end.y[:, -1], tension
        return sol.y[:, -1], tension

    @staticmethod
    def pack(x) -> dict:
        return {"x": np.asarray(x)}

    @staticmethod
    def unpack(data) -> np.ndarray:
        return np.asarray(data["x"]).copy()
