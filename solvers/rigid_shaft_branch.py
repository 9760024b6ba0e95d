"""The operating points' torque balance (solvers/torque_balance.py) as a problem that
the existing pseudo-arclength :class:`~rawehelix.periodic_orbits.continuation.Branch`
continues, in the wind along the rotor's axis V_n [m/s] (Branch's continuation
parameter, which it calls ``f1_Hz``):

    G(Omega, V_n) = [Q(Omega, V_n) - tau_gen(Omega) - L(Omega)] / (GJ / L0) = 0,

normalised as the rod solvers are (X = Omega t_scale, G in
GJ / L0).  G depends on the rod only through V_n, which the rod's top tangent sets
(solvers/operating_point.py): continued in V_n, the balance is exact and numpy only.
A generator that holds its speed (the paper's Eq. 40 with its integral action) has
one branch, Omega = Omega*, with nothing to continue (:func:`trace` gives it as it
is): its torque is whatever balances Q.

The problem gives Branch what it asks of a periodic-orbit problem (residual, its
Jacobians in X and V_n, a Newton at fixed V_n, the finished point) and nothing about
periods: ``resolution`` is 0, and its "samples" are X itself, which the step guard
:class:`SpinStep` reads.  Branches are sought from both ends of the window and from
SEEDS speeds inside it (:func:`trace`).  The point's "multiplier" is
exp(lambda t_scale) of the rigid torsional mode, lambda = dG/dOmega / J (J the rotor's
spin inertia): 1 at a fold, < 1 where the point is stable.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import time

import numpy as np

from rawehelix.errors import SolverError
from rawehelix.periodic_orbits.continuation import StepGuard
from rawehelix.periodic_orbits.problem import DenseLU
from rawehelix.solvers.torque_balance import Drive, OutsideTable, stable

#: the speeds V_n inside a window where branches are also sought (their roots not yet
#: traced): a branch that begins inside the window (a fold, the table's edge) is found
#: where it spans one of them
SEEDS = 24
#: the largest relative change of Omega between two points of a branch (SpinStep)
MAX_SPIN_STEP = 0.05


class SpinStep(StepGuard):
    """Branch's step guard on the spin: a corrected point whose Omega differs from the
    last point's by more than MAX_SPIN_STEP of it is refused (a shorter step), so that
    the corrector cannot land on a neighbouring branch where two are close (near a fold,
    or where the torque coefficient has humps)."""

    def admit(self, prev, orbit, samples):
        X = orbit.X if orbit is not None else samples
        if X is None:
            return None
        change = abs(float(X[0]) - float(prev.X[0])) / max(abs(float(prev.X[0])), 1e-300)
        return None if change <= MAX_SPIN_STEP else 0.5


@dataclasses.dataclass
class RigidPoint:
    """A point of the branch: the balance's root at V_n (normalised X = Omega t_scale),
    with what Branch reads (its parameter ``f1_Hz`` is V_n here)."""

    v_n: float  # [m/s]
    X: np.ndarray  # (1,): Omega t_scale
    multipliers: np.ndarray  # (1,): exp(lambda t_scale) of the rigid mode
    newton_iterations: int
    residual: float
    wall_s: float
    slope_Nm_s: float
    steps: int = 0  # Branch's resolution: no period here
    G: np.ndarray | None = None

    @property
    def f1_Hz(self) -> float:
        """Branch's name for its continuation parameter: here V_n [m/s]."""
        return self.v_n

    def release(self):
        self.G = None

    @property
    def stable(self) -> bool:
        return stable(self.slope_Nm_s)


