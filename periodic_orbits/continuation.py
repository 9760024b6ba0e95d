"""Pseudo-arclength continuation of periodic orbits in f1, through folds.

Branch asks its problem only for the protocol below (G, its Jacobians, a Newton at
fixed parameter, a finished point with ``X``, ``f1_Hz``, ``multipliers``), so any
problem with that protocol is continued the same way: the operating points of issue 43
(solvers/rigid_shaft_branch.py) continue a torque balance in the wind V_n, which they
hand to Branch as its parameter ``f1_Hz``.

The orbits are those of a periodic-orbit problem
(:class:`~rawehelix.periodic_orbits.problem.PeriodicOrbitProblem`: shooting with
the FE or the spline scheme), which gives the residual G(X, f1), its Jacobians
G_X and G_f1, its own Newton at fixed f1 and the finished orbit with its Floquet
multipliers; nothing here knows the rod.  The caller's step guards
(:class:`StepGuard`; studies/orbits.py gives its observable's relative step
and the resonance sites of periodic_orbits/resonances.py) refuse points, cap steps and
report their events in ``peaks``; folds and bifurcations are located by
periodic_orbits/bifurcations.py and report the caller's observable.

Unknowns Y = (X, f1) (a problem with a family of orbits at each f1 is
refused by the problem itself, :meth:`PeriodicOrbitProblem.continuable`).  From an orbit Y_k with unit tangent tau_k (||tau||
in the problem's unknowns and f1 [Hz]), the predictor Y_k + ds tau_k is
corrected by Newton on

    G(X, f1) = 0,     tau_k . (Y - Y_pred) = 0,

with the chord [[G_X, G_f1], [tau_k^T]] at Y_k (shooting: G_X = M_k - I with M_k
the monodromy, G_f1 central differences of G over f1 with the steps per period
held: one resolution for the whole corrector, so that G is smooth in f1).  The
next tangent solves [[G_X, G_f1], [tau_k^T]] tau = (0, 1).

A corrector that had to refresh the Jacobian starts the next one with the
Jacobian at its predictor (``State.fresh``): below a resonance the
multipliers rotate between points, so the last point's monodromy is a stale
chord.  After two slow correctors in a row (>= SLOW iterations) or a failed
one, and while every multiplier of the last point is FOLD_MARGIN away from +1
(no fold near, so f1 parametrises the branch), the next point is found by
*natural* steps (``State.natural``): the problem's own Newton at the
predictor's f1 (:meth:`PeriodicOrbitProblem.orbit`, with its own resolution
there), f1 moving by at most NATURAL_STEP of itself.  Near a fold the
arclength corrector takes over again.

The step adapts: x1.5 after a corrector of <= 5 iterations, /1.5 after >= 7,
/2 after a failure; then each guard caps it (:meth:`StepGuard.cap`).
"""

from __future__ import annotations

import dataclasses
import logging
import time

import numpy as np
import scipy.sparse

from rawehelix.errors import SolverError
from rawehelix.periodic_orbits import bifurcations
from rawehelix.periodic_orbits.bifurcations import far_from_folds
from rawehelix.periodic_orbits.floquet import SLOW_RATE, Broyden
from rawehelix.periodic_orbits.problem import Observable, Orbit, PeriodicOrbitProblem

log = logging.getLogger(__name__)

NATURAL_STEP = 0.5  # a natural step moves f1 by at most this fraction of itself
STOP_TOL = 1e-9  # relative: a point this near the window's end ends the trace
SLOW = 6  # two correctors in a row of this many iterations turn to natural steps
#: a corrector whose step is this small (relative to Y) with |G| within FLOOR_FACTOR of
#: the tolerance is converged: |G| is at its round-off floor (harmonic balance at N = 32:
#: the axial rows' scale grows like N^2, and so does |G|'s floor)
FLOOR_STEP, FLOOR_FACTOR = 1e-12, 1e3


