"""The Bouc-Wen torsion law as an ODE in time, integrated by scipy: the reference
of the hysteretic torsion (forms/hysteresis.py), in SI, numpy and scipy only.

For a segment twisted uniformly, tau(t) = theta(t) / L0, the moment is
M = GJ (rho tau + (1 - rho) z) with

    dz/dt = tau_t (A - (beta sign(tau_t z) + gamma) |z|^n)          (Wen 1976)

(the same law as forms/hysteresis.py, written from the paper's
sign(dtau z) form, not from that module).  :func:`torsion_cycle` is the
twist history of the paper's torsion test (Sec. 4: to ~50 degrees and back,
four cycles), smoothed to a cosine so that its rate is continuous;
:func:`cycle_energies` the energy a loop dissipates, the work of M on theta.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp

from rawehelix.parameters import TorsionHysteresis


def torsion_cycle(theta_max_rad: float, period_s: float):
    """theta(t) = theta_max (1 - cos(2 pi t / P)) / 2 and its rate: 0 -> theta_max -> 0 per period."""
    w = 2 * math.pi / period_s

    def theta(t):
        return 0.5 * theta_max_rad * (1 - np.cos(w * np.asarray(t)))

    def theta_t(t):
        return 0.5 * theta_max_rad * w * np.sin(w * np.asarray(t))

    return theta, theta_t


def internal_twist(bw: TorsionHysteresis, length_m: float, theta_t, times, z0: float = 0.0,
                   rtol: float = 1e-11):
    """z(t) [rad/m] at ``times`` for the uniform twist rate theta_t(t) / L0 (solve_ivp, DOP853;
    steps no longer than 1/200 of the span, so that the kinks at the reversals are met)."""
    times = np.asarray(times, dtype=float)

    def rhs(t, z):
        tau_t = theta_t(t) / length_m
        za = abs(z[0])
        return [tau_t * (bw.A - (bw.beta_m_n * np.sign(tau_t * z[0]) + bw.gamma_m_n) * za**bw.n)]

    sol = solve_ivp(rhs, (times[0], times[-1]), [z0], method="DOP853", t_eval=times, rtol=rtol,
                    atol=1e-14, max_step=(times[-1] - times[0]) / 200)
    if not sol.success:
        raise RuntimeError(f"solve_ivp: {sol.message}")
    return sol.y[0]


def moment(bw: TorsionHysteresis, GJ_Nm2: float, length_m: float, theta, theta_t, times):
    """M(t) [Nm] of the segment of length L0 twisted by theta(t) [rad]."""
    z = internal_twist(bw, length_m, theta_t, times)
    return GJ_Nm2 * (bw.rho * theta(times) / length_m + (1 - bw.rho) * z)


def cycle_energies(times, theta, M, period_s: float, cycles: int) -> np.ndarray:
    """The work of M on theta over each period [J], the trapezoid rule on the samples
    (each period's samples from its first to its last time, both included)."""
    times, theta, M = (np.asarray(x, dtype=float) for x in (times, theta, M))
    out = []
    for k in range(cycles):
        t0, t1 = k * period_s, (k + 1) * period_s
        eps = 1e-9 * period_s
        sel = (times >= t0 - eps) & (times <= t1 + eps)
        th, m = theta[sel], M[sel]
        out.append(float(np.sum(0.5 * (m[1:] + m[:-1]) * np.diff(th))))
    return np.array(out)


def secant(theta, M, length_m: float):
    """M L0 / theta [Nm^2], the ratio of the paper's Fig. 5 (Eq. 65 solved for GJ);
    NaN where theta = 0."""
    theta = np.asarray(theta, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(theta != 0, np.asarray(M) * length_m / theta, np.nan)
