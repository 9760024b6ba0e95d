"""Periodic orbits of the forced rod (Sec. 5.3, Eq. 70) by harmonic balance, with
Floquet stability by Hill's method: the periodic-orbit problem
(:mod:`rawehelix.periodic_orbits.problem`) beside shooting (:mod:`.orbits`).

The unknowns X are the Fourier coefficients of the dofs U up to harmonic H of
f1 (:mod:`.harmonics`, X[i P + l]); the twist's
steady rotation is a known secular term, as in the shooting's "periodic modulo
the rotation" (the controller's integral action, Eq. 40, fixes it):

    U(t) = sum_l phi_l(w t) X_l + alpha_dot* t e_alpha,   w = 2 pi f1 t_scale.

G is the Galerkin projection of the rod's residual F(t, U, U_t, U_tt) (the
shooting's operator, :class:`~rawehelix.solvers.rod_operator.RodOperator`) on
the basis, by AFT on N = 4H + 2 samples; the Dirichlet dofs (35)-(37) hold the
coefficients of g(t) (their rows X - g^).  dG/dX from the tangents F_U, F_V,
F_A at the samples (harmonics.BlockPattern); the Newton's linear solves are
PETSc's (prefix ``rawehelix_hb_``, MUMPS LU by default: the continuation's
bordered matrix has a zero pivot).

H is chosen by accuracy (:meth:`HarmonicBalance.orbit` without a resolution): raised
until the energy in the highest harmonic is below TAIL_TOL of the oscillation's
(``Orbit.accuracy``).  The Floquet multipliers: Hill's method (:mod:`.hill`)
on F_A x'' + F_V x' + F_U x = 0 from the tangents at the samples, its exponents sorted
by their eigenvectors' symmetry (Bentvelsen & Lazarus 2018), by shift-invert at 0
(folds), i w/2 (period doubling) and the least damped exponents of the averaged system
(:data:`SHIFTS`): the largest multiplier, not all of them.

Where harmonic balance is the wrong tool it refuses, naming the other method
(:mod:`.scope`): the hysteretic torsion (a non-smooth internal variable) and no
controller (a free rotation).  The members' slack is non-smooth too: it needs many
harmonics, which the accuracy test shows (docs/explanation/harmonic_balance.md).
"""

from __future__ import annotations

import contextlib
import math
import time

import numpy as np
from mpi4py import MPI

from rawehelix.parameters import Parameters
from rawehelix.periodic_orbits.continuation import SLOW
from rawehelix.periodic_orbits.problem import Orbit, PeriodicOrbitProblem
from rawehelix.solvers.dynamics import DynamicsSolver
from rawehelix.solvers.harmonic_balance import harmonics, hill, newton
from rawehelix.solvers.harmonic_balance.stability import (EVERY_POINT, HillPoint, StabilityStep,
                                                          Track)
from rawehelix.solvers.harmonic_balance.newton import Diverged
from rawehelix.solvers.harmonic_balance.scope import H_MAX, H_START, cannot
from rawehelix.solvers.harmonic_balance.sparse_lu import LU
from rawehelix.solvers.rod_operator import RodOperator
from rawehelix.solvers.snes import SolverError

TAIL_TOL = 1e-8  # the highest harmonic's share of the oscillation's energy, at most
FINE = 256  # samples of T(0) per period for its extremes (a smooth signal's maximum
# is then missed by (pi / 256)^2 / 2 = 8e-5 of its oscillation at the highest harmonic)
SHIFTS = 2  # the least damped exponents of the averaged system used as Hill shifts
HOMOTOPY_MIN = 1.0 / 64  # the shortest step in the end's amplitude (HarmonicBalance._start)
START_RETRIES = 2  # the first orbit's search, H raised this many times where it fails