class RigidShaftProblem:
    """G(X, V_n) of the module docstring, in the protocol Branch continues."""

    def __init__(self, drive: Drive, t_scale_s: float, torque_scale_Nm: float):
        self.drive, self.t, self.m = drive, float(t_scale_s), float(torque_scale_Nm)
        J = getattr(drive.rotor, "spin_inertia_kgm2", 0.0) or 1.0
        self.J = float(J)  # [kg m^2]: the rigid mode's inertia (1 where the rotor has none)

    def continuable(self) -> None:
        """Every root is isolated (a scalar balance with a nonzero slope off the folds)."""

    def resolution(self, f1_Hz: float) -> int:
        return 0

    def _G(self, X, v_n) -> np.ndarray:
        omega = float(X[0]) / self.t
        return np.array([self.drive.balance_Nm(omega, v_n) / self.m])

    def _dG(self, X, v_n) -> float:
        omega = float(X[0]) / self.t
        return self.drive.slope_Nm_s(omega, v_n) / (self.m * self.t)

    def residual(self, X, f1_Hz: float, jacobian: bool = False, resolution=None):
        """(G, the state X as the point's "samples" (what :class:`SpinStep` reads), dG/dX)."""
        try:
            G = self._G(X, f1_Hz)
            J = np.array([[self._dG(X, f1_Hz)]]) if jacobian else None
        except OutsideTable as err:
            raise SolverError(str(err)) from None  # the corrector retries a shorter step
        return G, np.array(X, dtype=float), J

    def residual_f1(self, X, f1_Hz: float, resolution: int, G=None) -> np.ndarray:
        h = 1e-6 * max(abs(f1_Hz), 1.0)
        try:
            return (self._G(X, f1_Hz + h) - self._G(X, f1_Hz - h)) / (2 * h)
        except OutsideTable as err:
            raise SolverError(str(err)) from None

    def jacobian(self, point: RigidPoint) -> np.ndarray:
        return np.array([[self._dG(point.X, point.v_n)]])

    def factor(self, K):
        return DenseLU(K)

    def refine(self, prev, point):
        return None

    def embed(self, X, resolution: int):
        return X

    def resume_from(self, point) -> None:
        pass

    def norm(self, G, X) -> float:
        return float(np.linalg.norm(G) / max(np.linalg.norm(X), 1.0))

    def settle(self, X, G):
        return X

    def deferred_stability(self, last):
        """Every point's multiplier is computed at its finish (a scalar): nothing deferred."""
        return contextlib.nullcontext()

    def stability(self, point, event: bool) -> None:
        """Nothing to bring up to date (:meth:`deferred_stability`)."""

    def multipliers(self, X, f1_Hz: float, resolution=None) -> np.ndarray:
        slope = self._slope(X, f1_Hz)
        return np.array([math.exp(max(-700.0, min(700.0, slope / self.J * self.t)))])

    def _slope(self, X, v_n) -> float:
        return self.drive.slope_Nm_s(float(X[0]) / self.t, v_n)

    def finish(self, X, f1_Hz: float, iterations: int, residual: float, start: float,
               resolution=None) -> RigidPoint:
        G = self._G(X, f1_Hz)
        slope = self._slope(X, f1_Hz)
        mu = self.multipliers(X, f1_Hz)
        return RigidPoint(float(f1_Hz), np.asarray(X, dtype=float).copy(), mu, iterations,
                          float(residual), time.perf_counter() - start, slope, G=G)

    def orbit(self, X0, f1_Hz: float, tol: float = 1e-7, max_it: int = 12, steps=None):
        """The root near X0 at fixed V_n = ``f1_Hz`` (Branch's natural step)."""
        start = time.perf_counter()
        try:
            omega = self.drive.root_near(float(X0[0]) / self.t, f1_Hz)
        except OutsideTable as err:
            raise SolverError(str(err)) from None
        X = np.array([omega * self.t])
        return self.finish(X, f1_Hz, 1, self.norm(self._G(X, f1_Hz), X), start)

    def predicted_orbit(self, X, f1_Hz: float, tol: float, max_it: int):
        return self.orbit(X, f1_Hz, tol=tol, max_it=max_it)

    def point_at(self, omega: float, v_n: float) -> RigidPoint:
        """The branch's first point: a root ``omega`` [rad/s] at V_n."""
        return self.orbit(np.array([omega * self.t]), v_n)

    def samples(self, X, f1_Hz: float, resolution=None):
        return None


