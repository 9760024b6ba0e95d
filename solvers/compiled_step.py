"""TSALPHA2's steps by chord Newton, compiled (issue 46): solvers/chord.py's loop
(:meth:`~rawehelix.solvers.generalised_alpha.AlphaStepper.solve_stage`, its
predictor, Hairer's test, the LU refresh rule and its failures) in numba's
nopython mode, on F and J assembled by the FFCx kernels
(:mod:`~rawehelix.solvers.compiled_forms`) and a banded LU with partial pivoting
(:mod:`~rawehelix.solvers.banded_lu`, J renumbered to a narrow band).

The time data (the forms' constants and the Dirichlet values g at each step's
stage time) come from the affine map of the forcing laws found on the
formulation's own ``set_time`` (:mod:`~rawehelix.solvers.compiled_time_data`:
one set_time a stretch of steps), or from set_time at every step when the form
has other time data; the loop only reads them.  So the numbers are
ChordAlpha's to the Newton tolerance (tests/test_compiled_steps.py compares them
with TS).  Like ChordAlpha it has no line search: a step whose Newton diverges
with a fresh Jacobian raises; one
rank, dense (3 n <= generalised_alpha.MAX_STATE).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from rawehelix.solvers import banded_lu, compiled_dynamics, dynamics
from rawehelix.solvers.chord import ChordAlpha
from rawehelix.solvers.compiled_forms import CompiledForms, jacobian, residual
from rawehelix.solvers.compiled_time_data import TimeDataFit
from rawehelix.solvers.generalised_alpha import TOL
from rawehelix.solvers.snes import SolverError

# the compiled loop's outcomes (its return code)
OK, NON_FINITE, DIVERGES, NO_CONVERGENCE, SINGULAR = 0, 1, 2, 3, 4


@numba.njit(cache=True)
def _steps(u, v, a, hist, nhist, h, scheme, sv, sa, cF, cj, shift_slots, G, bc, Fp, Jp,
           LU, piv, kl, has_lu, D, sigma, tension, tol, rate, max_it, order, counters, work,
           marks, saved, Jw, LT, UT, perm):
    """``G.shape[0]`` steps from (u, v, a) in place; ``hist`` the last stage values
    (newest first, ``nhist`` of them), ``cF``/``G`` each step's constants and
    Dirichlet values; ``cj`` (J's constants), ``Jw`` (J) and ``work`` (8 n + F's
    constants) scratch, held by the caller (no allocation a call); the LU (``LU``,
    ``LT``, ``UT``, ``piv``: banded_lu) is of J renumbered by ``perm``; (u, v, a) after ``marks[i]``
    steps into ``saved[i]`` (the outputs' states).  Returns (code, step, size,
    theta) and counts iterations and factorisations in ``counters``."""
    mark = 0
    am, af, g_, b_ = scheme[0], scheme[1], scheme[2], scheme[3]
    n = u.shape[0]
    X = work[:3 * n]
    R, dz, z = work[3 * n:4 * n], work[4 * n:5 * n], work[5 * n:6 * n]
    b, y = work[6 * n:7 * n], work[7 * n:8 * n]  # R and dz renumbered
    cf = work[8 * n:]
    for k in range(G.shape[0]):
        # predictor (AlphaStepper.predict): extrapolation, or constant acceleration
        if nhist[0] < order + 1:
            for i in range(n):
                z[i] = u[i] + af * (h * v[i] + 0.5 * h * h * a[i])
        elif order == 2:
            for i in range(n):
                z[i] = 3.0 * hist[0, i] - 3.0 * hist[1, i] + hist[2, i]
        else:
            for i in range(n):
                z[i] = hist[0, i]
        for j in range(bc.shape[0]):
            z[bc[j]] = G[k, j]
        cf[:] = cF[k]
        zmax = 0.0
        for i in range(n):
            zmax = max(zmax, abs(z[i]))
        noise = 1e-14 * max(1.0, zmax)  # generalised_alpha.ROUNDOFF
        # newmark's V_a, A_a of z
        for i in range(n):
            u1 = (z[i] - (1 - af) * u[i]) / af
            a1 = (u1 - u[i] - h * v[i] - h * h * (0.5 - b_) * a[i]) / (b_ * h * h)
            v1 = v[i] + h * ((1 - g_) * a[i] + g_ * a1)
            X[n + i] = v[i] + af * (v1 - v[i])
            X[2 * n + i] = a[i] + am * (a1 - a[i])
        fresh, last, size, theta = False, -1.0, 0.0, -1.0
        done = False
        for it in range(max_it):
            for i in range(n):
                X[i] = z[i]
            if not has_lu[0]:
                for j in range(cF.shape[1]):
                    cj[shift_slots[2 + j]] = cF[k, j]
                cj[shift_slots[0]], cj[shift_slots[1]] = sv, sa
                jacobian(Jw, X, cj, Jp, bc)
                banded_lu.permute(Jw, perm, LU)
                if banded_lu.factor(LU, piv, kl, LT, UT) != 0:
                    return SINGULAR, k, 0.0, -1.0
                has_lu[0] = True
                counters[1] += 1
                fresh, last = True, -1.0
            residual(R, X, cf, Fp)
            for j in range(bc.shape[0]):
                R[bc[j]] = 0.0
            for i in range(n):
                b[i] = R[perm[i]]
            banded_lu.solve(LU, LT, UT, piv, kl, b, y)
            for i in range(n):
                dz[perm[i]] = y[i]
            size = 0.0
            for i in range(n):
                size = max(size, abs(dz[i]))
            if not size < math.inf:
                return NON_FINITE, k, size, theta
            at_floor = size <= noise
            theta = -1.0 if (at_floor or last < 0.0) else size / last
            if theta >= 1.0:
                if size <= 100.0 * noise:  # generalised_alpha.STALL: converged at R's floor
                    done = True
                    break
                if fresh:
                    return DIVERGES, k, size, theta
                has_lu[0] = False
                continue
            for i in range(n):
                z[i] -= dz[i]
                X[n + i] -= sv * dz[i]
                X[2 * n + i] -= sa * dz[i]
            counters[0] += 1
            if at_floor:
                done = True
                break
            if theta >= 0.0:
                eta = theta / (1.0 - theta)
                if eta * size <= tol:
                    if theta > rate:
                        has_lu[0] = False
                    done = True
                    break
                if theta > rate:
                    has_lu[0] = False
                    fresh = False
                    continue
            last = size
        if not done:
            return NO_CONVERGENCE, k, size, theta
        for i in range(n):
            u[i] = u[i] + (z[i] - u[i]) / af
            v[i] = v[i] + (X[n + i] - v[i]) / af
            a[i] = a[i] + (X[2 * n + i] - a[i]) / am
        for j in range(hist.shape[0] - 1, 0, -1):
            hist[j, :] = hist[j - 1, :]
        hist[0, :] = z
        nhist[0] = min(nhist[0] + 1, hist.shape[0])
        counters[2] += 1
        r2 = 0.0
        for c in range(3):
            d = 0.0
            for i in range(n):
                d += D[c, i] * u[i]
            r2 += d * d
        tension[k] = sigma * (math.sqrt(r2) - 1.0)
        if mark < marks.shape[0] and marks[mark] == k + 1:
            saved[mark, 0, :], saved[mark, 1, :], saved[mark, 2, :] = u, v, a
            mark += 1
    return OK, G.shape[0], 0.0, 0.0


class CompiledChordAlpha(ChordAlpha):
    """ChordAlpha whose steps (not its start) run compiled: same scheme, predictor,
    chord Newton and tests, on the FFCx kernels (module docstring)."""

    def __init__(self, params, rho_inf: float = 0.9, solver=None, tol: float = 1e-11,
                 rate: float = 0.03, max_it: int = 8, order: int = 2, tension: bool = True):
        if order not in (0, 2):
            raise SolverError(f"compiled steps: predictor order {order} (0 or 2)")
        super().__init__(params, rho_inf, solver, tol, rate, max_it, order, tension_map=tension)
        op = self.op
        #: the loop's T(0) is the section's (the solid's linear map); False: NaN
        self.tension_known = tension
        if not tension:
            op._D, op._sigma = np.zeros((3, op.n)), math.nan
        self.forms = CompiledForms(op)
        self._Fp, self._Jp = self.forms.pieces()
        sv_slot, sa_slot, rest = self.forms._shift_slots
        self._slots = np.concatenate([[sv_slot, sa_slot], rest]).astype(np.int64)
        self._bc = np.asarray(op.bc_dofs, dtype=np.int64)
        n = op.n
        self._LU, self._piv = np.zeros((n, n)), np.zeros(n, np.int64)
        self._has_lu, self._lu_h = np.zeros(1, np.bool_), None
        self._counters = np.zeros(3, np.int64)
        # the last stage values (newest first), carried into a continued run
        self._hist, self._nhist = np.zeros((3, n)), np.zeros(1, np.int64)
        self._bc_sources = op.form.bc_sources()
        if self._bc_sources is None:
            raise SolverError("compiled steps: a Dirichlet value that is not a function")
        self._fit = TimeDataFit(op.form, self._sample)
        self._cF_size = self.forms.constants().size
        self._cj, self._work = np.empty(self._cF_size + 2), np.empty(8 * n + self._cF_size)
        # J's band narrowed by renumbering (banded_lu.ordering), its LU's scratch
        self._perm, self.bandwidth = banded_lu.ordering(
            [e.dofs for e in self.forms.J_entities.values()], n)
        self._Jw, self._LT = np.zeros((n, n)), np.zeros((n, self.bandwidth))
        self._UT = np.zeros((n, 2 * self.bandwidth))

    # ChordAlpha's counters: the start's (AlphaStepper) and the compiled steps'
    iterations = property(lambda self: self.alpha.iterations + int(self._counters[0]))
    factorisations = property(lambda self: self.alpha.factorisations + int(self._counters[1]))
    steps = property(lambda self: self.alpha.steps + int(self._counters[2]))

    def _sample(self, t):
        """(constants of F, Dirichlet values) at t, from the form's set_time."""
        self.op.set_time(t)
        functions, index = self._bc_sources
        return self.forms.constants(), np.concatenate([f.x.array for f in functions])[index]

    def time_data(self, times, t_end=None):
        """(constants of F, Dirichlet values) at each stage time: by the fit of the
        forcing laws (anchored at ``t_end``, where the form is left), or by the form's
        set_time at each."""
        if t_end is not None:
            fitted = self._fit(times, t_end, self._cF_size)
            if fitted is not None:
                return fitted
        rows = [self._sample(t) for t in times]
        return np.array([r[0] for r in rows]), np.array([r[1] for r in rows])

    def run(self, t0, h, steps, u, v, a=None, marks=None):
        """ChordAlpha.run, the steps compiled (the start, if any, by ChordAlpha's); a
        run continued (``a`` given, the same h) keeps the predictor's history.
        ``marks`` (ascending step counts): (u, v, a) after each in ``self.saved``
        (len(marks), 3, n), and ``self.saved_count`` of them valid, a failure too."""
        alpha = self.alpha
        tension = np.empty(steps + 1)
        tension[0] = self.tension0(u)
        given = a
        if a is None:
            a = self.start(t0, h, u, v)
        u, v, a = u.copy(), v.copy(), np.array(a, dtype=float)
        same_h = self._lu_h is not None and abs(h - self._lu_h) <= 1e-9 * h
        if not same_h:  # the LU's shifts are h's (round-off of h: the chord copes)
            self._has_lu[0], self._lu_h = False, h
        if given is None or not same_h:  # the predictor's history: a new start
            self._nhist[0] = 0
        hist, nhist = self._hist, self._nhist
        scheme = np.array(alpha.scheme)
        sv, sa = alpha.shifts(h)
        cF, G = self.time_data(t0 + (np.arange(steps) + alpha.alpha_f) * h, t0 + steps * h)
        marks = np.zeros(0, np.int64) if marks is None else np.asarray(marks, dtype=np.int64)
        self.saved = np.empty((marks.size, 3, u.size))
        code, k, size, theta = _steps(
            u, v, a, hist, nhist, h, scheme, sv, sa, cF, self._cj, self._slots,
            G, self._bc, self._Fp, self._Jp, self._LU, self._piv, self.bandwidth, self._has_lu, self.op._D,
            self.op._sigma, tension[1:], alpha.tol, alpha.rate, alpha.max_it,
            alpha.order, self._counters, self._work, marks, self.saved, self._Jw, self._LT,
            self._UT, self._perm)
        self.saved_count = int(np.searchsorted(marks, k, side="right"))
        if code != OK:
            t = t0 + k * h
            self._has_lu[0] = False
            raise SolverError({
                NON_FINITE: f"compiled alpha2: the state became NaN or Inf at t = {t:.6g} "
                            f"(normalised)",
                DIVERGES: f"compiled alpha2: Newton diverges with a fresh Jacobian at t = {t:.6g} "
                          f"(normalised; contraction {theta:.2g}, |dz| {size:.2g}); try a smaller step "
                          f"(time.dt_s)",
                NO_CONVERGENCE: f"compiled alpha2: no convergence in {alpha.max_it} iterations at "
                                f"t = {t:.6g} (normalised; last |dz| = {size:.3g}, tol "
                                f"{alpha.tol:g}); try a smaller step (time.dt_s)",
                SINGULAR: f"compiled alpha2: the Jacobian is singular at t = {t:.6g} (normalised); "
                          f"try a smaller step (time.dt_s)"}[code])
        self.acceleration = a
        return u, v, tension