class StepGuard:
    """A caller's rule on the branch's steps and the events it watches for; this
    base guards nothing (a null guard)."""

    def admit(self, prev: Orbit, orbit: Orbit | None, samples) -> float | None:
        """None to take the corrected point after ``prev`` (``orbit``: the finished
        orbit of a natural step, else None and the problem's ``samples`` over the
        corrected point's period), or the factor (< 1) to retry with a shorter step."""
        return None

    def cap(self, points, f1_s: float, ds: float, last_ds: float | None) -> float:
        """The next step from the last of ``points`` (``f1_s``: df1/ds there;
        ``last_ds``: the step that reached it, None at the branch's start)."""
        return ds

    def events(self, branch: "Branch", a: Orbit, b: Orbit, st: "State", steps) -> list[dict]:
        """Events between a (the branch's last point) and b (the new one), called
        once the branch has two points."""
        return []


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
        A = {"A": self.A}
        if scipy.sparse.issparse(self.A):  # harmonic balance's: CSR in four arrays
            S = self.A.tocsr()
            A = {"A": S.data, "A_indices": S.indices, "A_indptr": S.indptr,
                 "A_shape": np.array(S.shape)}
        return {"tau": self.tau, **A, "gf": self.gf, "w": self.w, "ds": np.array(self.ds),
                "fresh": np.array(self.fresh), "natural": np.array(self.natural)}

    @classmethod
    def from_arrays(cls, data) -> "State":
        flag = lambda key: bool(data[key]) if key in data else False  # noqa: E731 (older stores)
        A = data["A"]
        if "A_indptr" in data:
            A = scipy.sparse.csr_matrix((A, data["A_indices"], data["A_indptr"]),
                                        shape=tuple(int(x) for x in data["A_shape"]))
        return cls(tau=data["tau"], A=A, gf=data["gf"], w=data["w"], ds=float(data["ds"]),
                   fresh=flag("fresh"), natural=flag("natural"))


