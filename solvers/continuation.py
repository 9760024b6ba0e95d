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

A corrector that had to refresh the monodromy starts the next one with the
monodromy at its predictor (``State.fresh``): below the resonance the
multipliers rotate by 2 pi f_n d(1/f1) between points, so the last point's
monodromy is a stale chord.  After two slow correctors in a row (>= SLOW
iterations) or a failed one, and while every multiplier of the last point is
FOLD_MARGIN away from +1 (no fold near, so f1 parametrises the branch), the
next point is found by *natural* steps (``State.natural``): shooting at the
predictor's f1 (:meth:`PeriodMap.orbit`, with the scheme's own steps per period
there), f1 moving by at most NATURAL_STEP of itself.  Near a fold the
arclength corrector takes over again.

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

Superharmonic resonances k:1 (k f1 = f_n of a driven natural frequency) are
where a Floquet multiplier mu = exp(lambda T1) of that mode passes the
positive real axis: its angle is 2 pi f_n / f1 (mod 2 pi), its distance
|mu - 1| (about the modal damping over a period there, 1 - |mu|) sets the
resonance's width, and the resolvent (M - I)^-1 its height.  A narrow one
lies between two points of the T max step unseen, so the caller names the
``sites`` (:class:`Site`: f_n / k with f_n from the linearisation) and, within
``SITE_WINDOW`` of a site, the step moves the site's multiplier's angle
(d theta / d f1 = 2 pi f_n / f1^2) by at most ``angle_step`` |mu - 1| (the
multiplier's distance to +1 at the last point), so the points close in
geometrically on the crossing; a step that would jump a window is cut to
land at its edge.  The site's multiplier is tracked from point to point
(:func:`track`): the lightly damped one (|mu| >= ``LIGHT``) nearest the
predicted angle 2 pi (f_n / f1 - k) where a run in the window begins, then
the one nearest the last one's angle moved by the predicted rotation, so
that the many other lightly damped multipliers (70 of 156 at N = 4), which
rotate at other rates, are not taken for it.  Only near the linearisation's
state (the orbit's mean T(0) within LINEAR_SHIFT of its tension,
:meth:`Site.holds_at`): on the primary resonance's S-curve a site's prediction
means nothing (at N = 4 the 3:1 site of a 38.1 Hz lateral mode, 12.70 Hz, lies
on it, and 10 "superharmonic" minima of |mu - 1| were reported there).
Where the tracked multiplier's angle changes sign between two points of a
window, the resonance is located by the angle's zero, interpolated linearly
in 1/f1 (:func:`superharmonic_between`), and reported in ``peaks`` with kind
``superharmonic``, its f1, |mu - 1| there and T max and T max - T min
interpolated to it.
"""

from __future__ import annotations

import dataclasses
import logging
import time

import numpy as np

from rawehelix.solvers.floquet import SLOW_RATE, Broyden, Orbit, PeriodMap
from rawehelix.solvers.snes import SolverError

log = logging.getLogger(__name__)

TENSION_STEP = 0.05  # the largest relative change of T max between two branch points
BISECTION_HZ = 1e-4  # PD / NS located to this width in f1 [Hz]
BISECTION_MAX = 12  # probes per bisection
PEAK_PROBES = 8  # correctors per peak refinement
PEAK_TOL = 1e-6  # a peak's T max located to this relative change between two vertices
SITE_WINDOW = 0.05  # the step control acts within this relative distance of a site's f1
ANGLE_STEP = 1.0  # within a window: the angle's change per step over |mu - 1|
LIGHT = 0.5  # multipliers of modulus below this are not a site's (damped over a period)
SITE_ANGLE = 0.5  # a site's multiplier: within this of its predicted angle [rad]
RUN = 200  # the points a site's multiplier is tracked over (the last of the branch)
SUPERHARMONIC_ORDERS = (2, 3)  # k of the k:1 resonances the sites are made for
LINEAR_SHIFT = 0.1  # sites act on orbits whose mean T(0) is within this of the linearised one
FOLD_MARGIN = 0.02  # natural steps only while every multiplier is this far from +1
NATURAL_STEP = 0.5  # a natural step moves f1 by at most this fraction of itself
STOP_TOL = 1e-9  # relative: a point this near the window's end ends the trace
SLOW = 6  # two correctors in a row of this many iterations turn to natural steps


@dataclasses.dataclass(frozen=True)
class Site:
    """Where a k:1 superharmonic resonance of the natural frequency f_n is expected."""

    f_n_Hz: float
    k: int
    tension_N: float | None = None  # T(0) of the linearised state (None: not checked)

    @property
    def f1_Hz(self) -> float:
        return self.f_n_Hz / self.k

    def angle(self, f1: float) -> float:
        """The mode's multiplier's predicted angle at f1, in (-pi, pi]."""
        return float(np.angle(np.exp(2j * np.pi * (self.f_n_Hz / f1 - self.k))))

    def near(self, f1: float) -> bool:
        return abs(f1 / self.f1_Hz - 1.0) <= SITE_WINDOW

    def holds_at(self, orbit: Orbit) -> bool:
        """The orbit's mean tension at s = 0 is within LINEAR_SHIFT of the
        linearised state's, so f_n (~ sqrt(T) for the lateral modes) has moved
        by less than the window: on a resonance's S-curve (T several times the
        stationary) the prediction means nothing."""
        if self.tension_N is None:
            return True
        mean = 0.5 * (orbit.tension_max_N + orbit.tension_min_N)
        return abs(mean / self.tension_N - 1.0) <= LINEAR_SHIFT


def sites_for(frequencies_Hz, f1_lo: float, f1_hi: float,
              orders=SUPERHARMONIC_ORDERS, tension_N: float | None = None) -> list[Site]:
    """The k:1 sites f_n / k of the natural frequencies f_n inside [f1_lo, f1_hi]
    (of the linearisation about a state whose tension at s = 0 is ``tension_N``);
    sites closer than a tenth of the window (a lateral pair) are one."""
    out = []
    for site in sorted((Site(float(f), int(k), tension_N) for f in frequencies_Hz for k in orders
                        if f1_lo <= f / k <= f1_hi), key=lambda x: x.f1_Hz):
        if not out or site.f1_Hz / out[-1].f1_Hz - 1.0 > 0.1 * SITE_WINDOW:
            out.append(site)
    return out


def track(site: Site, points) -> list:
    """The site's multiplier at each of ``points`` (None outside its window): at the
    first point of a run inside the window, the lightly damped one (|mu| >= LIGHT)
    nearest the predicted angle 2 pi (f_n / f1 - k); at each next point, the one
    nearest the last one's angle moved by the predicted 2 pi f_n (1/f1 - 1/f1_last),
    so that other modes passing by are not taken for it.  A run restarts where
    none is within SITE_ANGLE of the prediction."""
    out, last = [], None
    for o in points:
        mu = np.asarray(o.multipliers)
        mu = mu[np.abs(mu) >= LIGHT]
        if not site.near(o.f1_Hz) or mu.size == 0 or not site.holds_at(o):
            out.append(None)
            last = None
            continue
        if last is None:
            want = site.angle(o.f1_Hz)
        else:
            want = np.angle(last[0]) + 2 * np.pi * site.f_n_Hz * (1 / o.f1_Hz - 1 / last[1])
        miss = np.abs(np.angle(mu * np.exp(-1j * want)))
        k = int(np.argmin(miss))
        if miss[k] > SITE_ANGLE:
            out.append(None)
            last = None
            continue
        out.append(complex(mu[k]))
        last = (out[-1], o.f1_Hz)
    return out


def far_from_folds(mu) -> bool:
    """No multiplier within FOLD_MARGIN of +1: no fold (a real multiplier through
    +1) is near, so f1 parametrises the branch and shooting at fixed f1 is sound."""
    mu = np.asarray(mu)
    return bool(mu.size == 0 or np.min(np.abs(mu - 1.0)) > FOLD_MARGIN)


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
    fresh: bool = False  # the next corrector starts with a monodromy at its predictor
    natural: bool = False  # the next point by shooting at fixed f1, if no fold is near

    def arrays(self) -> dict:
        return {"tau": self.tau, "A": self.A, "gf": self.gf, "w": self.w, "ds": np.array(self.ds),
                "fresh": np.array(self.fresh), "natural": np.array(self.natural)}

    @classmethod
    def from_arrays(cls, data) -> "State":
        flag = lambda key: bool(data[key]) if key in data else False  # noqa: E731 (older stores)
        return cls(tau=data["tau"], A=data["A"], gf=data["gf"], w=data["w"], ds=float(data["ds"]),
                   fresh=flag("fresh"), natural=flag("natural"))


class Branch:
    """A branch of orbits traced by pseudo-arclength continuation."""

    def __init__(self, alpha_map: PeriodMap, ds: float = 0.1, ds_min: float = 1e-4,
                 ds_max: float = 2.0, tol: float = 1e-7, max_it: int = 8,
                 tension_step: float = TENSION_STEP, sites=(), angle_step: float = ANGLE_STEP):
        if not alpha_map.controller:
            raise SolverError("continuation: a scene without the controller's integral action "
                              "(k1 = 0) has a free twist rotation; continue it at fixed f1 steps "
                              "(AlphaMap.orbit) instead")
        if not 0 < tension_step < 1:
            raise SolverError(f"continuation: tension_step {tension_step} must be in (0, 1)")
        self.m = alpha_map
        self.ds, self.ds_min, self.ds_max, self.tol, self.max_it = ds, ds_min, ds_max, tol, max_it
        self.tension_step = tension_step
        self.sites, self.angle_step = tuple(sites), angle_step  # superharmonic sites
        self.points: list[Orbit] = []
        self.folds: list[dict] = []
        self.bifurcations: list[dict] = []
        self.peaks: list[dict] = []
        self.state: State | None = None

    def _G(self, X, f1, steps, tangent=False):
        """(G, tension over the period, monodromy or None) at (X, f1), Delta fixed
        by the controller."""
        return self.m.shooting_residual(X, f1, self.m.rotation(f1), tangent=tangent, steps=steps)

    def _G_f1(self, X, f1, steps, G=None, eps=1e-5):
        """dG/df1 at fixed steps per period: forward differences from ``G`` (G at
        (X, f1), one more period), or central ones without it."""
        if G is None:
            gf = (self._G(X, f1 + eps, steps)[0] - self._G(X, f1 - eps, steps)[0]) / (2 * eps)
        else:
            gf = (self._G(X, f1 + eps, steps)[0] - G) / eps
        gf[self.m.carried] = 0.0  # carried entries (floquet.py): not on the tangent
        return gf

    def _bordered(self, A, gf, tau):
        """[[M - I, G_f1], [(w^2 tau)^T]]: the corrector's and the tangent's matrix."""
        return np.block([[A, gf[:, None]], [(self.w**2 * tau)[None, :]]])

    def _tangent(self, orbit: Orbit, tau_prev, steps):
        A = self.m.newton_matrix(orbit.monodromy)
        G = orbit.G if orbit.steps == steps else None
        gf = self._G_f1(orbit.X, orbit.f1_Hz, steps, G)
        K = self._bordered(A, gf, tau_prev)
        rhs = np.zeros(K.shape[0])
        rhs[-1] = 1.0
        tau = np.linalg.solve(K, rhs)
        return tau / np.linalg.norm(self.w * tau), A, gf

    def _correct(self, prev: Orbit, tau, A, gf, ds, steps, fresh: bool = False):
        """The corrector from ``prev`` along ``tau`` by ``ds``: (X, f1, iterations,
        |G|/|X|, the tension over the period (normalised), whether it refreshed the
        monodromy) or None if it fails.  The bordered chord (``A``: the last point's
        M - I) improved by Broyden's updates (:class:`Broyden`) and refreshed where
        an iteration leaves more than SLOW_RATE of |G|.  ``fresh``: the first
        iteration takes the monodromy at the predictor instead of ``A``."""
        n = prev.X.size
        Y0 = np.concatenate([prev.X, [prev.f1_Hz]])
        Y = Y0 + ds * tau
        K = self._bordered(A, gf, tau)
        H, res, last, refreshed, previous = None, np.inf, np.inf, False, None
        for its in range(1, self.max_it + 1):
            X, f1 = Y[:n], float(Y[-1])
            if not f1 > 0:
                return None
            # the chord is too far off (or stale from the start)
            slow = (H is not None and res > SLOW_RATE * last) or (fresh and its == 1)
            try:
                G, tension, Phi = self._G(X, f1, steps, tangent=slow)
            except SolverError as err:  # the period's steps failed from this iterate
                log.debug("corrector %d: the period map failed at f1 = %.6f Hz: %s", its, f1, err)
                return None
            if slow:  # Newton: the monodromy and G_f1 here
                A = self.m.newton_matrix(Phi)
                gf = self._G_f1(X, f1, steps, G)
                K, H, refreshed = self._bordered(A, gf, tau), None, True
            last, res = res, self.m.shooting_norm(G, X)
            log.debug("corrector %d: f1 = %.6f Hz, |G|/|X| = %.3g, ds %.3g%s", its, f1, res,
                      ds, " (fresh monodromy)" if slow else "")
            if res <= self.tol:
                return self.m.settle(X, G), f1, its, res, tension, refreshed
            r = np.concatenate([G, [(self.w**2 * tau) @ (Y - Y0) - ds]])
            if H is None:
                H = Broyden(K)
            elif previous is not None:  # the secant of the last step
                H.update(Y - previous[0], r - previous[1])
            previous = (Y, r)
            Y = Y - H.solve(r)
        return None

    def _natural(self, prev: Orbit, st: State, f1_stop: float) -> Orbit | None:
        """The next point by shooting at the predictor's f1 (natural parameter), from
        the predictor's state, with the monodromy at each start of the shooting's
        Newton (:meth:`PeriodMap.orbit`) and the scheme's own steps per period at that
        f1; None if it fails.  The step moves f1 by at most NATURAL_STEP of itself,
        and not past ``f1_stop`` (``st.ds`` is cut to match): at 0.5 Hz a period is
        the dearest of the curve, and one past the window cost 46 s of 505 at N = 8."""
        room = abs(f1_stop - prev.f1_Hz)
        cap = min(NATURAL_STEP * prev.f1_Hz, room) / max(abs(st.tau[-1]), 1e-300)
        st.ds = max(self.ds_min, min(st.ds, cap))
        Y = np.concatenate([prev.X, [prev.f1_Hz]]) + st.ds * st.tau
        f1 = float(Y[-1])
        if not f1 > 0:
            return None
        try:
            return self.m.orbit(Y[:-1], f1, tol=self.tol, max_it=2 * self.max_it,
                                steps=self.m.steps_per_period(f1), linear=True)
        except SolverError as err:
            log.debug("natural step to %.6f Hz failed: %s", f1, err)
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
        ds = max(self.ds_min, self._site_step(self.points, tau[-1], self.ds))
        self.state = State(tau=tau, A=A, gf=gf, w=self.w.copy(), ds=ds)

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
        def done(f1):  # out of the window, or at its end (where a natural step lands)
            return not (lo <= f1 <= hi) or abs(f1 - f1_stop) <= STOP_TOL * f1_stop

        if len(self.points) > 1 and done(last.f1_Hz):
            return self.points  # a resumed branch that had already left the window
        while len(self.points) < max_points:
            prev, st = self.points[-1], self.state
            start = time.perf_counter()
            steps = self.m.steps_per_period(prev.f1_Hz)
            natural = st.natural and far_from_folds(prev.multipliers)
            if natural:  # the corrector was slow and no fold is near: shooting at the next f1
                orbit = self._natural(prev, st, f1_stop)
                got = None if orbit is None else (orbit.X, orbit.f1_Hz, orbit.newton_iterations,
                                                  orbit.residual, None, True)
            else:
                got = self._correct(prev, st.tau, st.A, st.gf, st.ds, steps, fresh=st.fresh)
            if got is None:
                st.ds /= 2
                st.natural = True  # a failed corrector: try the next step at fixed f1
                if st.ds < self.ds_min:
                    raise SolverError(f"continuation: the corrector failed at f1 = "
                                      f"{prev.f1_Hz:.4f} Hz with the smallest step {self.ds_min}")
                continue
            X, f1, its, res, tension, refreshed = got
            T_max = orbit.tension_max_N if natural else self.m.q.tension_N(tension).max()
            change = abs(T_max / prev.tension_max_N - 1.0)
            if change > self.tension_step and st.ds > self.ds_min:
                # T max moved too far: a shorter step (before the Floquet period of a corrector)
                st.ds = max(self.ds_min, st.ds * max(0.2, 0.8 * self.tension_step / change))
                continue
            if not natural:
                orbit = self.m.orbit_through(X, f1, self.m.rotation(f1), its, res, start, steps)
            # the new point's tangent with the steps it was found with (a natural step:
            # its own at its f1); the events between the two with the last point's
            tau_new, A, gf = self._tangent(orbit, st.tau, orbit.steps)
            events = self._detect(prev, orbit, st, tau_new, steps)
            ds = st.ds
            if its <= 5 or natural:  # an easy corrector (a chord step and a refresh or two),
                # or a natural step (its iterations on the linear monodromy are cheap periods;
                # the step is capped by NATURAL_STEP and halved where it fails)
                ds = min(self.ds_max, ds * 1.5)
            elif its >= 7:
                ds = max(self.ds_min, ds / 1.5)
            if change > 0:  # the next change of T max, predicted linearly, within the bound
                ds = max(self.ds_min, min(ds, st.ds * 0.8 * self.tension_step / change))
            ds = max(self.ds_min, self._site_step(self.points + [orbit], tau_new[-1], ds))
            self.state = State(tau=tau_new, A=A, gf=gf, w=self.w.copy(), ds=ds, fresh=refreshed,
                               natural=natural or min(its, prev.newton_iterations) >= SLOW)
            self.points.append(orbit)
            if on_point:
                on_point(orbit, events, self.state)
            if progress:
                progress(orbit)
            if done(f1):
                break
        return self.points

    def _site_step(self, points, f1_s: float, ds: float) -> float:
        """The next step from the last of ``points`` cut by the superharmonic sites
        (module docstring): within a window, the site's multiplier's angle moves by
        at most angle_step |mu - 1|; a window ahead is not jumped (the step lands
        just inside its edge)."""
        if not self.sites or abs(f1_s) < 1e-12:
            return ds
        f1, ahead = points[-1].f1_Hz, float(np.sign(f1_s))
        for site in self.sites:
            if site.near(f1):
                mu = track(site, points[-RUN:])[-1]
                if mu is not None:
                    rate = 2 * np.pi * site.f_n_Hz / f1**2  # |d theta / d f1| [rad/Hz]
                    ds = min(ds, self.angle_step * abs(mu - 1.0) / rate / abs(f1_s))
                continue
            edge = site.f1_Hz * (1.0 - ahead * 0.9 * SITE_WINDOW)  # just inside the window
            if ahead * (edge - f1) > 0 and ahead * (f1 + ds * f1_s - edge) > 0:
                ds = min(ds, abs(edge - f1) / abs(f1_s))
        return ds

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
            for site in self.sites:
                found = superharmonic_between(site, (self.points + [b])[-RUN:])
                if found:
                    events.append(found)
                    self.peaks.append(found)
        return events

    def _peak(self, z: Orbit, a: Orbit, b: Orbit, st: State, steps) -> dict:
        """A local maximum of T max at or near a (T max of z < a >= b): the vertex
        of the parabola through (s, T max) of the three, in arclength s from a
        along its tangent, then correctors at the vertex, each keeping the highest
        point and its neighbours in s (a bracket), until T max changes by less
        than PEAK_TOL."""
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
            _, f1, _, _, tension, _ = got
            T = float(self.m.q.tension_N(tension).max())
            previous = best
            if T > best[1]:
                best, located = (sv, T, f1), "refined"
            # the highest of the four and its neighbours on either side in s: a bracket
            # (dropping the lowest could drop the only point beyond the vertex)
            pts = sorted(pts + [(sv, T, f1)])
            top = int(np.argmax([p[1] for p in pts]))
            top = min(max(top, 1), len(pts) - 2)
            pts = pts[top - 1:top + 2]
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
            X, f1, its, res, _, _ = got
            o = self.m.orbit_through(X, f1, self.m.rotation(f1), its, res, time.perf_counter(), steps)
            return o.f1_Hz, o.multipliers, o

        lo, hi, f_lo, f_hi, o, probes = bisect_crossing(probe, st.ds, count_a, kind)
        f_lo = a.f1_Hz if f_lo is None else f_lo
        if o is None:
            o = b
        f_hi = o.f1_Hz
        return {"f1_Hz": 0.5 * (f_lo + f_hi), "tension_max_N": o.tension_max_N, "kind": kind,
                "f1_error_Hz": 0.5 * abs(f_hi - f_lo), "probes": probes,
                "multiplier": _crossing(o.multipliers, kind)}


def superharmonic_between(site: Site, points) -> dict | None:
    """The site's resonance between the last two ``points`` (a, b), where the
    angle of the site's tracked multiplier changes sign: k f1 passes the orbit's
    own f_n there.  Located by linear interpolation of the angle in 1/f1 (theta =
    2 pi (f_n / f1 - k) is linear in 1/f1 while f_n holds), with |mu|, T max and
    T max - T min interpolated linearly in the same weight; ``distance`` is
    |mu - 1| there, | |mu| - 1 |.  (The former vertex of the parabola through
    |mu - 1|^2 of three points moved by 1.7e-3 Hz at the N = 8 2:1 site when the
    points were twice as far apart; this zero moved by 2e-5 Hz.)"""
    if len(points) < 2:
        return None
    a, b = points[-2:]
    mus = track(site, points)[-2:]
    if any(m is None for m in mus):
        return None
    ta, tb = np.angle(mus)
    if not ((ta > 0 >= tb or ta < 0 <= tb) and abs(ta - tb) < np.pi):
        return None
    w = ta / (ta - tb)
    at = lambda va, vb: float(va + w * (vb - va))  # noqa: E731
    fv = 1.0 / at(1.0 / a.f1_Hz, 1.0 / b.f1_Hz)
    mu = complex(at(abs(mus[0]), abs(mus[1])), 0.0)  # on the positive real axis there
    return {"f1_Hz": fv, "kind": "superharmonic", "order": site.k, "f_n_Hz": site.f_n_Hz,
            "distance": abs(mu.real - 1.0),
            "tension_max_N": at(a.tension_max_N, b.tension_max_N),
            "oscillation_N": at(a.tension_max_N - a.tension_min_N,
                                b.tension_max_N - b.tension_min_N),
            "multiplier": [mu.real, mu.imag], "bracket_Hz": [a.f1_Hz, b.f1_Hz]}


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
