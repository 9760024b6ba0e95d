"""Periodic orbits by shooting, scheme-independent: the shooting Newton, the
twist's rotation per period and the Floquet multipliers of an orbit.  Shooting
is one :class:`~rawehelix.periodic_orbits.problem.PeriodicOrbitProblem`
(:class:`PeriodMap`), which the continuation traces.

A scheme supplies the period map (:meth:`PeriodMap.period`: the state after
one forcing period, the tension at s = 0 over it and, on request, the
monodromy dP/dX), ``e_alpha`` (a uniform unit twist in its state),
``controller``, ``q_base`` (the scene's normalised parameters, the torque at
its final value), ``q`` (at the current f1) and ``steps_per_period``:

- the FE generalised-alpha map, :class:`rawehelix.solvers.orbits.AlphaMap`;
- the paper's spline-Galerkin flow,
  :class:`rawehelix.references.spline_galerkin.orbits.SplineMap`.

Here, with Delta the rotation per period:

    G(X) = P(X) - X - Delta e_alpha = 0                          (shooting)

Carried entries (``carried``, empty by default).  A scheme may name entries
of its state that the Newton does not solve for but carries along: the
hysteretic torsion's internal twist z and the generalised-alpha scheme's
rate and acceleration of it (V_z, A_z) in
:class:`rawehelix.solvers.orbits.AlphaMap`.  At an orbit z hardly moves (the
twist's travel per period is tiny), so its multipliers are 1 - O(beta
travel): M - I is nearly singular in z, and z's Newton correction, G_z / (1
- mu), overshoots the kinks of the law (|dtau|, |z|); V_z and A_z ring
after every reversal of the twist rate, so that P's values of them are not
smooth in X either.  The Newton matrix has the carried entries' rows of the
monodromy set to zero (:meth:`PeriodMap.newton_matrix`): its step sets them
to P's (substitution, X_c <- P_c(X)) and solves the other entries with the
change of X_c included (their columns are kept); the residual measured
(:meth:`PeriodMap.shooting_norm`) is that of the other entries; the orbit's
carried entries are P's at the converged X.  :meth:`PeriodMap.orbit_through`
measures what remains (``Orbit.defects``, :meth:`PeriodMap.defects`) and
refuses the orbit where a defect exceeds its entry of ``defect_tolerances``.
Multipliers that belong to the carried variables (:meth:`PeriodMap.set_aside`)
are reported apart (``Orbit.internal_multipliers``), not in the stability.

No FE code (numpy only), so that the spline reference stays free of it.
"""

from __future__ import annotations

import time

import numpy as np

from rawehelix.errors import SolverError
from rawehelix.periodic_orbits.problem import (FREE_ROTATION, DenseLU, Orbit,  # noqa: F401
                                               PeriodicOrbitProblem)

BACKTRACK_MIN = 1.0 / 32  # the shortest fraction of a Newton step the shooting tries
#: a Newton iteration on a held monodromy (a chord) that leaves more than this fraction of
#: the residual asks for a fresh monodromy at the next iterate
SLOW_RATE = 0.1
#: the same for the linear monodromy (PeriodMap.linear_monodromy), which costs about one
#: period of the map to build, a tenth of a fresh monodromy (N = 8, 4.34 Hz; 1/50 at 0.6 Hz)
LINEAR_RATE = 0.5
#: the periods stepped from the stationary state before a branch's first shooting: the
#: scheme's start-up transient decays (:meth:`PeriodMap.first_orbit`)
LEAD_IN_PERIODS = 5


#: what to try where shooting finds no orbit (its refusals' way out, on the command line)
WAY_OUT = ("try --method hb (harmonic balance, where the scene's laws allow it), or start "
           "the --f1 window where the response is small, away from a resonance")


class Broyden:
    """The inverse of a Newton matrix B0 (LU) with Broyden's rank-one updates
    (the "good" method, Broyden 1965): after a step s that changed the
    residual by y, B_{k+1} s = y, B_{k+1} - B_k of rank one in the direction s,
    and by Sherman-Morrison

        H_{k+1} = H_k + (s - H_k y) (s^T H_k) / (s^T H_k y),   H = B^-1,

    kept as H_0 plus the sum of the rank-one terms.  A held monodromy (the
    last point's, or one from an earlier iterate) is a chord; its updates learn
    the directions the steps take, where a period of the map costs a tenth of
    a fresh monodromy (a tangent period of 3n columns)."""

    def __init__(self, B, factor=DenseLU):
        self.lu = factor(B)  # solve(r, transpose): problem.factor
        self.terms: list[tuple[np.ndarray, np.ndarray]] = []  # (u, v): H += u v^T

    def solve(self, r: np.ndarray, transpose: bool = False) -> np.ndarray:
        """H r (or H^T r)."""
        x = self.lu.solve(r, transpose)
        for u, v in self.terms:
            x += v * (u @ r) if transpose else u * (v @ r)
        return x

    def update(self, s: np.ndarray, y: np.ndarray):
        """The secant condition B s = y for the step s that changed the residual by y."""
        Hy, sH = self.solve(y), self.solve(s, transpose=True)
        d = s @ Hy
        if abs(d) > 1e-12 * np.linalg.norm(s) * np.linalg.norm(Hy):
            self.terms.append((s - Hy, sH / d))


