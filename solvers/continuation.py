"""Pseudo-arclength continuation of periodic orbits in f1, through folds.

Unknowns Y = (X, f1) (and Delta without a controller: not continued here,
refused).  From an orbit Y_k with unit tangent tau_k (||tau|| in the
normalised state and f1 [Hz]), the predictor Y_k + ds tau_k is corrected
by Newton on

    G(X, f1) = P(X; f1) - X - Delta(f1) e_alpha = 0,     tau_k . (Y - Y_pred) = 0,

with the chord [[M_k - I, G_f1], [tau_k^T]]: M_k is the monodromy at Y_k,
G_f1 central differences of G over f1 with the steps per period held
(one M for the whole corrector, so that the map is smooth in f1).  The
next tangent solves [[M - I, G_f1], [tau_k^T]] tau = (0, 1).

The step adapts: x1.5 after a corrector of <= 5 iterations, /1.5 after >= 7,
/2 after a failure; and so that T max changes by at most ``tension_step``
(relative) between two points: a corrected point past it is refused (before
its Floquet period) and retried with a step scaled to the change, and the
next step is capped by the same linear prediction.  So a peak of T max is
approached in steps of at most that fraction and is not stepped over.

Folds (limit points of cycles) are where df1/ds changes sign; their arclength
by the secant on tau_f1, their f1 there by the cubic Hermite interpolant of
f1(s) (values and slopes tau_f1 at both points); ``f1_error_Hz`` is its
distance from the linear interpolant, an estimate of the error.  Period
doubling (a real multiplier through -1) and Neimark-Sacker (a complex pair
through the unit circle) are flagged where the count of multipliers of that
kind outside the unit circle changes, and located by bisection in arclength
between the two points (:func:`bisect_crossing`): each probe is a corrector
from the earlier point with a shorter step and a Floquet period.
"""

from __future__ import annotations

import dataclasses
import logging
import time

import numpy as np
import scipy.linalg

from rawehelix.solvers.floquet import Orbit, PeriodMap
from rawehelix.solvers.snes import SolverError

log = logging.getLogger(__name__)

TENSION_STEP = 0.05  # the largest relative change of T max between two branch points
BISECTION_HZ = 1e-4  # PD / NS located to this width in f1 [Hz]
BISECTION_MAX = 12  # probes per bisection
PEAK_PROBES = 5  # correctors per peak refinement
PEAK_TOL = 1e-5  # a peak's T max located to this relative change between two vertices


def _unstable(mu) -> dict:
    """Multipliers outside the unit circle, by kind (real > 1, real < -1, complex)."""
    out = np.abs(mu) > 1.0 + 1e-9
    real = np.abs(mu.imag) <= 1e-9 * np.maximum(1.0, np.abs(mu))
    return {"fold": int(np.sum(out & real & (mu.real > 0))),
            "period_doubling": int(np.sum(out & real & (mu.real < 0))),
            "neimark_sacker": int(np.sum(out & ~real))}


def bisect_crossing(probe, s_b: float, count_a: int, kind: str, f1_width: float = BISECTION_HZ,
                    max_probes: int = BISECTION_MAX):
    """Bisection in arclength s in (0, s_b) for the change of the count of
    ``kind`` multipliers outside the unit circle, from ``count_a`` at s = 0.
    ``probe(s)`` -> (f1, multipliers, info).  Returns (s_lo, s_hi, f1_lo,
    f1_hi, info_hi, probes): the bracket that holds the change, the probe
    just past it, and the number of probes used.  Stops when the bracket is
    under ``f1_width`` in f1 or after ``max_probes``."""
    lo, hi, f_lo, f_hi, info_hi = 0.0, s_b, None, None, None
    probes = 0
    while probes < max_probes and (f_lo is None or f_hi is None or abs(f_hi - f_lo) > f1_width):
        mid = 0.5 * (lo + hi)
        f1, mu, info = probe(mid)
        probes += 1
        if _unstable(np.asarray(mu))[kind] == count_a:
            lo, f_lo = mid, f1
        else:
            hi, f_hi, info_hi = mid, f1, info
    return lo, hi, f_lo, f_hi, info_hi, probes


