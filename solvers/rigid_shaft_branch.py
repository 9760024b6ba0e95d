"""The operating points' torque balance as a problem that the existing pseudo-arclength
:class:`~rawehelix.periodic_orbits.continuation.Branch` continues, in the wind along the
rotor's axis V_n [m/s] (Branch's continuation parameter, which it calls ``f1_Hz``).

At a relative equilibrium without the helix's own distributed loss the twist moment is
constant along s (Eq. 31 with alpha_t uniform and no distributed torque), so the spin
Omega closes the rigid-shaft balance

    G(Omega, V_n) = [Q(Omega, V_n) - tau_gen(Omega) - L(Omega)] / (GJ / L0) = 0,

Q the rotor's aerodynamic torque, tau_gen the generator's, L the helix's integrated
spin-drag loss (0 when off), normalised as the rod solvers are (X = Omega t_scale, G in
GJ / L0).  G depends on the rod only through V_n, which the rod's top tangent sets
(solvers/operating_point.py): continued in V_n, the balance is exact and numpy only.
A generator that holds its speed (the paper's Eq. 40 with its integral action) has
one branch, Omega = Omega*, with nothing to continue (:func:`trace` gives it as it
is): its torque is whatever balances Q.

The problem gives Branch what it asks of a periodic-orbit problem (residual, its
Jacobians in X and V_n, a Newton at fixed V_n, the finished point) and nothing about
periods: ``resolution`` is 0, there are no samples.  The point's "multiplier" is
exp(lambda t_scale) of the rigid torsional mode, lambda = dG/dOmega / J (J the rotor's
spin inertia): 1 at a fold, < 1 where the point is stable.
"""

from __future__ import annotations

import dataclasses
import math
import time

import numpy as np
import scipy.optimize

from rawehelix.errors import SolverError
from rawehelix.operation import rigid_shaft
from rawehelix.operation.rotor import OutOfTable
from rawehelix.periodic_orbits.problem import DenseLU

#: the scalar Newton at fixed V_n stops at |G| below this (normalised torque)
TOL = 1e-12


class OutsideTable(SolverError):
    """The balance asked the rotor's table for a tip-speed ratio it does not have."""


@dataclasses.dataclass(frozen=True)
class Drive:
    """What turns the helix: the rotor's and the generator's laws (operation/rotor.py,
    operation/generator.py), the air density [kg/m^3] and the helix's spin-drag loss (an
    object with ``torque(Omega)`` and ``dtorque_domega(Omega)`` [N m], None: off)."""

    rotor: object  # operation.rotor.RotorLaw
    generator: object  # operation.generator.GeneratorLaw
    rho_kg_m3: float
    loss: object = None

    def __post_init__(self):
        if not self.rho_kg_m3 > 0:
            raise ValueError(f"Drive: air density {self.rho_kg_m3!r} must be > 0 kg/m^3")

    def held_speed(self) -> float | None:
        """The spin [rad/s] the generator holds (Eq. 40's integral action), or None."""
        return self.generator.holds_speed

    def loss_Nm(self, omega: float) -> float:
        return 0.0 if self.loss is None else float(self.loss.torque(omega))

    def rotor_torque(self, omega: float, v_n: float) -> float:
        """Q = 1/2 rho pi R^2 V_n^3 Cp(lambda) / Omega [N m] (the rotor's law); a ratio
        outside its table raises :class:`OutsideTable`."""
        try:
            return float(self.rotor.torque(omega, v_n, self.rho_kg_m3))
        except OutOfTable as err:
            raise OutsideTable(str(err)) from None

    def balance_Nm(self, omega: float, v_n: float) -> float:
        """Q - tau_gen - L [N m] at Omega [rad/s], V_n [m/s] (rigid shaft)."""
        return self.rotor_torque(omega, v_n) - self.generator.torque(omega) - self.loss_Nm(omega)

    def slope_Nm_s(self, omega: float, v_n: float) -> float:
        """d(Q - tau_gen - L)/dOmega [N m s]: the rigid torsional mode's stiffness, < 0
        where it is stable; the paper's law holding the speed contributes its speed gain
        K2 (operation/rigid_shaft.py)."""
        try:
            dQ = float(self.rotor.dtorque_domega(omega, v_n, self.rho_kg_m3))
        except OutOfTable as err:
            raise OutsideTable(str(err)) from None
        dL = 0.0 if self.loss is None else float(self.loss.dtorque_domega(omega))
        if self.held_speed() is not None:
            return dQ - dL - self.generator.K2
        return dQ - float(self.generator.dtorque_domega(omega)) - dL

    def roots(self, v_n: float) -> list[float]:
        """Every spin [rad/s] in the table's range where the balance holds at V_n,
        ascending (operation/rigid_shaft.py); none where the held speed is outside it."""
        try:
            return [p.omega_rad_s for p in rigid_shaft.operating_points(
                self.rotor, self.generator, v_n, self.rho_kg_m3, self.loss)]
        except OutOfTable:
            return []

    def root_near(self, omega: float, v_n: float) -> float:
        """The root of the balance at V_n nearest ``omega`` by Newton (the held speed for
        a generator that holds one); SolverError if it does not converge."""
        held = self.held_speed()
        if held is not None:
            self.rotor_torque(held, v_n)  # OutsideTable where the table has no such ratio
            return held
        x = omega
        for _ in range(50):
            g = self.balance_Nm(x, v_n)
            if abs(g) <= TOL * max(1.0, abs(self.rotor_torque(x, v_n))):
                return x
            step = g / self.slope_Nm_s(x, v_n)
            x = x - step
            if abs(step) <= 1e-15 * abs(x):
                return x
        raise SolverError(f"the torque balance at V_n = {v_n:.6g} m/s did not converge from "
                          f"{omega:.6g} rad/s")