def _steps_to(t, h0, outputs):
    """The ends of TS's steps from ``t``: steps of ``h0``, the one that would pass an
    output time (or leave less than 1e-3 h0 before it) cut to land on it, as
    DynamicsSolver.advance's prestep cuts them."""
    ends = []
    for end in outputs:
        while t + h0 <= end - 1e-3 * h0:
            t += h0
            ends.append(t)
        ends.append(end)
        t = end
    return ends


#: the outputs one compiled call steps to at most (their states kept for the outputs
#: after it): fewer Python calls a step (at 2 ms output, 4 steps an output)
BATCH = 32


def _batches(t, ends, h0, batch=BATCH):
    """The output stretches from t to each of ``ends`` by steps of at most h0, as
    compiled calls: [(start, h, step counts of the outputs, output times)], consecutive
    stretches of equal steps together (``batch`` at most)."""
    out, key = [], None
    for end in ends:
        n = max(1, math.ceil((end - t) / h0 - 1e-9))
        h = (end - t) / n
        if key is not None and key[0] == n and abs(key[1] - h) <= 1e-12 * h \
                and len(out[-1][2]) < batch:
            out[-1][2].append(out[-1][2][-1] + n)
            out[-1][3].append(end)
        else:
            out.append((t, h, [n], [end]))
            key = (n, h)
        t = end
    return out


