"""Periodic orbits of the forced rod (Sec. 5.3, Eq. 70) by shooting, with Floquet stability.

The period map P advances the state X = (U, V, A) of the generalised-alpha
integrator (Chung and Hulbert 1993, the scheme of TSALPHA2, same rho_inf)
over one forcing period T1 = 1/f1 in M equal steps.  A periodic orbit is a
fixed point of P modulo the twist's steady rotation:

    G(X) = P(X) - X - Delta e_alpha = 0,                         (shooting)

e_alpha: a uniform unit twist (U's alpha dofs).  With the controller's
integral action (k1 > 0, Eq. 40) the rotation per period is fixed,
Delta = alpha_dot* T1; without it, the rigid rotation is a symmetry, Delta
is free and one phase condition (the mean twist of X) closes the system.
The torque ramp (69) is taken at its final value (``Normalised.steady_torque``).

One step solves R(z) = F(t_n + alpha_f h, z, V_a(z), A_a(z)) = 0 for the
stage value z = U_{n+alpha_f} (the unknown of TSALPHA2 up to the factor
alpha_f); U_{n+1}, V_{n+1}, A_{n+1}, V_a, A_a are linear in (z, X_n)
(:meth:`AlphaStepper.newmark`).  The monodromy dP/dX comes from tangent
propagation through the steps: at a converged step

    J dz = -(F_V dV_a + F_A dA_a)|_{z fixed},  J = F_U + s_V F_V + s_A F_A,

with the step's own Jacobian J at the converged stage (NLvib does this for
Newmark).  Dirichlet rows (35)-(37) read z - g(t), so their rows of J are
unit rows and they do not depend on X_n.  The Floquet multipliers are the
eigenvalues of the monodromy at the orbit; the n spurious roots of the
scheme (about -rho_inf per step) give multipliers near 0.

The steps are :class:`~rawehelix.solvers.generalised_alpha.AlphaStepper`'s
(chord Newton at ``tol`` = 1e-14, the tangent), on the operator of
:class:`~rawehelix.solvers.rod_operator.RodOperator`; here, the shooting
problem on their period map:

- every period starts with no LU held, so P is a function of (X, f1, M)
  (the branch store's resume is bit for bit);
- the tangent only in a tangent period; a tangent period from the (X, f1, M)
  of the last plain period (the Floquet period after the last residual)
  propagates along its kept steps.

Dense monodromy on one rank: the state has 3 n entries (n dofs), the
monodromy (3n)^2; refused past ``MAX_STATE`` (N = 8, p = 3: 3n = 300).
"""

from __future__ import annotations

import math

import numpy as np
from mpi4py import MPI

from rawehelix.parameters import Parameters
from rawehelix.solvers.dynamics import DynamicsSolver, law_hint
from rawehelix.periodic_orbits.floquet import Orbit, PeriodMap  # noqa: F401  (Orbit re-exported)
from rawehelix.solvers.generalised_alpha import MAX_STATE, TOL, AlphaStepper, check_newton  # noqa: F401
from rawehelix.solvers.rod_operator import RodOperator
from rawehelix.solvers.snes import SolverError

#: hysteretic torsion (floquet.py, "Carried entries"): the largest residual of the solved
#: entries once the carried ones are P's (10 x the shooting's tol), the largest drift of
#: z over a period relative to z, and the distance to 1 of a multiplier of z
CARRIED_TOL, Z_TOL, Z_MULTIPLIER = 1e-6, 1e-6, 1e-3


