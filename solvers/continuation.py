"""Pseudo-arclength continuation of periodic orbits in f1, through folds.

Unknowns Y = (X, f1) (and Delta without a controller: not continued here,
refused).  From an orbit Y_k with unit tangent tau_k (||tau|| in the
normalised state and f1 [Hz]), the predictor Y_k + ds tau_k is corrected
by Newton on

    G(X, f1) = P(X; f1) - X - Delta(f1) e_alpha = 0,     tau_k . (Y - Y_pred) = 0,

with the chord [[M_k - I, G_f1], [tau_k^T]]: M_k is the monodromy at Y_k,
G_f1 central differences of G over f1 with the steps per period held
(one M for the whole corrector, so that the map is smooth in f1).  The
next tangent solves [[M - I, G_f1], [tau_k^T]] tau = (0, 1).  The step
adapts: x1.5 after a corrector of <= 5 iterations, /1.5 after >= 7, /2 after a failure.

Folds (limit points of cycles) are where df1/ds changes sign; they are
located between the two points by the secant on tau_f1.  Period doubling
(a multiplier through -1) and Neimark-Sacker (a complex pair through the
unit circle) are flagged where the count of multipliers outside the
unit circle changes, by kind; they are not bisected (stated in the summary).
"""

from __future__ import annotations

import logging
import time

import numpy as np
import scipy.linalg

from rawehelix.solvers.orbits import AlphaMap, Orbit
from rawehelix.solvers.snes import SolverError

log = logging.getLogger(__name__)


def _unstable(mu) -> dict:
    """Multipliers outside the unit circle, by kind (real > 1, real < -1, complex)."""
    out = np.abs(mu) > 1.0 + 1e-9
    real = np.abs(mu.imag) <= 1e-9 * np.maximum(1.0, np.abs(mu))
    return {"fold": int(np.sum(out & real & (mu.real > 0))),
            "period_doubling": int(np.sum(out & real & (mu.real < 0))),
            "neimark_sacker": int(np.sum(out & ~real))}