@dataclasses.dataclass
class Segment:
    """A stretch of a traced branch between folds (or its ends): V_n monotone along it,
    the rigid mode's stability one throughout.  ``index``: the ``branch`` of summary.json."""

    index: int
    v_n: np.ndarray  # [m/s], ascending
    omega: np.ndarray  # [rad/s] at v_n
    stable: bool

    def __post_init__(self):
        self.v_n, self.omega = (np.asarray(x, dtype=float) for x in (self.v_n, self.omega))
        if self.v_n.shape != self.omega.shape or self.v_n.size < 2 or \
                np.any(np.diff(self.v_n) < 0):
            raise ValueError(f"Segment {self.index}: V_n must ascend and match Omega, with "
                             f"two points or more (got {self.v_n.size} and {self.omega.size})")

    def covers(self, v_n: float) -> bool:
        return bool(self.v_n[0] <= v_n <= self.v_n[-1])

    def root(self, drive: Drive, v_n: float) -> float:
        """The balance's root at V_n on this segment: Brent's method between the two
        traced points that bracket it (the segment is a graph Omega(V_n) between folds),
        Newton from the interpolant where they do not bracket a sign change.  OutsideTable
        where the segment does not reach V_n."""
        if not self.covers(v_n):
            raise OutsideTable(f"the branch {self.index} has no operating point at V_n = "
                               f"{v_n:.6g} m/s (it spans {self.v_n[0]:.6g} .. {self.v_n[-1]:.6g})")
        w_lo, w_hi = drive.omega_range(v_n)
        guess = float(np.clip(np.interp(v_n, self.v_n, self.omega), w_lo, w_hi))
        if drive.held_speed() is not None:
            return drive.root_near(guess, v_n)
        k = int(np.clip(np.searchsorted(self.v_n, v_n), 1, self.v_n.size - 1))
        a, b = np.clip(sorted((self.omega[k - 1], self.omega[k])), w_lo, w_hi)
        if a < b:  # the root at v_n lies between the neighbours' roots (a graph)
            ga, gb = drive.balance_Nm(a, v_n), drive.balance_Nm(b, v_n)
            if ga * gb <= 0:
                return drive.bracketed(a, b, v_n)
        return drive.root_near(guess, v_n)


@dataclasses.dataclass
class Traced:
    """The branches of the balance over a window of V_n: their segments, their folds
    (V_n [m/s]) and why a trace ended early (the table's end)."""

    segments: list
    folds: list
    notes: list
    points: int  # branch points traced

    def at(self, drive: Drive, v_n: float) -> list:
        """Every root of the balance at V_n (:meth:`Drive.roots`, each once) as (branch,
        root): ``root(v_n')`` the root near it at a nearby V_n' on the segment that
        reaches it (the first, where several do), or a new index past the segments for a
        root that no traced segment reaches (a continuation that jumped a branch)."""
        out, spare = [], len(self.segments)
        for w in drive.roots(v_n):
            seg = next((s for s in self.segments if s.covers(v_n) and _reaches(s, drive, v_n, w)),
                       None)
            if seg is None:
                out.append((spare, lambda vn, w=w: drive.root_near(w * vn / v_n, vn)))
                spare += 1
            else:
                out.append((seg.index, lambda vn, s=seg: s.root(drive, vn)))
        return out


def _reaches(seg: Segment, drive: Drive, v_n: float, omega: float) -> bool:
    """Whether the segment's root at V_n is ``omega`` [rad/s]."""
    try:
        return abs(seg.root(drive, v_n) - omega) <= 1e-8 * max(1.0, abs(omega))
    except SolverError:
        return False


def _on(segments, drive: Drive, omega: float, v_n: float) -> bool:
    """Whether the root ``omega`` at V_n lies on a segment already traced."""
    return any(seg.covers(v_n) and _reaches(seg, drive, v_n, omega) for seg in segments)