class AlphaMap(PeriodMap):
    """The shooting problem on the generalised-alpha period map of the FE rod.

    The steps' chord Newton (:class:`AlphaStepper`): ``tol`` Hairer's test on the
    stage value (normalised, max norm), ``rate`` the contraction above which the LU
    is refreshed, ``max_it`` per step, ``order`` of the predictor's extrapolation;
    ``newton="full"``: the former full Newton with dense matrices (a reference)."""

    def __init__(self, params: Parameters, rho_inf: float = 0.9, comm=MPI.COMM_SELF,
                 solver: DynamicsSolver | None = None, tol: float = TOL, rate: float = 0.03,
                 max_it: int = 12, order: int = 2, newton: str = "chord"):
        check_newton(newton)
        if comm.size > 1:
            raise SolverError("orbits: the shooting solver runs on one rank (dense monodromy); "
                              "run separate frequency windows on separate ranks")
        self.params = params
        self.op = op = RodOperator(params, comm, solver)
        self.stepper = AlphaStepper(op, rho_inf, tol=tol, rate=rate, max_it=max_it, order=order,
                                    newton=newton)
        self.solver, self.n = op.solver, op.n
        self.q_base = params.normalised().steady_torque()
        self.e_alpha, self.z_dofs = op.e_alpha, op.z_dofs
        if self.z_dofs.size:  # z and its V and A: carried (floquet.py)
            self.carried = op.carried
        self.controller = self.q_base.k1 != 0.0
        self.newton_iterations = 0  # of the steps, since the last orbit() began
        self._kept = None  # the steps of the last period without tangent (period())
        self.X_stationary = op.X_stationary

    #: the defects allowed at an orbit (floquet.py, "Carried entries"; docs/explanation/orbits.md)
    defect_tolerances = {"carried": CARRIED_TOL, "z": Z_TOL}

    def defects(self, G, X, Phi) -> dict:
        """floquet's carried defect and, with the hysteretic torsion, z's own:
        |G_z| / max(1, |z|), z's drift over one period relative to z."""
        out = super().defects(G, X, Phi)
        if self.z_dofs.size:
            z = self.z_dofs
            out["z"] = float(np.linalg.norm(G[z]) / max(1.0, np.linalg.norm(X[z])))
        return out

    def defect_meaning(self, name: str) -> str:
        if name == "z":
            return ("the hysteretic torsion's internal twist z still drifts over a period "
                    "with the rod periodic (its multipliers are 1 - O(beta x twist travel), "
                    "so the shooting carries z instead of solving for it); more lead-in "
                    "periods, or 'rawehelix sweep'")
        return super().defect_meaning(name)

    @property
    def needs_vectors(self) -> bool:
        return bool(self.z_dofs.size)

    def set_aside(self, mu, vectors):
        """z's multipliers: real within Z_MULTIPLIER of 1, their eigenvector mostly
        z in U (|v_z| > |v_U| / 2); 1 - mu ~ beta x the twist's travel per period,
        how much of a change of z a period forgets (docs/explanation/orbits.md)."""
        U = vectors[:self.n]
        share = np.linalg.norm(U[self.z_dofs], axis=0) / np.maximum(
            np.linalg.norm(U, axis=0), 1e-300)
        return (np.abs(mu - 1.0) <= Z_MULTIPLIER) & (share > 0.5)

    def set_frequency(self, f1_Hz: float):
        self.q = self.q_base.at_frequency(f1_Hz, 0.0)
        self.op.load_forcing(self.q)

    def step(self, t, h, X, Phi=None, z=None):
        """One step of the stepper (:meth:`AlphaStepper.step`), its Newton
        iterations counted in :attr:`newton_iterations`."""
        before = self.stepper.iterations
        out = self.stepper.step(t, h, X, Phi, z)
        self.newton_iterations += self.stepper.iterations - before
        return out

    def steps_per_period(self, f1_Hz: float) -> int:
        period = 1.0 / (f1_Hz * self.q_base.t_scale)  # normalised
        return max(8, math.ceil(period / (self.params.time.dt_s / self.q_base.t_scale) - 1e-9))

    def linear_monodromy(self, X, f1_Hz: float, steps: int | None = None) -> np.ndarray:
        """S^M: the tangent S of the period's first step from X (at t = 0, h = T1 / M)
        to the M-th power (by squaring), the monodromy of the scheme on the
        time-invariant linearisation about that step.  A chord for the shooting
        (:meth:`PeriodMap.orbit`, ``linear``) where the orbit hardly varies over the
        period: it turns each lightly damped multiplier by that mode's angle over
        this T1, which a neighbouring orbit's monodromy does not.  Measured (N = 8,
        from the orbit at the f1 before): at 4.34 Hz it costs 0.13 s against a
        tangent period's 1.22 s, its largest multiplier 0.96502 is the exact one
        to 5 digits, and Newton takes 9 periods instead of 5; at 0.6 Hz 0.16 s
        against 8.54 s, 0.940 against 0.960, and 8 periods instead of 6."""
        self.set_frequency(f1_Hz)
        M = steps or self.steps_per_period(f1_Hz)
        self.stepper.forget()
        _, S = self.step(0.0, 2 * math.pi / self.q.omega1 / M, X, np.eye(3 * self.n))
        return np.linalg.matrix_power(S, M)

    def period(self, X, f1_Hz: float, tangent: bool = False, steps: int | None = None,
               on_step=None):
        """P(X) over one period at f1 (phase 0 at t = 0), the tension at s = 0 at
        every step (normalised) and, with ``tangent``, the monodromy dP/dX.
        ``on_step(probes)`` is called after every step with the rod's probes
        (:class:`~rawehelix.solvers.probes.Probes`) at the new state.  The
        steps of the last period without tangent are kept: a tangent period
        from the same (X, f1, M) (the shooting's and the continuation's
        Floquet period after their last residual) propagates the tangent along
        them instead of solving them again (the same numbers: the steps start
        from no held LU, so they are a function of (X, f1, M))."""
        self.set_frequency(f1_Hz)
        M = steps or self.steps_per_period(f1_Hz)
        T1 = 2 * math.pi / self.q.omega1
        h = T1 / M
        key = (f1_Hz, M)
        kept, stepper = self._kept, self.stepper
        if (tangent and on_step is None and kept is not None and kept[0] == key  # chord only
                and np.array_equal(kept[1][0], X)):
            return self._replay(kept, h)
        Phi = np.eye(3 * self.n) if tangent else None
        stepper.forget()  # no LU held from another period: P is a function of (X, f1, M)
        tension, history, n = [], [], self.n
        trajectory = [X]  # X_k, then each step's stage value and X_{k+1}
        for k in range(M):
            z = stepper.predict(history, X[:n], X[n:2 * n], X[2 * n:], h)
            try:
                X, Phi = self.step(k * h, h, X, Phi, z)
            except SolverError as err:
                hint = law_hint(self.params)
                if not hint:
                    raise
                raise SolverError(str(err) + hint) from err
            history = [stepper.stage] + history[:stepper.order]
            if not np.all(np.isfinite(X)):
                raise SolverError(f"orbits: the state became NaN or Inf at f1 = {f1_Hz} Hz")
            tension.append(self.op.probe_tension(X[:self.n]))
            if on_step:
                on_step(self.op.probes)
            trajectory += [stepper.stage, X]
        tension = np.array(tension)
        self._kept = (key, trajectory, tension) if not tangent and stepper.newton == "chord" else None
        return X, tension, Phi

    #: the section's samples a period for the limits block (:meth:`sections`): one
    #: Probes.section() costs 1.8 ms at N = 8 against 1.2 ms a step, and a period
    #: has 4000 steps at 0.5 Hz; at 128 the maximum of a smooth periodic signal is
    #: missed by at most (pi / 128)^2 / 2 = 3e-4 of its oscillation
    SECTION_SAMPLES = 128

    def sections(self, X, f1_Hz: float, steps: int | None = None,
                 samples: int | None = None) -> list:
        """The section state along s at ``samples`` (default SECTION_SAMPLES; at most
        one a step) equally spaced steps of one period from X: [(t, Probes.section()
        dict)] (normalised, t from phase 0), the orbit's fields for its limits block
        (studies/analysis/branch_limits.py).  A plain :meth:`period`: it keeps its steps as
        one would."""
        M = steps or self.steps_per_period(f1_Hz)
        n = min(M, samples or self.SECTION_SAMPLES)
        at = {(j * M) // n - 1 for j in range(1, n + 1)}  # the steps sampled, the last one's end
        out, count = [], [0]

        def keep(probes):
            if count[0] in at:
                out.append((count[0] + 1, probes.section()))
            count[0] += 1

        self.period(X, f1_Hz, steps=M, on_step=keep)
        h = 2 * math.pi / self.q.omega1 / M
        return [(h * k, section) for k, section in out]

    def _replay(self, kept, h):
        """The tangent period along the kept steps (:meth:`period`)."""
        _, trajectory, tension = kept
        n, Phi = self.n, np.eye(3 * self.n)
        for k in range(len(trajectory) // 2):
            X, z = trajectory[2 * k], trajectory[2 * k + 1]
            self.op.set_time((k + self.stepper.alpha_f) * h)
            Phi = self.stepper.tangent(z, X[:n], X[n:2 * n], X[2 * n:], h, Phi)
        return trajectory[-1].copy(), tension.copy(), Phi