class PeriodMap(PeriodicOrbitProblem):
    """Shooting on a scheme's period map (see the module's docstring): the
    :class:`~rawehelix.periodic_orbits.problem.PeriodicOrbitProblem` whose unknowns
    are the state at the start of the period and whose resolution is the steps
    per period.  ``carried``: entries of X the Newton does not solve for (module
    docstring, "Carried entries")."""

    # -- the periodic-orbit problem (periodic_orbits/problem.py) ---------------------------
    def continuable(self):
        if not self.controller:
            raise SolverError(f"orbits: {FREE_ROTATION}")

    def resolution(self, f1_Hz: float) -> int:
        return self.steps_per_period(f1_Hz)

    def residual(self, X, f1_Hz: float, jacobian: bool = False, resolution: int | None = None):
        """G = P(X) - X - Delta e_alpha with Delta fixed by the controller, the
        tension over the period and, with ``jacobian``, the Newton matrix."""
        G, tension, Phi = self.shooting_residual(X, f1_Hz, self.rotation(f1_Hz), tangent=jacobian,
                                                 steps=resolution)
        return G, tension, (self.newton_matrix(Phi) if jacobian else None)

    def residual_f1(self, X, f1_Hz: float, resolution: int, G=None, eps=1e-5) -> np.ndarray:
        """dG/df1 at fixed steps per period: forward differences from ``G`` (G at
        (X, f1), one more period), or central ones without it."""
        G_at = lambda f1: self.residual(X, f1, resolution=resolution)[0]  # noqa: E731
        if G is None:
            gf = (G_at(f1_Hz + eps) - G_at(f1_Hz - eps)) / (2 * eps)
        else:
            gf = (G_at(f1_Hz + eps) - G) / eps
        gf[self.carried] = 0.0  # carried entries: not on the tangent
        return gf

    def jacobian(self, orbit: Orbit) -> np.ndarray:
        """The Newton matrix at ``orbit``: of its monodromy, or of a tangent period
        again where the branch has released it (``Orbit.release``)."""
        if orbit.monodromy is None:
            orbit.monodromy = self.period(orbit.X, orbit.f1_Hz, tangent=True,
                                          steps=orbit.steps)[2]
        return self.newton_matrix(orbit.monodromy)

    def norm(self, G, X) -> float:
        return self.shooting_norm(G, X)

    def finish(self, X, f1_Hz, iterations, residual, start, resolution=None) -> Orbit:
        """The orbit through X with Delta fixed by the controller (:meth:`orbit_through`)."""
        return self.orbit_through(X, f1_Hz, self.rotation(f1_Hz), iterations, residual, start,
                                  resolution)

    def multipliers(self, X, f1_Hz: float, resolution: int | None = None) -> np.ndarray:
        """The multipliers of a tangent period from X (Delta: the controller's)."""
        _, _, Phi = self.period(X, f1_Hz, tangent=True, steps=resolution)
        return self.floquet(Phi)[0]

    def samples(self, X, f1_Hz: float, resolution: int | None = None) -> np.ndarray:
        return self.period(X, f1_Hz, steps=resolution)[1]

    # -- shooting -----------------------------------------------------------------

    def newton_matrix(self, Phi):
        """M - I, the carried entries' rows of the monodromy M set to zero."""
        if self.carried.size:
            Phi = Phi.copy()
            Phi[self.carried, :] = 0.0
        return Phi - np.eye(Phi.shape[0])

    def shooting_norm(self, G, X) -> float:
        """|G| / max(1, |X|) over the entries the Newton solves for."""
        if self.carried.size:
            keep = np.ones(X.size, dtype=bool)
            keep[self.carried] = False
            G, X = G[keep], X[keep]
        return np.linalg.norm(G) / max(1.0, np.linalg.norm(X))

    def settle(self, X, G):
        """X with its carried entries replaced by P's, X_c + G_c (G at X)."""
        if not self.carried.size:
            return X
        X = X.copy()
        X[self.carried] += G[self.carried]
        return X

    #: the largest defect allowed at an orbit, by name (:meth:`defects`)
    defect_tolerances: dict = {}

    def defects(self, G, X, Phi) -> dict:
        """The periodicity defects at X (G = P(X) - X - Delta e_alpha, Phi = dP/dX):
        here, with carried entries, "carried": the shooting's residual
        (:meth:`shooting_norm`) at the orbit, whose carried entries are P's of the
        last Newton period: what substituting them left in the solved entries."""
        if not self.carried.size:
            return {}
        return {"carried": float(self.shooting_norm(G, X))}

    def defect_meaning(self, name: str) -> str:
        """What a defect of :meth:`defects` measures (the refusal's message)."""
        return {"carried": "with the carried entries set to P's, the solved entries are no "
                           "longer periodic within the tolerance"}.get(name, name)

    def set_aside(self, mu, vectors):
        """A boolean mask of the multipliers (eigenvectors: columns of ``vectors``)
        that belong to the carried variables, or None (none; eigenvectors not needed)."""
        return None

    needs_vectors = False  # set_aside reads the eigenvectors

    def period(self, X, f1_Hz: float, tangent: bool = False, steps: int | None = None,
               on_step=None):
        raise NotImplementedError

    def linear_monodromy(self, X, f1_Hz: float, steps: int | None = None):
        """An approximation of the monodromy at X for a first chord (:meth:`orbit`,
        ``linear``), or None: a scheme without one (the spline reference) shoots
        from a fresh monodromy, whose tangent period also gives G."""
        return None

    def rotation(self, f1_Hz: float) -> float:
        """Delta = alpha_dot* T1: the twist's rotation per period fixed by the
        controller (k1 > 0, Eq. 40); T1 = 1 / (f1 t_scale), normalised."""
        return self.q_base.spin_target / (f1_Hz * self.q_base.t_scale)

    def shooting_residual(self, X, f1_Hz: float, delta: float, tangent: bool = False,
                          steps: int | None = None):
        """G(X) = P(X) - X - Delta e_alpha, the tension over the period and (with
        ``tangent``) the monodromy."""
        PX, tension, Phi = self.period(X, f1_Hz, tangent=tangent, steps=steps)
        return PX - X - delta * self.e_alpha, tension, Phi

    def first_orbit(self, f1_Hz: float) -> Orbit:
        """From the stationary state after LEAD_IN_PERIODS periods of lead-in."""
        return self.orbit(self.X_stationary, f1_Hz, lead_in=LEAD_IN_PERIODS)

    def predicted_orbit(self, X, f1_Hz: float, tol: float, max_it: int) -> Orbit:
        """The shooting's Newton with the linear monodromy as its first chord."""
        return self.orbit(X, f1_Hz, tol=tol, max_it=max_it, steps=self.resolution(f1_Hz),
                          linear=True)

    def orbit(self, X0, f1_Hz: float, tol: float = 1e-7, max_it: int = 12, lead_in: int = 0,
              steps: int | None = None, linear: bool = False) -> Orbit:
        """Newton on G(X) = P(X) - X - Delta e_alpha = 0 with a held monodromy
        (a chord; with the controller its LU is held), improved by Broyden's
        updates (:class:`Broyden`; with the controller and no carried entries) and
        refreshed at the next iterate when an iteration leaves more than SLOW_RATE
        of |G| (the updates only after the others).  ``linear``: the first chord is the scheme's
        :meth:`linear_monodromy` at X0 (a tenth of a tangent period or less), held
        while iterations leave at most LINEAR_RATE of |G|.  A neighbouring orbit's
        monodromy is no chord: between two f1 a shooting is asked for, the lightly
        damped multipliers rotate by 2 pi f_n d(1/f1), and Newton on it diverged
        (N = 8, 4.54 -> 4.34 Hz).  Backtracking: where |G| does not fall after a step
        (or the period map fails), a step on a held monodromy is redone from its
        start with a fresh one, and a step on a fresh one is halved, down to
        BACKTRACK_MIN of itself."""
        start = time.perf_counter()
        self.newton_iterations = 0
        X = X0.copy()
        for _ in range(lead_in):
            X, _, _ = self.period(X, f1_Hz)
        e = self.e_alpha
        delta = self.rotation(f1_Hz) if self.controller else 0.0
        updates = self.controller and not self.carried.size  # Broyden's, on the held chord
        held = None  # the Newton matrix's inverse, as a Broyden (with the controller), or
        mono = None  # the fresh monodromy (without: the bordered least-squares step)
        chord = self.linear_monodromy(X, f1_Hz, steps) if linear and updates else None
        approx = chord is not None  # the chord is the linear monodromy, not a fresh one
        if approx:
            held = Broyden(self.newton_matrix(chord))
        last, its, G_last = np.inf, 0, None
        back = None  # (X, delta, step, fraction, fresh monodromy) of the last step taken
        for its in range(1, max_it + 1):
            need = held is None and mono is None
            try:
                G, _, Phi = self.shooting_residual(X, f1_Hz, delta, tangent=need, steps=steps)
                res = self.shooting_norm(G, X)
            except SolverError:  # the step's Newton failed from this X
                G, res = None, np.inf
            if back is not None and not res < last:  # no descent
                X0_, d0, step, frac, fresh = back
                if not fresh:  # the held monodromy was stale: Newton from there
                    X, delta, mono, held, back, last = X0_, d0, None, None, None, np.inf
                    approx = False
                    continue
                if frac < BACKTRACK_MIN:  # half the Newton step, down to this
                    raise SolverError(f"orbits: shooting at f1 = {f1_Hz} Hz found no descent "
                                      f"along its Newton step (|G|/|X| = {last:.3g}); "
                                      f"{WAY_OUT}")
                frac /= 2
                X, delta = X0_ - frac * step[:-1], d0 - frac * step[-1]
                back = (X0_, d0, step, frac, fresh)
                continue
            if G is None:
                raise SolverError(f"orbits: the period map failed from the shooting's "
                                  f"start at f1 = {f1_Hz} Hz; {WAY_OUT}")
            if res <= tol:
                X = self.settle(X, G)
                break
            if need:
                approx = False
                if self.controller:
                    held = Broyden(self.newton_matrix(Phi))
                else:
                    mono = Phi
            stale = res > (LINEAR_RATE if approx else SLOW_RATE) * last and not need  # slow
            if updates and back is not None and not need and not stale:
                held.update(-back[3] * back[2][:-1], G - G_last)  # the secant of the last step
            if held is not None:
                step = np.append(held.solve(G), 0.0)
            else:  # unknowns (X, Delta); phase: e . (X - X_prev) = 0.  Without torque
                # the spin is free too (a family of orbits): the least-squares step
                K = np.block([[self.newton_matrix(mono), -e[:, None]],
                              [e[None, :], np.zeros((1, 1))]])
                step = np.linalg.lstsq(K, np.concatenate([G, [0.0]]), rcond=None)[0]
            if stale:
                mono, held, approx = None, None, False
            last, G_last = res, G
            back = (X, delta, step, 1.0, need)
            X, delta = X - step[:-1], delta - step[-1]
        else:
            raise SolverError(f"orbits: shooting did not converge at f1 = {f1_Hz} Hz in "
                              f"{max_it} iterations (|G|/|X| = {res:.3g} > {tol:g}); {WAY_OUT}")
        return self.orbit_through(X, f1_Hz, delta, its, res, start, steps)

    def orbit_through(self, X, f1_Hz, delta, its, res, start, steps=None) -> Orbit:
        """The orbit through X: one more period with the tangent gives the
        Floquet multipliers at the orbit itself, and the tension over it."""
        PX, tension, Phi = self.period(X, f1_Hz, tangent=True, steps=steps)
        G = PX - X - delta * self.e_alpha
        defects = self.defects(G, X, Phi)
        for name, value in defects.items():
            limit = self.defect_tolerances.get(name)
            if limit is not None and not value <= limit:
                raise SolverError(
                    f"orbits: at f1 = {f1_Hz} Hz the orbit's {name} defect is "
                    f"{value:.3g} > {limit:g}: {self.defect_meaning(name)} (docs/explanation/orbits.md, "
                    f"'carried entries')")
        mu, symmetry, internal = self.floquet(Phi)
        T = self.q.tension_N(tension)
        orbit = Orbit(f1_Hz=f1_Hz, X=X, delta=delta, tension_max_N=float(T.max()),
                      tension_min_N=float(T.min()), multipliers=mu, newton_iterations=its,
                      residual=float(res), steps=steps or self.steps_per_period(f1_Hz),
                      wall_s=time.perf_counter() - start, monodromy=Phi,
                      symmetry_multiplier=symmetry, defects=defects,
                      internal_multipliers=internal, G=G)
        return orbit

    def floquet(self, Phi):
        """The Floquet multipliers of the monodromy Phi by decreasing modulus, the
        free rotation's pair (without the controller; else None) and the carried
        variables' multipliers (:meth:`set_aside`; None: none)."""
        internal = None
        if self.needs_vectors:
            mu, vectors = np.linalg.eig(Phi)
            aside = self.set_aside(mu, vectors)
            internal = mu[aside]
            internal = internal[np.argsort(-np.abs(internal))]
            mu = mu[~aside]
        else:
            mu = np.linalg.eigvals(Phi)
        symmetry = None
        if not self.controller:
            # the free rotation alpha -> alpha + c and the uniform spin that drives it
            # form a Jordan block of the multiplier 1; round-off eps splits it into
            # 1 +- sqrt(eps): the pair is set aside, and reported by its mean
            pair = np.argsort(np.abs(mu - 1.0))[:2]
            symmetry = complex(np.mean(mu[pair]))
            mu = np.delete(mu, pair)
        mu = mu[np.argsort(-np.abs(mu))]
        return mu, symmetry, internal