@dataclasses.dataclass
class State:
    """What the next step needs besides the last point: the tangent, the chord's
    monodromy - I and G_f1, the arclength metric and the step."""

    tau: np.ndarray
    A: np.ndarray
    gf: np.ndarray
    w: np.ndarray
    ds: float

    def arrays(self) -> dict:
        return {"tau": self.tau, "A": self.A, "gf": self.gf, "w": self.w, "ds": np.array(self.ds)}

    @classmethod
    def from_arrays(cls, data) -> "State":
        return cls(tau=data["tau"], A=data["A"], gf=data["gf"], w=data["w"], ds=float(data["ds"]))


class Branch:
    """A branch of orbits traced by pseudo-arclength continuation."""

    def __init__(self, alpha_map: PeriodMap, ds: float = 0.1, ds_min: float = 1e-4,
                 ds_max: float = 0.5, tol: float = 1e-7, max_it: int = 8,
                 tension_step: float = TENSION_STEP):
        if not alpha_map.controller:
            raise SolverError("continuation: a scene without the controller's integral action "
                              "(k1 = 0) has a free twist rotation; continue it at fixed f1 steps "
                              "(AlphaMap.orbit) instead")
        if not 0 < tension_step < 1:
            raise SolverError(f"continuation: tension_step {tension_step} must be in (0, 1)")
        self.m = alpha_map
        self.ds, self.ds_min, self.ds_max, self.tol, self.max_it = ds, ds_min, ds_max, tol, max_it
        self.tension_step = tension_step
        self.points: list[Orbit] = []
        self.folds: list[dict] = []
        self.bifurcations: list[dict] = []
        self.peaks: list[dict] = []
        self.state: State | None = None

    def _G(self, X, f1, steps, tangent=False):
        """(G, tension over the period, monodromy or None) at (X, f1), Delta fixed
        by the controller."""
        return self.m.shooting_residual(X, f1, self.m.rotation(f1), tangent=tangent, steps=steps)

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

    def _correct(self, prev: Orbit, tau, A, gf, ds, steps):
        """The corrector from ``prev`` along ``tau`` by ``ds``: (X, f1, iterations,
        |G|/|X|, the tension over the period (normalised)) or None if it fails."""
        n = prev.X.size
        Y0 = np.concatenate([prev.X, [prev.f1_Hz]])
        Y = Y0 + ds * tau
        K = self._bordered(A, gf, tau)
        lu, res, last = None, np.inf, np.inf
        for its in range(1, self.max_it + 1):
            X, f1 = Y[:n], float(Y[-1])
            if not f1 > 0:
                return None
            slow = lu is not None and res > 0.1 * last  # the chord is too far off
            G, tension, Phi = self._G(X, f1, steps, tangent=slow)
            if slow:  # Newton: the monodromy and G_f1 here
                A, gf = Phi - np.eye(n), self._G_f1(X, f1, steps)
                K, lu = self._bordered(A, gf, tau), None
            last, res = res, np.linalg.norm(G) / max(1.0, np.linalg.norm(X))
            log.debug("corrector %d: f1 = %.6f Hz, |G|/|X| = %.3g, ds %.3g%s", its, f1, res,
                      ds, " (fresh monodromy)" if slow else "")
            if res <= self.tol:
                return X, f1, its, res, tension
            if lu is None:
                lu = scipy.linalg.lu_factor(K)
            r = np.concatenate([G, [(self.w**2 * tau) @ (Y - Y0) - ds]])
            Y = Y - scipy.linalg.lu_solve(lu, r)
        return None

    def start(self, first: Orbit, direction: float = 1.0):
        """The first point and its tangent in ``direction`` of f1."""
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
        self.state = State(tau=tau, A=A, gf=gf, w=self.w.copy(), ds=self.ds)

    def resume(self, points: list[Orbit], state: State, folds=(), bifurcations=(), peaks=()):
        """Continue from stored points and the state after the last of them."""
        self.points, self.state, self.w = list(points), state, state.w.copy()
        self.folds, self.bifurcations = list(folds), list(bifurcations)
        self.peaks = list(peaks)

    def trace(self, first: Orbit | None, f1_stop: float, direction: float = 1.0,
              max_points: int = 400, progress=None, on_point=None):
        """Continue from ``first`` (or from :meth:`resume`'s points, ``first`` None)
        until f1 leaves [min, max] of (f1 of the branch's first point, f1_stop)
        or the branch has ``max_points``.  ``progress(orbit)`` is called at every
        new point, ``on_point(orbit, events, state)`` too, with the folds and
        bifurcations found before it and the state after it (a store's hook)."""
        if first is not None:
            self.start(first, direction)
        lo, hi = sorted((self.points[0].f1_Hz, f1_stop))
        n = self.points[0].X.size
        last = self.points[-1]
        if len(self.points) > 1 and not (lo <= last.f1_Hz <= hi):
            return self.points  # a resumed branch that had already left the window
        while len(self.points) < max_points:
            prev, st = self.points[-1], self.state
            start = time.perf_counter()
            steps = self.m.steps_per_period(prev.f1_Hz)
            got = self._correct(prev, st.tau, st.A, st.gf, st.ds, steps)
            if got is None:
                st.ds /= 2
                if st.ds < self.ds_min:
                    raise SolverError(f"continuation: the corrector failed at f1 = "
                                      f"{prev.f1_Hz:.4f} Hz with the smallest step {self.ds_min}")
                continue
            X, f1, its, res, tension = got
            change = abs(self.m.q.tension_N(tension).max() / prev.tension_max_N - 1.0)
            if change > self.tension_step and st.ds > self.ds_min:
                # T max moved too far: a shorter step, before the Floquet period
                st.ds = max(self.ds_min, st.ds * max(0.2, 0.8 * self.tension_step / change))
                continue
            orbit = self.m.finish(X, f1, self.m.rotation(f1), its, res, start, steps)
            tau_new, A, gf = self._tangent(orbit, st.tau, steps)
            events = self._detect(prev, orbit, st, tau_new, steps)
            ds = st.ds
            if its <= 5:  # an easy corrector (a chord step and a refresh or two)
                ds = min(self.ds_max, ds * 1.5)
            elif its >= 7:
                ds = max(self.ds_min, ds / 1.5)
            if change > 0:  # the next change of T max, predicted linearly, within the bound
                ds = max(self.ds_min, min(ds, st.ds * 0.8 * self.tension_step / change))
            self.state = State(tau=tau_new, A=A, gf=gf, w=self.w.copy(), ds=ds)
            self.points.append(orbit)
            if on_point:
                on_point(orbit, events, self.state)
            if progress:
                progress(orbit)
            if not (lo <= f1 <= hi):
                break
        return self.points

    # -- events -------------------------------------------------------------------------
    def _detect(self, a: Orbit, b: Orbit, st: State, tau_b, steps) -> list[dict]:
        """Folds and bifurcations between two consecutive points (appended to
        ``folds`` / ``bifurcations`` and returned)."""
        events = []
        ta, tb = st.tau[-1], tau_b[-1]
        if np.sign(ta) != np.sign(tb):  # df1/ds through zero: a fold
            events.append(fold_between(a, b, ta, tb, st.ds))
            self.folds.append(events[-1])
        ua, ub = _unstable(a.multipliers), _unstable(b.multipliers)
        for kind in ("period_doubling", "neimark_sacker"):
            if ua[kind] != ub[kind]:
                events.append(self._locate(a, b, st, kind, ua[kind], steps))
                self.bifurcations.append(events[-1])
        if len(self.points) >= 2:
            z = self.points[-2]
            if a.tension_max_N > z.tension_max_N and a.tension_max_N >= b.tension_max_N:
                events.append(self._peak(z, a, b, st, steps))
                self.peaks.append(events[-1])
        return events

    def _peak(self, z: Orbit, a: Orbit, b: Orbit, st: State, steps) -> dict:
        """A local maximum of T max at or near a (T max of z < a >= b): the vertex
        of the parabola through (s, T max) of the three, in arclength s from a
        along its tangent, then correctors at the vertex, each replacing the
        lowest of the three, until T max changes by less than PEAK_TOL."""
        Y = lambda o: np.concatenate([o.X, [o.f1_Hz]])  # noqa: E731
        s_z = float((self.w**2 * st.tau) @ (Y(z) - Y(a)))
        pts = [(s_z, z.tension_max_N, z.f1_Hz), (0.0, a.tension_max_N, a.f1_Hz),
               (st.ds, b.tension_max_N, b.f1_Hz)]
        best, probes, located = pts[1], 0, "point"
        while probes < PEAK_PROBES:
            x, y = np.array([p[0] for p in pts]), np.array([p[1] for p in pts])
            c2, c1, _ = np.polyfit(x, y, 2)
            if not c2 < 0:
                break
            sv = -c1 / (2 * c2)
            if not min(x) < sv < max(x):
                break
            got = self._correct(a, st.tau, st.A, st.gf, sv, steps)
            probes += 1
            if got is None:
                break
            _, f1, _, _, tension = got
            T = float(self.m.q.tension_N(tension).max())
            previous = best
            if T > best[1]:
                best, located = (sv, T, f1), "refined"
            pts[int(np.argmin(y))] = (sv, T, f1)
            if abs(T / previous[1] - 1) <= PEAK_TOL:
                break
        return {"f1_Hz": best[2], "tension_max_N": best[1], "kind": "peak", "located": located,
                "probes": probes, "bracket_Hz": [z.f1_Hz, b.f1_Hz]}

    def _locate(self, a: Orbit, b: Orbit, st: State, kind: str, count_a: int, steps) -> dict:
        """PD / NS between a and b by bisection in arclength (each probe: a
        corrector from a with a shorter step and the Floquet period there)."""

        def probe(s):
            got = self._correct(a, st.tau, st.A, st.gf, s, steps)
            if got is None:
                raise SolverError(f"continuation: the corrector failed while bisecting a "
                                  f"{kind} between {a.f1_Hz:.5f} and {b.f1_Hz:.5f} Hz")
            X, f1, its, res, _ = got
            o = self.m.finish(X, f1, self.m.rotation(f1), its, res, time.perf_counter(), steps)
            return o.f1_Hz, o.multipliers, o

        lo, hi, f_lo, f_hi, o, probes = bisect_crossing(probe, st.ds, count_a, kind)
        f_lo = a.f1_Hz if f_lo is None else f_lo
        if o is None:
            o = b
        f_hi = o.f1_Hz
        return {"f1_Hz": 0.5 * (f_lo + f_hi), "tension_max_N": o.tension_max_N, "kind": kind,
                "f1_error_Hz": 0.5 * abs(f_hi - f_lo), "probes": probes,
                "multiplier": _crossing(o.multipliers, kind)}