class CompiledAdvance:
    """``DynamicsSolver.advance`` by compiled steps (module docstring)."""

    def __init__(self, solver, rho_inf: float):
        self.solver = solver
        # Hairer's test at the orbits' 1e-14, not ChordAlpha's 1e-11: the energy balance
        # of an undamped free vibration is then TS's (2.9e-7 against 3.1e-7 over 2000
        # steps; 1e-11: 4.2e-5, 1e-13: 7.0e-6), for 2.8 iterations a step instead of 2.0
        self.stepper = CompiledChordAlpha(solver.params, rho_inf, solver=solver, tol=TOL,
                                          tension=compiled_dynamics.loop_tension(solver.params))
        self._last = None  # (t, U) where the last advance ended, with its acceleration

    def __call__(self, t_end: float, on_step=None, on_output=None, output_every=None):
        solver, stepper = self.solver, self.stepper
        ts, form = solver.ts, solver.form
        t = ts.getTime()
        eps = 1e-9 * max(1.0, t_end)
        h0 = ts.getTimeStep()
        outputs = [t_end]
        if output_every:
            n = int(math.floor((t_end - t) / output_every + 1e-9))
            outputs = [t + k * output_every for k in range(1, n + 1)]
            if not outputs or outputs[-1] < t_end - eps:
                outputs.append(t_end)
        ends, marks = outputs, set(outputs if output_every else ())  # advance's outputs
        batch = BATCH
        if on_step is not None or solver.release is not None:
            # every step ends a stretch (a start-up's release latches after each step, as
            # in advance: one step a compiled call then); the outputs stay TS's
            ends = _steps_to(t, h0, outputs)
            if solver.release is not None:
                batch = 1
        U, V = ts.getSolution2()
        u, v = form.u.x.array.copy(), form.v.x.array.copy()
        last = self._last
        a = last[2] if (last is not None and abs(last[0] - t) <= eps
                        and (last[1] == u).all()) else None
        solver._on_step, solver._on_output = on_step, on_output
        if solver._fresh:
            solver._fresh = False
            solver._pending = []
            solver._accepted(t, first=True)
        it0, st0 = stepper.iterations, stepper.steps
        try:
            for t0, h, counts, times in _batches(t, ends, h0, batch):
                failed = None
                try:
                    stepper.run(t0, h, counts[-1], u, v, a, marks=counts)
                except SolverError as err:
                    failed = err
                for i in range(stepper.saved_count):  # the stretches' ends, in Python
                    u, v, a = stepper.saved[i]
                    t = times[i]
                    U.array[:] = u
                    V.array[:] = v
                    ts.setTime(t)
                    solver._pending = [t] if t in marks else []
                    solver._accepted(t)
                if failed is not None:
                    solver._restore_good()
                    t_s = solver.q.time_s(solver._good[0] if solver._good else t)
                    raise SolverError(f"dynamics stopped at t = {float(t_s):.6g} s (simulated): "
                                      f"{failed}; or run without {compiled_dynamics.OPTION}") from None
        finally:
            solver.newton_iterations += stepper.iterations - it0
            solver.steps += stepper.steps - st0
        self._last = (t, u.copy(), a.copy())


dynamics.ADVANCES["compiled"] = CompiledAdvance