class Branch:
    """A branch of orbits traced by pseudo-arclength continuation."""

    def __init__(self, alpha_map: AlphaMap, ds: float = 0.1, ds_min: float = 1e-4,
                 ds_max: float = 0.5, tol: float = 1e-7, max_it: int = 8):
        if not alpha_map.controller:
            raise SolverError("continuation: a scene without the controller's integral action "
                              "(k1 = 0) has a free twist rotation; continue it at fixed f1 steps "
                              "(AlphaMap.orbit) instead")
        self.m = alpha_map
        self.ds, self.ds_min, self.ds_max, self.tol, self.max_it = ds, ds_min, ds_max, tol, max_it
        self.points: list[Orbit] = []
        self.folds: list[dict] = []
        self.bifurcations: list[dict] = []

    def _G(self, X, f1, steps, tangent=False):
        """(G, monodromy or None) at (X, f1), Delta fixed by the controller."""
        G, _, Phi = self.m.shooting_residual(X, f1, self.m.rotation(f1), tangent=tangent,
                                             steps=steps)
        return G, Phi

    def _G_f1(self, X, f1, steps, eps=1e-5):
        return (self._G(X, f1 + eps, steps)[0] - self._G(X, f1 - eps, steps)[0]) / (2 * eps)

    def _bordered(self, A, gf, tau):
        """[[M - I, G_f1], [(w^2 tau)^T]]: the corrector's and the tangent's matrix."""
        return np.block([[A, gf[:, None]], [(self.w**2 * tau)[None, :]]])

    def _tangent(self, orbit: Orbit, tau_prev, steps):
        A = orbit.monodromy - np.eye(orbit.X.size)
        gf = self._G_f1(orbit.X, orbit.f1_Hz, steps)
        K = self._bordered(A, gf, tau_prev)
        rhs = np.zeros(K.shape[0])
        rhs[-1] = 1.0
        tau = np.linalg.solve(K, rhs)
        return tau / np.linalg.norm(self.w * tau), A, gf

    def trace(self, first: Orbit, f1_stop: float, direction: float = 1.0, max_points: int = 400,
              progress=None):
        """Continue from ``first`` until f1 leaves [min, max] of (first.f1, f1_stop)."""
        lo, hi = sorted((first.f1_Hz, f1_stop))
        n = first.X.size
        tau = np.zeros(n + 1)
        tau[-1] = direction
        steps = first.steps
        # the arclength's metric: the state weighted so that, where the branch
        # starts, a step ds moves f1 by about ds / sqrt(2) [Hz]
        self.w = np.ones(n + 1)
        tau, A, gf = self._tangent(first, tau, steps)
        self.w[:n] = abs(tau[-1]) / max(np.linalg.norm(tau[:n]), 1e-300)
        tau, A, gf = self._tangent(first, tau, steps)
        self.points = [first]
        ds = self.ds
        while len(self.points) < max_points:
            prev = self.points[-1]
            Y0 = np.concatenate([prev.X, [prev.f1_Hz]])
            start = time.perf_counter()
            steps = self.m.steps_per_period(prev.f1_Hz)
            Y = Y0 + ds * tau
            K = self._bordered(A, gf, tau)
            ok, lu, res, last = False, None, np.inf, np.inf
            for its in range(1, self.max_it + 1):
                X, f1 = Y[:n], float(Y[-1])
                if not f1 > 0:
                    break
                slow = lu is not None and res > 0.1 * last  # the chord is too far off
                G, Phi = self._G(X, f1, steps, tangent=slow)
                if slow:  # Newton: the monodromy and G_f1 here
                    A, gf = Phi - np.eye(n), self._G_f1(X, f1, steps)
                    K, lu = self._bordered(A, gf, tau), None
                last, res = res, np.linalg.norm(G) / max(1.0, np.linalg.norm(X))
                log.debug("corrector %d: f1 = %.6f Hz, |G|/|X| = %.3g, ds %.3g%s", its, f1, res,
                          ds, " (fresh monodromy)" if slow else "")
                if res <= self.tol:
                    ok = True
                    break
                if lu is None:
                    lu = scipy.linalg.lu_factor(K)
                r = np.concatenate([G, [(self.w**2 * tau) @ (Y - Y0) - ds]])
                Y = Y - scipy.linalg.lu_solve(lu, r)
            if not ok:
                ds /= 2
                if ds < self.ds_min:
                    raise SolverError(f"continuation: the corrector failed at f1 = "
                                      f"{prev.f1_Hz:.4f} Hz with the smallest step {self.ds_min}")
                continue
            orbit = self.m.finish(X, f1, self.m.rotation(f1), its, res, start, steps)
            tau_new, A, gf = self._tangent(orbit, tau, steps)
            self._detect(prev, orbit, tau, tau_new)
            tau = tau_new
            self.points.append(orbit)
            if progress:
                progress(orbit)
            if its <= 5:  # an easy corrector (a chord step and a refresh or two)
                ds = min(self.ds_max, ds * 1.5)
            elif its >= 7:
                ds = max(self.ds_min, ds / 1.5)
            if not (lo <= f1 <= hi):
                break
        return self.points

    def _detect(self, a: Orbit, b: Orbit, tau_a, tau_b):
        if np.sign(tau_a[-1]) != np.sign(tau_b[-1]):  # df1/ds through zero: a fold
            w = tau_a[-1] / (tau_a[-1] - tau_b[-1])
            self.folds.append({"f1_Hz": a.f1_Hz + w * (b.f1_Hz - a.f1_Hz),
                               "tension_max_N": a.tension_max_N + w * (b.tension_max_N - a.tension_max_N),
                               "kind": "fold"})
        ua, ub = _unstable(a.multipliers), _unstable(b.multipliers)
        for kind in ("period_doubling", "neimark_sacker"):
            if ua[kind] != ub[kind]:
                self.bifurcations.append({"f1_Hz": 0.5 * (a.f1_Hz + b.f1_Hz),
                                          "tension_max_N": 0.5 * (a.tension_max_N + b.tension_max_N),
                                          "kind": kind})