def stable(slope_Nm_s: float, eigenvalues=None) -> bool:
    """Whether an operating point is stable: every eigenvalue of the linearisation
    about it in the left half plane where they are given (the full linearisation), else
    the rigid torsional mode's d(Q - tau_gen - L)/dOmega < 0."""
    if eigenvalues is not None and len(eigenvalues):
        return bool(np.all(np.real(eigenvalues) < 0))
    return bool(slope_Nm_s < 0)


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
        try:
            G = self._G(X, f1_Hz)
            J = np.array([[self._dG(X, f1_Hz)]]) if jacobian else None
        except OutsideTable as err:
            raise SolverError(str(err)) from None  # the corrector retries a shorter step
        return G, None, J

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
        lam_lo, lam_hi = drive.rotor.tsr_range  # the spins the table has at v_n
        w_lo, w_hi = (x * v_n / drive.rotor.radius_m for x in (lam_lo, lam_hi))
        guess = float(np.clip(np.interp(v_n, self.v_n, self.omega), w_lo, w_hi))
        if drive.held_speed() is not None:
            return drive.root_near(guess, v_n)
        k = int(np.clip(np.searchsorted(self.v_n, v_n), 1, self.v_n.size - 1))
        a, b = np.clip(sorted((self.omega[k - 1], self.omega[k])), w_lo, w_hi)
        if a < b:  # the root at v_n lies between the neighbours' roots (a graph)
            ga, gb = drive.balance_Nm(a, v_n), drive.balance_Nm(b, v_n)
            if ga * gb <= 0:
                return float(scipy.optimize.brentq(drive.balance_Nm, a, b, args=(v_n,),
                                                   xtol=1e-14, rtol=4 * np.finfo(float).eps))
        return drive.root_near(guess, v_n)
        k = int(np.clip(np.searchsorted(self.v_n, v_n), 1, self.v_n.size - 1))
        a, b = sorted((self.omega[k - 1], self.omega[k]))
        if a < b:  # widen by the step: the root at v_n lies between the neighbours' roots
            ga, gb = drive.balance_Nm(a, v_n), drive.balance_Nm(b, v_n)
            if ga * gb < 0:
                return float(scipy.optimize.brentq(drive.balance_Nm, a, b, args=(v_n,),
                                                   xtol=1e-14, rtol=4 * np.finfo(float).eps))
        return drive.root_near(guess, v_n)


@dataclasses.dataclass
class Traced:
    """The branches of the balance over a window of V_n: their segments, their folds
    (V_n [m/s]) and why a trace ended early (the table's end)."""

    segments: list
    folds: list
    notes: list
    points: int  # branch points traced


def _on(segments, drive: Drive, omega: float, v_n: float) -> bool:
    """Whether the root ``omega`` at V_n lies on a segment already traced."""
    for seg in segments:
        if seg.covers(v_n):
            try:
                if abs(seg.root(drive, v_n) - omega) <= 1e-8 * max(1.0, abs(omega)):
                    return True
            except SolverError:
                pass
    return False


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


def trace(problem: RigidShaftProblem, vn_lo: float, vn_hi: float, ds_max: float = 0.5,
          max_points: int = 400) -> Traced:
    """Every branch of the balance through [vn_lo, vn_hi] [m/s]: traced by Branch from
    each root at vn_lo upwards and from each root at vn_hi not yet met downwards, through
    folds, until it leaves the window or the rotor's table ends."""
    from rawehelix.periodic_orbits.continuation import Branch

    drive = problem.drive
    if drive.held_speed() is not None:
        return _held(drive, vn_lo, vn_hi)
    segments, folds, notes, count = [], [], [], 0
    for v0, v1, direction in ((vn_lo, vn_hi, 1.0), (vn_hi, vn_lo, -1.0)):
        for omega in drive.roots(v0):
            if _on(segments, drive, omega, v0):
                continue
            branch = Branch(problem, ds=0.1, ds_max=ds_max, ds_min=1e-6, tol=1e-10)
            try:
                branch.trace(problem.point_at(omega, v0), v1, direction=direction,
                             max_points=max_points)
            except SolverError:  # the corrector failed with the smallest step: the table ends
                last = branch.points[-1]
                notes.append(f"the rotor's table ends at V_n = {last.v_n:.4g} m/s, "
                             f"{last.X[0] / problem.t:.4g} rad/s")
            count += len(branch.points)
            for f in branch.folds:  # once where the branch lands on it (a table's corner)
                if not any(abs(f["f1_Hz"] - v) <= 1e-9 * v for v in folds):
                    folds.append(f["f1_Hz"])
            if len(branch.points) >= 2:
                segments += _split(branch.points, problem, len(segments))
    return Traced(segments, folds, notes, count)
