"""Time integration of Eq. (61) with scipy's solve_ivp (Sec. 5.2 and 5.3).

Integrator: Radau (implicit Runge-Kutta, Radau IIA, order 5) with the exact
complex-step Jacobian.  The system is stiff: the slowest dynamics of interest
(spin-up and controller, |lambda| ~ 1) sit under axial and bending modes whose
frequencies grow like N pi sqrt(sigma) and mu^(1/2) (N pi)^2 (|lambda|max = 271
at N = 2, 2600 at N = 8), so explicit steps are set by stability, not
accuracy.  Radau is A- and L-stable; BDF of orders 3-5 is not A-stable near
the imaginary axis, where the undamped torsional modes live, and takes tiny
steps there.  Measured on Sec. 5.2 (30 s, rtol 1e-7): N = 2, Radau 0.5 s,
RK45 1.6 s, BDF 4.0 s; N = 8, Radau 5 s, RK45 24 s, BDF 69 s, all agreeing
to 1e-9 in the final spin.

The end torques: the ramp derivatives mN', mN'' are exact (Eq. 69) and the
controller is an extra state (see :mod:`.system`), so no finite differences
of alpha are needed.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from rawehelix.parameters import Parameters

from . import stationary
from .system import SplineGalerkin


@dataclass
class TimeSeries:
    """SI time series of a run, for point-by-point comparison with other solvers."""

    time_s: np.ndarray  # (n,) [s]
    node_s_m: np.ndarray  # (3,) arc length of the spin nodes: 0, ~L0/2, L0 [m]
    spin_rpm: np.ndarray  # (n, 3) alpha_dot at those nodes [rpm]
    ground_torque_Nm: np.ndarray  # (n,) torque_Nm(m0) [Nm]
    tension0_N: np.ndarray  # (n,) T at s = 0 [N]
    states: np.ndarray  # (n, size) normalised state vectors


def initial_state(system: SplineGalerkin, x_s: np.ndarray, t: float = 0.0) -> np.ndarray:
    """The stationary state x_s, with w = m0' consistent with Eq. (40) when k2 > 0.

    w(0) = mN' + k1 (alpha_0' - alpha*') + k2 alpha_0'', with alpha_0'' from
    Eq. (56) taking alpha_0''' = 0 at t = 0 (m0'' = mN'' + k1 alpha_0'').
    """
    if not system.with_rate:
        return x_s.copy()
    nd = system.nd
    plain = SplineGalerkin(dataclasses.replace(nd, k2=0.0), system.N,
                           len(system.basis.w) // system.N)
    x0 = np.zeros(plain.size)
    x0[:plain.size] = x_s[:plain.size]
    acc0 = plain.f(x0, t)[system.n_q + system.n_r]  # alpha_0''
    alphadot0 = x_s[system.n_q + system.n_r]
    x = x_s.copy()
    x[system.i_m0 + 1] = nd.top_torque_rate(t) + nd.k1 * (alphadot0 - nd.spin_target) \
        + nd.k2 * acc0
    return x


def integrate(system: SplineGalerkin, x0: np.ndarray, t_end: float, t_eval: np.ndarray,
              rtol: float = 1e-7, atol: float = 1e-9):
    """solve_ivp(Radau) of xdot = f(x, t) on [0, t_end] (normalised time)."""
    sol = solve_ivp(lambda t, x: system.f(x, t), (0.0, t_end), x0, method="Radau",
                    t_eval=t_eval, jac=lambda t, x: system.jacobian(x, t),
                    rtol=rtol, atol=atol)
    if not sol.success:
        raise RuntimeError(f"time integration failed: {sol.message}")
    return sol.t, sol.y.T


def time_series(params: Parameters, elements: int | None = None, until_s: float | None = None,
                output_every_s: float | None = None, rtol: float = 1e-7) -> TimeSeries:
    """Run a scene from its stationary state (Sec. 5.2) and return SI series.

    Spin nodes: s = 0, the middle node (s = L0/2 for even N, else the node
    nearest to it) and s = L0; tension at s = 0.
    """
    nd = params.normalised()
    N = elements or params.discretisation.elements
    system = SplineGalerkin(nd, N)
    x_s = stationary.solve(system).x
    x0 = initial_state(system, x_s)
    until = (until_s or params.time.until_s) / nd.t_scale
    every = (output_every_s or params.time.output_every_s) / nd.t_scale
    t_eval = np.arange(0.0, until + 0.5 * every, every)
    t_eval = t_eval[t_eval <= until]
    t, X = integrate(system, x0, until, t_eval, rtol=rtol)
    nodes = np.array([0, int(round(N / 2)), N])
    alphadot = X[:, system.n_q + system.n_r:2 * system.n_q]
    T0 = np.array([system.tension(x, tk, s=np.array([0.0]))[0] for x, tk in zip(X, t)])
    return TimeSeries(
        time_s=nd.time_s(t), node_s_m=nd.length_m(nodes / N),
        spin_rpm=nd.spin_rpm(alphadot[:, nodes]),
        ground_torque_Nm=nd.torque_Nm(X[:, system.i_m0]),
        tension0_N=nd.tension_N(T0), states=X)