def _split(points, problem, first_index: int) -> list:
    """The points of one trace cut at each reversal of V_n (a fold) into segments."""
    v = np.array([p.v_n for p in points])
    w = np.array([p.X[0] / problem.t for p in points])
    cuts, last = [0], 0.0
    for k, d in enumerate(np.sign(np.diff(v))):
        if d != 0 and last != 0 and d != last:
            cuts.append(k)
        last = d if d != 0 else last
    cuts.append(v.size - 1)
    out = []
    for a, b in zip(cuts[:-1], cuts[1:]):
        vs, ws = v[a:b + 1], w[a:b + 1]
        order = np.argsort(vs)
        middle = points[(a + b) // 2]
        out.append(Segment(first_index + len(out), vs[order], ws[order],
                           stable(middle.slope_Nm_s)))
    return out


def _held(drive: Drive, vn_lo: float, vn_hi: float) -> Traced:
    """The one branch of a generator that holds its speed (Eq. 40's integral action):
    Omega = Omega* wherever the table has Omega* R / V_n, nothing to continue."""
    omega = drive.held_speed()
    lam_lo, lam_hi = drive.rotor.tsr_range
    lo = max(vn_lo, omega * drive.rotor.radius_m / lam_hi)
    hi = min(vn_hi, omega * drive.rotor.radius_m / lam_lo) if lam_lo > 0 else vn_hi
    if not lo < hi:
        return Traced([], [], [f"the held speed {omega:.4g} rad/s is outside the rotor's table "
                               f"at V_n = {vn_lo:.4g} to {vn_hi:.4g} m/s"], 0)
    v = np.linspace(lo, hi, 9)
    return Traced([Segment(0, v, np.full_like(v, omega),
                           stable(drive.slope_Nm_s(omega, 0.5 * (lo + hi))))], [], [], v.size)


def _one_way(problem, omega, v0, v1, direction, ds_max, max_points, notes, folds):
    """The points of Branch's trace from the root ``omega`` at V_n = v0 towards v1, through
    folds, until it leaves the window or the rotor's table ends (noted); its folds
    appended to ``folds`` once each."""
    from rawehelix.periodic_orbits.continuation import Branch
    branch = Branch(problem, ds=0.1, ds_max=ds_max, ds_min=1e-6, tol=1e-10,
                    guards=(SpinStep(),))
    try:
        branch.trace(problem.point_at(omega, v0), v1, direction=direction, max_points=max_points)
    except SolverError:  # the corrector failed with the smallest step: the table ends
        last = branch.points[-1]
        notes.append(f"the rotor's table ends at V_n = {last.v_n:.4g} m/s, "
                     f"{last.X[0] / problem.t:.4g} rad/s")
    for f in branch.folds:  # once where the branch lands on it (a table's corner)
        if not any(abs(f["f1_Hz"] - v) <= 1e-9 * v for v in folds):
            folds.append(f["f1_Hz"])
    return branch.points


def trace(problem: RigidShaftProblem, vn_lo: float, vn_hi: float, ds_max: float = 0.5,
          max_points: int = 400, seeds: int = SEEDS) -> Traced:
    """Every branch of the balance through [vn_lo, vn_hi] [m/s], traced by Branch through
    folds until it leaves the window or the rotor's table ends: from each root at vn_lo
    upwards, at vn_hi downwards, and from each root at ``seeds`` speeds between them that
    no branch has met yet both ways (a branch that starts or ends at the table's edge,
    or at a fold, inside the window)."""
    drive = problem.drive
    if drive.held_speed() is not None:
        return _held(drive, vn_lo, vn_hi)
    segments, folds, notes, count = [], [], [], 0
    starts = [(vn_lo, ((vn_hi, 1.0),)), (vn_hi, ((vn_lo, -1.0),))]
    starts += [(v, ((vn_lo, -1.0), (vn_hi, 1.0))) for v in np.linspace(vn_lo, vn_hi, seeds)[1:-1]]
    for v0, ways in starts:
        for omega in drive.roots(v0):
            if _on(segments, drive, omega, v0):
                continue
            parts = [_one_way(problem, omega, v0, v1, d, ds_max, max_points, notes, folds)
                     for v1, d in ways]
            points = parts[0][::-1] + parts[1][1:] if len(parts) == 2 else parts[0]
            count += len(points)
            if len(points) >= 2:
                segments += _split(points, problem, len(segments))
    return Traced(segments, folds, notes, count)