class HarmonicBalance(PeriodicOrbitProblem):
    """Harmonic balance on the FE rod (module docstring); ``H``: the harmonics to
    start with (None: H_START, raised by accuracy in :meth:`orbit`)."""

    def __init__(self, params: Parameters, H: int | None = None, comm=MPI.COMM_SELF,
                 solver: DynamicsSolver | None = None, tail_tol: float = TAIL_TOL,
                 H_max: int = H_MAX, oversample: int = 1,
                 stability: StabilityStep = EVERY_POINT):
        if comm.size > 1:
            raise SolverError("orbits --method hb runs on one rank; run separate frequency "
                              "windows on separate ranks")
        why = cannot(params)
        if why:
            raise SolverError(f"harmonic balance: {why}")
        self.params = params
        self.op = op = RodOperator(params, comm, solver)
        self.q_base = params.normalised().steady_torque()
        self.solver, self.n, self.controller = op.solver, op.n, True
        self.e = op.e_alpha[:self.n]  # a uniform twist of U
        self.bc = np.asarray(op.bc_dofs, dtype=int)
        self.free = np.setdiff1d(np.arange(self.n), self.bc)
        self.H, self.tail_tol, self.H_max = H or H_START, tail_tol, H_max
        self.oversample = int(oversample)  # x the samples of harmonics.samples_for (aliasing)
        try:  # T(0) linear in r'(0) (Eq. 29), or the probe's (a member law's tension)
            op.tension_map()
            self._linear_tension = True
        except RuntimeError:
            self._linear_tension = False
        self._cache = {}  # H -> (Basis, BlockPattern); (f1, H) -> g^ at the bc dofs
        self.stability_step = stability  # when a continued point gets a Hill solve (.stability)
        self._deferring = False  # inside a trace that calls stability() (deferred_stability)
        self._track = None  # the last Hill solve, the points since, the drift (.stability)
        self._natural = None  # the last natural step's orbit (predicted_orbit)
        self._its = 0  # the Newton iterations of the last point stability() saw
        self._pending = None  # (X, f1, H, tangents) of the last carried finish
        self.X_stationary = self.embed(op.X_stationary[:self.n], self.H)

    # -- the layout ------------------------------------------------------------------
    def basis(self, H: int) -> harmonics.Basis:
        if H not in self._cache:
            self._cache[H] = [harmonics.Basis(H, self.oversample * harmonics.samples_for(H)),
                              None]
        return self._cache[H][0]

    def coefficients(self, X, H) -> np.ndarray:
        return X.reshape(self.n, 2 * H + 1)

    def embed(self, X, H: int) -> np.ndarray:
        """X at H harmonics: a state U (n entries, the mean) or coefficients at another H."""
        C = X.reshape(self.n, -1) if X.size % self.n == 0 else None
        if C is None or (C.shape[1] % 2 == 0 and C.shape[1] != 1):
            raise ValueError(f"harmonic balance: cannot read {X.size} entries as coefficients")
        return harmonics.resize(C, 2 * H + 1).ravel()

    def omega(self, f1_Hz: float) -> float:
        return 2 * math.pi * f1_Hz * self.q_base.t_scale

    def set_frequency(self, f1_Hz: float):
        self.q = self.q_base.at_frequency(f1_Hz, 0.0)
        self.op.load_forcing(self.q)

    def _H(self, X, resolution) -> int:
        H = resolution or (X.size // self.n - 1) // 2
        if X.size != self.n * (2 * H + 1):
            raise ValueError(f"harmonic balance: X has {X.size} entries, not n (2H + 1) = "
                             f"{self.n * (2 * H + 1)} at H = {H}")
        return H

    def states(self, C, f1_Hz: float, basis, theta=None):
        """U, U_t, U_tt (N, n) at the basis' samples (or at angles ``theta``)."""
        w, s = self.omega(f1_Hz), self.q_base.spin_target
        at = basis.theta() if theta is None else theta
        U = basis.synthesis(C, theta=theta) + np.outer(at / w, s * self.e)
        return (U, basis.synthesis(C, w, 1, theta) + s * self.e, basis.synthesis(C, w, 2, theta))

    def state(self, X, f1_Hz: float, t: float = 0.0) -> np.ndarray:
        """(U, U_t, U_tt) at time t (normalised) as one vector of 3n: the shooting's
        state X (solvers/orbits.py), e.g. to start it on this orbit."""
        H = self._H(X, None)
        w = self.omega(f1_Hz)
        U, V, A = self.states(self.coefficients(X, H), f1_Hz, self.basis(H), np.array([w * t]))
        return np.concatenate([U[0], V[0], A[0]])

    def boundary(self, f1_Hz: float, basis) -> np.ndarray:
        """g^: the coefficients (n_bc, P) of the Dirichlet data less the secular twist."""
        key = (f1_Hz, basis.H)
        if key not in self._cache:
            w, s, op = self.omega(f1_Hz), self.q_base.spin_target, self.op
            g = []
            for theta in basis.theta():
                op.set_time(theta / w)
                g.append(op.bc_values() - s * (theta / w) * self.e[self.bc])
            self._cache[key] = basis.analysis(np.array(g))
        return self._cache[key]

    # -- the periodic-orbit problem ---------------------------------------------------
    def continuable(self):
        return None

    def resolution(self, f1_Hz: float) -> int:
        return self.H

    def residual(self, X, f1_Hz: float, jacobian: bool = False, resolution: int | None = None,
                 amplitude: float = 1.0):
        """(G, T(0) samples over the period (normalised, FINE of them), dG/dX or None);
        ``amplitude``: the end's oscillation scaled (the first orbit's homotopy)."""
        G, tension, data = self.sampled(X, f1_Hz, jacobian, resolution, amplitude)
        return G, tension, self._jacobian(data, f1_Hz, self._H(X, resolution)) if jacobian else None

    def sampled(self, X, f1_Hz: float, tangents: bool = True, resolution: int | None = None,
                amplitude: float = 1.0):
        """(G, T(0) samples, the tangents (F_U, F_V, F_A) at the AFT's samples or None)."""
        H = self._H(X, resolution)
        basis, C = self.basis(H), self.coefficients(X, H)
        self.set_frequency(f1_Hz)
        U, V, A = self.states(C, f1_Hz, basis)
        op, w = self.op, self.omega(f1_Hz)
        F, data = np.empty((basis.N, self.n)), []
        for j, theta in enumerate(basis.theta()):
            op.set_time(theta / w)
            op.load(U[j], V[j], A[j])
            F[j] = op.residual()
            if tangents:
                data.append([M.copy() for M in op.csr()])  # csr() reuses its matrices
        G = basis.analysis(F)
        g = self.boundary(f1_Hz, basis).copy()
        g[:, 1:] *= amplitude
        G[self.bc] = C[self.bc] - g
        return G.ravel(), self.tension(C, f1_Hz), data if tangents else None

    def _jacobian(self, data, f1_Hz, H):
        """dG/dX (CSR) from the tangents at the samples, the Dirichlet rows unit rows."""
        basis, w = self.basis(H), self.omega(f1_Hz)
        entry = self._cache[basis.H]
        if entry[1] is None:
            entry[1] = harmonics.BlockPattern(data[0][0], basis.P)
        pattern = entry[1]
        D = np.zeros((3, basis.N, pattern.nnz))
        for j, mats in enumerate(data):
            for a, M in enumerate(mats):
                D[a, j, pattern.entries(M)] = M.data
        W = basis.jacobian_weights(w)
        blocks = sum(Wa @ D[a] for a, Wa in enumerate(W)).reshape(basis.P, basis.P, -1)
        Fu = data[0][0]
        rows = np.repeat(np.arange(self.n), np.diff(Fu.indptr))
        in_bc = np.isin(rows, self.bc)
        blocks[:, :, in_bc] = 0.0
        diagonal = np.flatnonzero(in_bc & (rows == Fu.indices))
        for m in range(basis.P):
            blocks[m, m, diagonal] = 1.0
        return pattern.matrix(blocks)

    def _more(self, H: int) -> int:
        """The next H where H is too few: x 1.5, at least + 2, at most H_max."""
        return min(self.H_max, max(H + 2, math.ceil(1.5 * H)))

    def refine(self, prev: Orbit, orbit: Orbit) -> Orbit | None:
        """H raised (x 1.5, at least + 2) where ``orbit``'s tail exceeds tail_tol, and
        ``prev`` solved again at it (the continuation redoes the step)."""
        if orbit.accuracy.get("tail", 0.0) <= self.tail_tol or orbit.steps >= self.H_max:
            return None
        self.H = self._more(orbit.steps)
        return self.orbit(prev.X, prev.f1_Hz, steps=self.H)

    def resume_from(self, orbit: Orbit) -> None:
        self.H = orbit.steps

    def residual_f1(self, X, f1_Hz: float, resolution: int, G=None, eps: float = 1e-6) -> np.ndarray:
        """dG/df1 at fixed H by central differences (two residuals; AFT, no steps)."""
        h = eps * f1_Hz
        G_at = lambda f1: self.residual(X, f1, resolution=resolution)[0]  # noqa: E731
        return (G_at(f1_Hz + h) - G_at(f1_Hz - h)) / (2 * h)

    def jacobian(self, orbit: Orbit):
        """dG/dX at ``orbit``, evaluated again where the branch has released it."""
        if orbit.jacobian is None:
            orbit.jacobian = self.residual(orbit.X, orbit.f1_Hz, jacobian=True,
                                           resolution=orbit.steps)[2]
        return orbit.jacobian

    def factor(self, K):
        return LU(K)

    def norm(self, G, X) -> float:
        return float(np.linalg.norm(G) / max(1.0, np.linalg.norm(X)))

    def settle(self, X, G):
        return X

    def tension(self, C, f1_Hz: float) -> np.ndarray:
        """T(0) (normalised) at FINE angles over the period: Eq. (29) with r'(0) = D U."""
        op = self.op
        theta = 2 * math.pi * np.arange(FINE) / FINE
        basis = self.basis((C.shape[1] - 1) // 2)
        if not self._linear_tension:  # the probe at each angle
            return np.array([op.probe_tension(u) for u in self.states(C, f1_Hz, basis, theta)[0]])
        d = basis.synthesis(op._D @ C, theta=theta)  # (FINE, 3); the secular twist is not in r
        return op._sigma * (np.linalg.norm(d, axis=1) - 1.0)

    def samples(self, X, f1_Hz: float, resolution: int | None = None) -> np.ndarray:
        return self.tension(self.coefficients(X, self._H(X, resolution)), f1_Hz)

    def orbit(self, X0, f1_Hz: float, tol: float = 1e-9, max_it: int = 20,
              steps: int | None = None) -> Orbit:
        """Newton at fixed f1 (PETSc LU, backtracking on |G|); without ``steps`` (H),
        H is raised from the problem's until the tail is below ``tail_tol`` (then
        the problem's H)."""
        start = time.perf_counter()
        H = steps or self.H
        X = self.embed(X0, H)
        retries = 0
        while True:
            try:
                X, its, res = self._start(X, f1_Hz, H, tol, max_it)
            except Diverged:
                raise  # more harmonics do not help
            except SolverError as err:
                retries += 1  # too few harmonics may hold no orbit: twice more, then say so
                if steps or H >= self.H_max or retries > START_RETRIES:
                    raise SolverError(f"{err} (tried H up to {H}: a non-smooth law, such as "
                                      f"the members' slack, needs many harmonics: try "
                                      f"--method shooting)") from None
                H = self._more(H)
                X = self.embed(X0, H)
                continue
            tail = self.basis(H).tail(self.coefficients(X, H))
            if steps or tail <= self.tail_tol or H >= self.H_max:
                break
            H = self._more(H)
            X = self.embed(X, H)
        if not steps:
            self.H = H
        return self.finish(X, f1_Hz, its, res, start, H)

    def _start(self, X, f1_Hz, H, tol, max_it):
        """Newton from X, or where it fails, a homotopy in the end's amplitude from 0
        (the spinning stationary state) to 1 in steps halved where they fail (the
        shooting's lead-in periods)."""
        try:
            return self._newton(X, f1_Hz, H, tol, max_it)
        except SolverError:
            pass
        X, _, _ = self._newton(X, f1_Hz, H, tol, max_it, amplitude=0.0)
        done, step, total = 0.0, 0.25, 0
        while done < 1.0:
            to = min(1.0, done + step)
            try:
                X_to, its, res = self._newton(X, f1_Hz, H, tol, max_it, amplitude=to)
            except SolverError:
                step /= 2
                if step >= HOMOTOPY_MIN:
                    continue
                try:  # a fold in the amplitude: plain Newton steps may jump to the orbit
                    return self._newton(X, f1_Hz, H, tol, 3 * max_it, plain=True)
                except SolverError:
                    raise SolverError(f"harmonic balance at f1 = {f1_Hz} Hz, H = {H}: no orbit "
                                      f"found by a homotopy in the end's amplitude (a fold at "
                                      f"{done:.3g} of it); start the --f1 window where the "
                                      f"response is small, away from a resonance") from None
            X, done, total = X_to, to, total + its
        return X, total, res

    def _newton(self, X, f1_Hz, H, tol, max_it, amplitude=1.0, plain=False):
        """Newton at fixed f1 and H (:mod:`.newton`)."""
        return newton.newton(self, X, f1_Hz, H, tol, max_it, amplitude, plain)

    def finish(self, X, f1_Hz, iterations, residual, start, resolution=None) -> Orbit:
        H = self._H(X, resolution)
        basis = self.basis(H)
        G, tension, tangents = self.sampled(X, f1_Hz, resolution=H)
        J = self._jacobian(tangents, f1_Hz, H)
        T = self.q.tension_N(tension)
        orbit = Orbit(f1_Hz=f1_Hz, X=X, delta=self.q_base.spin_target * 2 * math.pi /
                      self.omega(f1_Hz), tension_max_N=float(T.max()),
                      tension_min_N=float(T.min()), multipliers=np.zeros(0),
                      newton_iterations=iterations, residual=float(residual), steps=H,
                      wall_s=time.perf_counter() - start, G=G, jacobian=J,
                      accuracy={"H": H, "samples": basis.N,
                                "tail": basis.tail(self.coefficients(X, H))})
        if self._deferring and self._track is not None:  # stability() decides
            self._carry(orbit)
            self._pending = (X, f1_Hz, H, tangents)
        else:
            self._floquet(orbit, tangents)
        return orbit

    def _floquet(self, orbit: Orbit, tangents) -> None:
        """The orbit's multipliers by Hill's method from its tangents."""
        floquet = self.hill(orbit.f1_Hz, orbit.steps, tangents)
        orbit.multipliers = floquet.multipliers
        orbit.accuracy["stability"] = (floquet.method + f"; the exponents near 0, i w / 2 and "
                                       f"the {SHIFTS} least damped of the averaged system, "
                                       f"not the whole spectrum")
        orbit.accuracy.pop("hill_f1_Hz", None)
        point = HillPoint(floquet.multipliers, orbit.f1_Hz, orbit.X, orbit.steps)
        if self._track is None:
            self._track = Track(point)
        else:
            self._track.hill(point, self._distance(orbit))

    def _carry(self, orbit: Orbit) -> None:
        """The last Hill solve's multipliers, said so (the guarded stability step)."""
        last = self._track.last
        orbit.multipliers = last.multipliers.copy()
        orbit.accuracy["stability"] = (f"carried from the Hill solve at f1 = {last.f1_Hz:.6g} "
                                       f"Hz (no fold since, no exponent predicted to cross; "
                                       f"guarded stability step, "
                                       f"docs/explanation/harmonic_balance.md)")
        orbit.accuracy["hill_f1_Hz"] = last.f1_Hz

    @contextlib.contextmanager
    def deferred_stability(self, last: Orbit):
        """Inside a trace, finish carries the last Hill's multipliers and
        :meth:`stability` runs Hill where the stability step says it is due."""
        if not self.stability_step.carries:
            yield
            return
        self._deferring, self._its = True, last.newton_iterations
        self._track = Track(HillPoint(last.multipliers, last.f1_Hz, last.X, last.steps))
        try:
            yield
        finally:
            self._deferring, self._pending = False, None

    def stability(self, orbit: Orbit, event: bool) -> None:
        if not (self._deferring and "hill_f1_Hz" in orbit.accuracy):
            return
        self._track.since += 1
        # the next step may be natural (continuation.py: after a natural step, or two slow
        # correctors in a row): it reads this point's multipliers
        natural = orbit is self._natural or min(orbit.newton_iterations, self._its) >= SLOW
        self._its = orbit.newton_iterations
        if not self.stability_step.due(self._track, self._distance(orbit), event, natural):
            return
        X, f1, H, tangents = self._pending or (None, None, None, None)
        if X is not orbit.X or f1 != orbit.f1_Hz or H != orbit.steps:
            tangents = self.sampled(orbit.X, orbit.f1_Hz, resolution=orbit.steps)[2]
        self._floquet(orbit, tangents)

    def predicted_orbit(self, X, f1_Hz: float, tol: float, max_it: int) -> Orbit:
        self._natural = super().predicted_orbit(X, f1_Hz, tol, max_it)
        return self._natural

    def _distance(self, orbit: Orbit) -> float:
        """``orbit``'s distance from the last Hill solve (stability.Track.distance)."""
        return self._track.distance(orbit.X, orbit.f1_Hz, orbit.steps, self.embed)

    def hill(self, f1_Hz: float, H: int, tangents):
        """Hill's exponents from the tangents at the AFT's samples (:meth:`sampled`)."""
        Fu, Fv, Fa = zip(*tangents)
        w = self.omega(f1_Hz)
        shifts = [0.0, 0.5j * w] + hill.averaged_exponents(Fa, Fv, Fu, self.free, SHIFTS)
        return hill.hill_exponents(Fa, Fv, Fu, w, H, free=self.free, shifts=shifts)

    def multipliers(self, X, f1_Hz: float, resolution: int | None = None) -> np.ndarray:
        H = self._H(X, resolution)
        return self.hill(f1_Hz, H, self.sampled(X, f1_Hz, resolution=H)[2]).multipliers

    def sections(self, X, f1_Hz: float, steps: int | None = None, samples: int = 128) -> list:
        """The section along s at ``samples`` times of the period: [(t, Probes.section())]."""
        H = self._H(X, steps)
        basis = self.basis(H)
        theta = 2 * math.pi * np.arange(1, samples + 1) / samples
        U, _, _ = self.states(self.coefficients(X, H), f1_Hz, basis, theta)
        self.set_frequency(f1_Hz)
        out, w = [], self.omega(f1_Hz)
        for j, th in enumerate(theta):
            self.op.set_time(th / w)
            self.op.probe_tension(U[j])
            out.append((th / w, self.op.probes.section()))
        return out