class Branch:
    """A branch of orbits of ``problem`` traced by pseudo-arclength continuation:
    ``observable`` the caller's scalar reported at folds and bifurcations,
    ``guards`` the caller's step guards (:class:`StepGuard`), in order."""

    def __init__(self, problem: PeriodicOrbitProblem, ds: float = 0.1, ds_min: float = 1e-4,
                 ds_max: float = 2.0, tol: float = 1e-7, max_it: int = 8,
                 observable: Observable | None = None, guards=()):
        problem.continuable()
        self.problem = problem
        self.ds, self.ds_min, self.ds_max, self.tol, self.max_it = ds, ds_min, ds_max, tol, max_it
        self.observable, self.guards = observable, tuple(guards)
        self.points: list[Orbit] = []
        self.stopped: str | None = None  # why the trace ended before its window's end
        self.folds: list[dict] = []
        self.bifurcations: list[dict] = []
        self.peaks: list[dict] = []
        self.state: State | None = None

    def _bordered(self, A, gf, tau):
        """[[G_X, G_f1], [(w^2 tau)^T]]: the corrector's and the tangent's matrix
        (sparse where the problem's G_X is)."""
        if scipy.sparse.issparse(A):
            row = (self.w**2 * tau)[None, :]
            return scipy.sparse.bmat([[A, gf[:, None]], [row[:, :-1], row[:, -1:]]], format="csr")
        return np.block([[A, gf[:, None]], [(self.w**2 * tau)[None, :]]])

    def _tangent(self, orbit: Orbit, tau_prev, steps):
        A = self.problem.jacobian(orbit)
        G = orbit.G if orbit.steps == steps else None
        gf = self.problem.residual_f1(orbit.X, orbit.f1_Hz, steps, G)
        K = self._bordered(A, gf, tau_prev)
        rhs = np.zeros(K.shape[0])
        rhs[-1] = 1.0
        tau = self.problem.factor(K).solve(rhs)
        return tau / np.linalg.norm(self.w * tau), A, gf

    def _cap(self, points, f1_s, ds, last_ds) -> float:
        """The step ``ds`` capped by each guard in turn, not below ds_min."""
        for guard in self.guards:
            ds = max(self.ds_min, guard.cap(points, f1_s, ds, last_ds))
        return ds

    def correct(self, prev: Orbit, tau, A, gf, ds, steps, fresh: bool = False):
        """The corrector from ``prev`` along ``tau`` by ``ds``: (X, f1, iterations,
        |G|/|X|, the problem's samples over the period, whether it refreshed the
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
                G, samples, J = self.problem.residual(X, f1, jacobian=slow, resolution=steps)
            except SolverError as err:  # the period's steps failed from this iterate
                log.debug("corrector %d: the period map failed at f1 = %.6f Hz: %s", its, f1, err)
                return None
            if slow:  # Newton: the Jacobians in X and f1 here
                A, gf = J, self.problem.residual_f1(X, f1, steps, G)
                K, H, refreshed = self._bordered(A, gf, tau), None, True
            last, res = res, self.problem.norm(G, X)
            log.debug("corrector %d: f1 = %.6f Hz, |G|/|X| = %.3g, ds %.3g%s", its, f1, res,
                      ds, " (fresh monodromy)" if slow else "")
            if res <= self.tol:
                return self.problem.settle(X, G), f1, its, res, samples, refreshed
            r = np.concatenate([G, [(self.w**2 * tau) @ (Y - Y0) - ds]])
            if H is None:
                H = Broyden(K, self.problem.factor)
            elif previous is not None:  # the secant of the last step
                H.update(Y - previous[0], r - previous[1])
            previous = (Y, r)
            step = H.solve(r)
            Y = Y - step
            if np.linalg.norm(step) <= FLOOR_STEP * max(1.0, np.linalg.norm(Y)) \
                    and res <= FLOOR_FACTOR * self.tol:  # G at its round-off floor
                X, f1 = Y[:n], float(Y[-1])
                G, samples, _ = self.problem.residual(X, f1, resolution=steps)
                return self.problem.settle(X, G), f1, its, self.problem.norm(G, X), samples, \
                    refreshed
        return None

    def _natural(self, prev: Orbit, st: State, f1_stop: float) -> Orbit | None:
        """The next point by shooting at the predictor's f1 (natural parameter), from
        the predictor's state, by the problem's own Newton (:meth:`PeriodicOrbitProblem.orbit`,
        shooting: the monodromy at each start) and its own resolution at that f1; None if it fails.  The step moves f1 by at most NATURAL_STEP of itself,
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
            return self.problem.predicted_orbit(Y[:-1], f1, tol=self.tol, max_it=2 * self.max_it)
        except SolverError as err:
            log.debug("natural step to %.6f Hz failed: %s", f1, err)
            return None

    def valid(self, orbit: Orbit) -> bool:
        """A point is an orbit only if its residual is within the tolerance (or within
        FLOOR_FACTOR of it, |G|'s round-off floor: the corrector's own test)."""
        return bool(orbit.residual <= FLOOR_FACTOR * self.tol)

    def invalid(self, orbit: Orbit, first: bool = False) -> str:
        """Why ``orbit`` is not a point of the branch (the run's stop reason)."""
        ends = "the branch has no point" if first else "the branch ends at the point before it"
        return (f"at f1 = {orbit.f1_Hz:.5g} Hz the residual |G|/|X| = {orbit.residual:.3g} is "
                f"above its tolerance {FLOOR_FACTOR * self.tol:g}: not an orbit, so {ends}; "
                f"check the scene (its forces' scales), or try the other --method")

    def start(self, first: Orbit, direction: float = 1.0):
        """The first point and its tangent in ``direction`` of f1 (SolverError if the
        first point is not an orbit: :meth:`valid`)."""
        if not self.valid(first):
            raise SolverError(f"continuation: {self.invalid(first, first=True)}")
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
        ds = self._cap(self.points, tau[-1], self.ds, None)
        self.state = State(tau=tau, A=A, gf=gf, w=self.w.copy(), ds=ds)

    def _restart(self, prev: Orbit, st: State):
        """The branch's last point replaced by ``prev`` at a finer resolution (a larger
        X): its tangent from the old one padded, the metric's state weight kept."""
        n = prev.X.size
        tau = np.append(self.problem.embed(st.tau[:-1], prev.steps), st.tau[-1])
        self.w = np.append(np.full(n, self.w[0]), self.w[-1])
        tau, A, gf = self._tangent(prev, tau, prev.steps)
        self.points[-1] = prev
        self.state = State(tau=tau, A=A, gf=gf, w=self.w.copy(), ds=st.ds, fresh=True)

    def resume(self, points: list[Orbit], state: State, folds=(), bifurcations=(), peaks=()):
        """Continue from stored points and the state after the last of them."""
        self.points, self.state, self.w = list(points), state, state.w.copy()
        self.problem.resume_from(self.points[-1])
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
        last = self.points[-1]
        def done(f1):  # out of the window, or at its end (where a natural step lands)
            return not (lo <= f1 <= hi) or abs(f1 - f1_stop) <= STOP_TOL * f1_stop

        if len(self.points) > 1 and done(last.f1_Hz):
            return self.points  # a resumed branch that had already left the window
        with self.problem.deferred_stability(last):
            self._steps(f1_stop, max_points, done, progress, on_point)
        return self.points

    def _steps(self, f1_stop, max_points, done, progress, on_point):
        """:meth:`trace`'s steps, until ``done(f1)`` or ``max_points``."""
        while len(self.points) < max_points:
            prev, st = self.points[-1], self.state
            start = time.perf_counter()
            steps = self.problem.resolution(prev.f1_Hz)
            natural = st.natural and far_from_folds(prev.multipliers)
            if natural:  # the corrector was slow and no fold is near: shooting at the next f1
                orbit = self._natural(prev, st, f1_stop)
                got = None if orbit is None else (orbit.X, orbit.f1_Hz, orbit.newton_iterations,
                                                  orbit.residual, None, True)
            else:
                got = self.correct(prev, st.tau, st.A, st.gf, st.ds, steps, fresh=st.fresh)
            if got is None:
                st.ds /= 2
                st.natural = True  # a failed corrector: try the next step at fixed f1
                if st.ds < self.ds_min:
                    raise SolverError(f"continuation: the corrector failed at f1 = "
                                      f"{prev.f1_Hz:.4f} Hz with the smallest step "
                                      f"{self.ds_min}; try the other --method")
                continue
            X, f1, its, res, samples, refreshed = got
            # the guards' verdicts (all of them: each keeps what it measured)
            scale = [x for x in (g.admit(prev, orbit if natural else None, samples)
                                 for g in self.guards) if x is not None]
            if scale and st.ds > self.ds_min:
                # a guard refuses the point: a shorter step (before the Floquet period of a corrector)
                st.ds = max(self.ds_min, st.ds * min(scale))
                continue
            if not natural:
                orbit = self.problem.finish(X, f1, its, res, start, steps)
            again = self.problem.refine(prev, orbit)
            if again is not None:  # a finer resolution from here on: redo the step from prev
                self._restart(again, st)
                continue
            # the new point's tangent with the steps it was found with (a natural step:
            # its own at its f1); the events between the two with the last point's
            tau_new, A, gf = self._tangent(orbit, st.tau, orbit.steps)
            # the multipliers, where the problem defers them: a fold is df1/ds through zero
            self.problem.stability(orbit, event=bool(np.sign(st.tau[-1]) != np.sign(tau_new[-1]))
                                   or done(f1))
            events = self._detect(prev, orbit, st, tau_new, steps)
            ds = st.ds
            if its <= 5 or natural:  # an easy corrector (a chord step and a refresh or two),
                # or a natural step (its iterations on the linear monodromy are cheap periods;
                # the step is capped by NATURAL_STEP and halved where it fails)
                ds = min(self.ds_max, ds * 1.5)
            elif its >= 7:
                ds = max(self.ds_min, ds / 1.5)
            ds = self._cap(self.points + [orbit], tau_new[-1], ds, st.ds)
            if not self.valid(orbit):  # not a point: the branch ends before it, and says why
                self.stopped = self.invalid(orbit)
                break
            self.state = State(tau=tau_new, A=A, gf=gf, w=self.w.copy(), ds=ds, fresh=refreshed,
                               natural=natural or min(its, prev.newton_iterations) >= SLOW)
            self.points.append(orbit)
            prev.release()  # only the newest point's tangent is taken again
            if on_point:
                on_point(orbit, events, self.state)
            if progress:
                progress(orbit)
            if done(f1):
                break

    # -- events -------------------------------------------------------------------------
    def _detect(self, a: Orbit, b: Orbit, st: State, tau_b, steps) -> list[dict]:
        """Folds and bifurcations between two consecutive points (appended to
        ``folds`` / ``bifurcations`` and returned), then the guards' events
        (appended to ``peaks``)."""
        events = []
        ta, tb = st.tau[-1], tau_b[-1]
        if np.sign(ta) != np.sign(tb):  # df1/ds through zero: a fold
            events.append(bifurcations.fold_between(a, b, ta, tb, st.ds, self.observable))
            self.folds.append(events[-1])
        for kind, count_a in bifurcations.unstable_changes(a, b):
            events.append(bifurcations.locate(self, a, b, st, kind, count_a, steps,
                                              self.observable))
            self.bifurcations.append(events[-1])
        if len(self.points) >= 2:
            for guard in self.guards:
                found = guard.events(self, a, b, st, steps)
                events += found
                self.peaks += found
        return events