def _crossing(mu, kind) -> list[float]:
    """The multiplier of ``kind`` nearest the unit circle (re, im)."""
    mu = np.asarray(mu)
    real = np.abs(mu.imag) <= 1e-9 * np.maximum(1.0, np.abs(mu))
    sel = (real & (mu.real < 0)) if kind == "period_doubling" else ~real
    if not np.any(sel):
        return []
    m = mu[sel][np.argmin(np.abs(np.abs(mu[sel]) - 1.0))]
    return [float(m.real), float(m.imag)]


def fold_between(a: Orbit, b: Orbit, ta: float, tb: float, ds: float) -> dict:
    """A fold between a and b, where df1/ds goes from ta to tb (opposite signs):
    s* by the secant on df1/ds, f1(s*) by the cubic Hermite interpolant of f1(s)
    over [0, ds]; the error estimate is its distance from the linear one."""
    w = ta / (ta - tb)
    fa, fb = a.f1_Hz, b.f1_Hz
    h00, h10, h01, h11 = (2 * w**3 - 3 * w**2 + 1, w**3 - 2 * w**2 + w, -2 * w**3 + 3 * w**2,
                          w**3 - w**2)
    hermite = h00 * fa + h10 * ds * ta + h01 * fb + h11 * ds * tb
    linear = fa + w * (fb - fa)
    return {"f1_Hz": float(hermite),
            "tension_max_N": a.tension_max_N + w * (b.tension_max_N - a.tension_max_N),
            "kind": "fold", "f1_error_Hz": float(abs(hermite - linear)),
            "bracket_Hz": [fa, fb]}
