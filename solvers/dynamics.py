"""Dynamics of the rod, Eqs. (30)-(40), with PETSc TS from the stationary state.

Default: generalised-alpha for second-order systems (TSALPHA2, Chung and
Hulbert 1993) with spectral radius 0.9 at infinite frequency: second order,
and the unresolved axial modes (period ~0.03 s, far below the usual step)
are damped instead of ringing, while a mode resolved with 20 steps per
period loses less than 1e-4 of its amplitude per period.  Options (prefix
``rawehelix_``; the TS's nonlinear solver has ``rawehelix_ts_``):

    -rawehelix_ts_type alpha2|theta|cn|beuler|bdf|arkimex|...
    -rawehelix_ts_alpha_radius 0.9     spectral radius of alpha2, in [0, 1]
    -rawehelix_ts_adapt_type basic|none
    -rawehelix_ts_rtol, -rawehelix_ts_atol   local error tolerances (normalised)
    -rawehelix_ts_max_snes_failures 8  retries of a failed step (dt x 0.25 each)
    -rawehelix_ts_jacobian_reuse 0.1   modified Newton: keep the Jacobian and its LU
                                       across iterations and steps until an iteration
                                       contracts |F| by less than this (0: full Newton)
    -rawehelix_ts_compiled 1           alpha2's fixed steps by compiled chord Newton
                                       (solvers/compiled_dynamics.py; one rank)
    -rawehelix_ts_snes_monitor, ...

TSALPHA2 solves the second-order form; every other type gets the first-order
form on (U, V) (implicit types: theta, cn, beuler, bdf, alpha, arkimex with
-ts_arkimex_fully_implicit; explicit types such as rk are not useful here:
the IP bending term is far too stiff).

This module is the TS driver (options, stepping, failures); the states it takes
and returns are :mod:`.dynamics_states`, what it reports of them
:mod:`.dynamics_outputs`.
"""

from __future__ import annotations

import dataclasses
import math
import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.fem
import dolfinx.fem.petsc

from rawehelix import compat, errors
from rawehelix.parameters import Parameters
from rawehelix.solvers import compiled_dynamics, lifted, lifted_top, weather
from rawehelix.solvers.discrete import RodDiscretisation
from rawehelix.solvers.dynamics_outputs import DynamicsOutputs
from rawehelix.solvers.dynamics_states import DynamicsStates
from rawehelix.solvers.end_torques import EndTorques, Machine, machine_of
from rawehelix.solvers.fields import set_constant
from rawehelix.solvers.probes import Probes
from rawehelix.solvers.snes import (FloorConvergence, ReusedJacobian, SolverError, default_options,
                                   lu_options, reason_name, temporary_options)
from rawehelix.solvers.stationary import StationarySolver
from rawehelix.solvers.ts_forms import FirstOrder, SecondOrder

PREFIX = "rawehelix_"
#: integrations other than PETSc TS: solvers/compiled_step.py registers "compiled" when
#: imported (which imports the rod operator, which imports this module: not from here)
ADVANCES: dict = {}

TS_DEFAULTS = {
    "ts_type": "alpha2",
    "ts_alpha_radius": 0.9,
    "ts_adapt_type": "basic",
    "ts_rtol": 1.0e-4,
    "ts_atol": 1.0e-4,
    "ts_max_snes_failures": 8,
    "ts_max_reject": 20,
    "ts_max_steps": 10_000_000,
    "ts_error_if_step_fails": "false",  # we raise SolverError with the reason
    "ts_jacobian_reuse": 0.0,  # full Newton; see ReusedJacobian
}
SNES_DEFAULTS = {  # under the prefix rawehelix_ts_
    "snes_type": "newtonls",
    "snes_linesearch_type": "basic",
    "snes_rtol": 1.0e-8,
    "snes_stol": 1.0e-10,  # |dx| < stol |x|: below the round-off floor of F
    # snes_atol: see residual_floor()
    "snes_max_it": 12,
    "ksp_type": "preonly",
    "pc_type": "lu",  # with lu_options(comm)
}


class NonFiniteState(ArithmeticError):
    """The state has a NaN or Inf after a step."""


def ts_reason_name(reason: int) -> str:
    return reason_name(reason, PETSc.TS.ConvergedReason)


class DynamicsSolver(DynamicsStates, DynamicsOutputs):
    """PETSc TS on the FE rod.  It takes a state and integrates it; it solves
    nothing when it is built and writes no files.

    Parameters
    ----------
    params
        A validated scene.  ``params.time.dt_s`` is the first step.
    comm
        MPI communicator.
    options
        Extra PETSc options for this solver only, without the ``rawehelix_``
        prefix: ``{"ts_type": "cn", "ts_adapt_type": "none"}``.
    rod
        The discretisation to integrate on (default: a new one of ``params``);
        :meth:`from_stationary` passes the stationary solver's.
    machine
        The rotor at the top and the generator at the ground (solvers/end_torques.py);
        default: the scene's (machine_of; none: the paper's ends).
    end_twist
        A prescribed end twist (the torsion test of Sec. 4): alpha(0) = 0 and
        alpha(1) = ``end_twist(t~)`` [rad, t~ normalised]; the end torques are
        then reactions, :meth:`end_moment` the moment at s = 1.  Default: the
        ends are free in twist and carry the torques of Eqs. (38)-(40).

    Give it a state with :meth:`set_state` (or build it with
    :meth:`from_stationary`), then :meth:`advance`; :meth:`state` returns the
    last accepted state, :meth:`set_end_motion` moves the upper end on its
    circle (Eq. 70) at another frequency.
    """

    def __init__(self, params: Parameters, comm=MPI.COMM_WORLD, options: dict | None = None,
                 rod: RodDiscretisation | None = None, end_twist=None,
                 machine: Machine | None = None):
        self.params, self.comm = params, comm
        self._q_scene = params.normalised()
        self.rod = rod if rod is not None else RodDiscretisation(params, comm)
        self.rod.q = self.q = self._q_scene
        self.rod.c.m0.value = 0.0  # the ground torque is the controller's, in the form
        # (35)-(36): r(0) = 0, r(1) = r_N(t) (a lifted top: r(0) only); alpha is free
        # (unless model.twist = false)
        positions = 1 if getattr(self.rod, "free_top", False) else 2
        bcs = self.rod.bcs[:positions] + self.rod.twist_bcs + self.rod.curvature_bcs  # (37)
        if end_twist is not None:  # a torsion test: alpha(0) = 0, alpha(1) = end_twist(t)
            bcs += self.rod.end_twist_conditions()
        ts_defaults = dict(TS_DEFAULTS)
        if self.q.moving_end:
            # a moving end (Eq. 70) starts with the end's velocity and acceleration
            # jumping, which alpha2's error estimate never accepts: fixed steps
            ts_defaults["ts_adapt_type"] = "none"
        if params.lifter.active:  # the top's axial mode bounds the step (solvers/lifted_top.py)
            ts_defaults["ts_adapt_dt_max"] = lifted_top.max_step_s(params) / self.q.t_scale
        snes_defaults = {**SNES_DEFAULTS, **lu_options(comm), "snes_atol": self.residual_floor()}
        with default_options(PREFIX, ts_defaults), default_options(PREFIX + "ts_", snes_defaults), \
                temporary_options(PREFIX, options):
            ts_type = PETSc.Options().getString(PREFIX + "ts_type", "alpha2")
            compiled = compiled_dynamics.wanted(PREFIX, ts_type, comm.size, end_twist)  # issue 46
            if end_twist is not None and ts_type != "alpha2":
                raise ValueError("end_twist: a prescribed end twist runs with alpha2 only "
                                 "(the first-order form sets its own end conditions)")
            self.machine = machine if machine is not None else machine_of(params)
            ends = EndTorques.of(self.q, self.machine)  # the rotor's and generator's (issue 43)
            # the wind in time and a start-up's release (issue 44), each set at each time
            self.weather, self.release, ends = weather.install(self.machine, self.q, self.rod, ends)
            top = lifted_top.of(params, self.rod, ts_type)  # None: r(1) prescribed
            self.form = (SecondOrder(self.rod, bcs, ends, top) if ts_type == "alpha2"
                         else FirstOrder(self.rod, bcs, ends))
            self.form.time_data += [x for x in (self.weather, self.release) if x is not None]
            if end_twist is not None:
                self.form.time_data.append(
                    lambda t: set_constant(self.rod.alpha_top, [end_twist(t)]))
            self.ts = self._create_ts(ts_type)
            self.compiled_wanted, self._compiled = compiled, None  # ADVANCES["compiled"]
            self._alpha_radius = PETSc.Options().getReal(PREFIX + "ts_alpha_radius", 0.9)
        self.probes = Probes(self.form)
        rod_ = self.rod
        self._v_top = dolfinx.fem.Function(rod_.V_r)  # the upper end's velocity, Eq. (70)
        self._bc_v = None if getattr(rod_, "free_top", False) else dolfinx.fem.dirichletbc(
            self._v_top, rod_.end_dofs["top"], rod_.sub("centre_line"))
        self._velocity = dolfinx.fem.Function(rod_.W)  # scratch for the first-order form
        self.newton_iterations = 0
        self.steps = 0
        self._good = None
        self._good_vecs = None  # the last good state's vectors, made once (_remember)
        self._fresh = False
        self._has_state = False

    @classmethod
    def from_stationary(cls, params: Parameters, comm=MPI.COMM_WORLD, options: dict | None = None,
                        scene: str = "scene", end_twist=None) -> "DynamicsSolver":
        """A solver started from the stationary state of Sec. 5.1 at t = 0: at
        rest, but for a moving upper end, whose velocity is the circle's (70)."""
        stationary = StationarySolver(params, comm, scene=scene)
        result = stationary.solve()
        solver = cls(params, comm, options, rod=stationary.rod, end_twist=end_twist)
        solver.set_state(result.state)
        if solver.form.moving_top:  # the end starts with the circle's velocity, Eq. (70)
            solver.set_end_motion(params.ends.circle_frequency_Hz, 0.0)
        return solver

    @classmethod
    def spinning(cls, params: Parameters, machine: Machine, spin: float, torque: float,
                 comm=MPI.COMM_WORLD, options: dict | None = None,
                 scene: str = "scene") -> "DynamicsSolver":
        """A solver with ``machine`` started at t = 0 from the stationary state twisted by
        ``torque`` at both ends (normalised, set_end_torques) spinning uniformly at
        ``spin`` (normalised): at the rigid-shaft point Q = tau, the relative equilibrium."""
        if params.lifter.active:  # the lifted top under the point's thrust (solvers/lifted.py)
            q = params.normalised()
            omega = spin / q.t_scale  # [rad/s]
            stationary, top = lifted.stationary(
                params, comm=comm, top_torque_Nm=q.torque_Nm(torque), omega_rad_s=omega,
                tangent_thrust_N=machine.thrust_N(omega))
            state = top.result.state
        else:
            stationary = StationarySolver(params, comm, scene=scene)
            stationary.set_end_torques(ground=torque, top=torque)
            state = stationary.solve().state
        state.w_t = np.zeros_like(state.w)  # alpha = spin t + phi(s):
        state.w_t[stationary.rod.dofs("twist")] = spin
        solver = cls(params, comm, options, rod=stationary.rod, machine=machine)
        solver.set_state(state)  # Eq. (40)'s C: its ground torque balances the top's
        solver.form.offset.value += torque
        return solver

    @property
    def compiled(self):
        """The compiled steps' :class:`~rawehelix.solvers.compiled_step.CompiledAdvance`
        (built at first use), or None: PETSc TS steps (``-rawehelix_ts_compiled``)."""
        if self._compiled is None and self.compiled_wanted:
            compiled_dynamics.check_loaded(ADVANCES)
            self._compiled = ADVANCES["compiled"](self, self._alpha_radius)
        return self._compiled

    def residual_floor(self) -> float:
        """An absolute Newton tolerance ten times the round-off floor of |F|.

        The floor is set by the IP bending term, whose Jacobian entries grow
        like mu eta p^4 N^3: measured (Sec. 5.2, p = 3) 3e-8, 3e-7 and 4e-6 at
        N = 8, 16 and 32, matched within a factor 10 by
        1e-14 (sigma + mu eta p^4 N^3) sqrt(dofs)."""
        q, d = self.q, self.params.discretisation
        scale = q.sigma + q.mu * d.penalty * d.degree**4 * d.elements**3
        if d.bending == "mixed":  # second order: entries ~ (sigma + mu) p^2 N, forms/mixed.py
            scale = (q.sigma + q.mu) * d.degree**2 * d.elements
        return 1e-14 * scale * math.sqrt(self.rod.dof_count())

    def _create_ts(self, ts_type: str):
        ts = PETSc.TS().create(self.comm)
        ts.setOptionsPrefix(PREFIX)
        ts.setType(ts_type)
        ts.setProblemType(PETSc.TS.ProblemType.NONLINEAR)
        self.form.attach(ts)
        U, V = self.form.initial_vectors()
        if self.form.second_order:
            ts.setSolution2(U, V)
        else:
            ts.setSolution(U)
        ts.setTime(0.0)
        ts.setTimeStep(self.params.time.dt_s / self.q.t_scale)
        ts.setExactFinalTime(PETSc.TS.ExactFinalTime.MATCHSTEP)
        ts.setFromOptions()
        if self.rod.model.has("internal_twist"):  # z, forms/hysteresis.py
            self._exclude_internal_twist_from_error(ts)
        snes = ts.getSNES()
        snes.setOptionsPrefix(PREFIX + "ts_")
        snes.setFromOptions()
        rate = PETSc.Options().getReal(PREFIX + "ts_jacobian_reuse", 0.0)
        self.convergence = ReusedJacobian(rate) if rate > 0 else FloorConvergence()
        self.convergence.stale = True
        self.form.reuse = self.convergence if rate > 0 else None
        snes.setConvergenceTest(self.convergence)
        snes.getKSP().setFromOptions()
        snes.getKSP().getPC().setFromOptions()
        return ts

    def _exclude_internal_twist_from_error(self, ts):
        """The step-size control leaves out the Bouc-Wen twist z (forms/hysteresis.py):
        infinite absolute tolerance on its dofs, the scalar ones on the rest.

        alpha2's error estimate on a field obeying a first-order equation sees
        the start's inconsistent A_z = 0 and every reversal of tau_t (where z_t
        has a kink) as large errors: with z in the norm the Sec. 5.2 spin-up at
        N = 4 takes 10 x the steps (docs/explanation/model.md).  z follows tau, whose error
        is controlled; tests/test_hysteresis.py measures z's accuracy."""
        z_dofs = self.rod.dofs("internal_twist")
        U = self.form.initial_vectors()[0]
        owned = U.getLocalSize()
        rtol, atol = ts.getTolerances()
        vatol = U.duplicate()
        vatol.set(float(atol))
        local = np.asarray(z_dofs, dtype=np.int32)
        local = local[local < owned]
        with vatol.localForm() as v:
            v.array[local] = 1e300
        ts.setTolerances(rtol=rtol, atol=vatol)
        self._vatol = vatol

    def set_top_torque(self, top_Nm: float, rise_time_s: float | None = None):
        """The rotor torque at the upper end, Eq. (69): M_N0 = ``top_Nm`` [Nm],
        reached with the rise time ``rise_time_s`` [s] (default: the scene's).
        The ground torque is the controller's, Eq. (40)."""
        q = self._q_scene
        t0 = q.t0 if rise_time_s is None else rise_time_s / q.t_scale
        if not (t0 > 0 and math.isfinite(top_Nm)):
            raise ValueError(f"set_top_torque: top_Nm = {top_Nm!r} must be finite and "
                             f"rise_time_s = {rise_time_s!r} > 0")
        self._q_scene = dataclasses.replace(q, mN0=top_Nm / q.torque_scale, t0=t0)
        self.q = self.rod.q = dataclasses.replace(self.q, mN0=self._q_scene.mN0, t0=t0)
        self.form.set_time(self.t)

    def set_end_motion(self, f1_Hz: float, t_start: float = 0.0):
        """The upper end on the circle of radius ``ends.circle_radius_m`` at f1 [Hz],
        Eq. (70), at phase 0 at the normalised time ``t_start``; the velocity of
        the end in the current state jumps to that of the circle (a sweep keeps
        its position: the circle restarts where the last one ended)."""
        q = self._q_scene.at_frequency(f1_Hz, t_start)
        self.q = self.rod.q = q
        self.form.moving_top = q.moving_end
        if self._has_state and self.form.second_order:
            t = self.t
            set_constant(self._v_top, q.top_velocity(t))
            dolfinx.fem.petsc.set_bc(compat.petsc_vec(self.form.v), [self._bc_v])
            self.form.v.x.scatter_forward()
            self._push()
            self._remember(t)

    # -- stepping ---------------------------------------------------------------
    @property
    def t(self) -> float:
        """Simulated time [normalised]."""
        return self.ts.getTime()

    def advance(self, t_end: float, on_step=None, on_output=None, output_every: float | None = None):
        """Integrate to ``t_end`` (normalised), calling ``on_output(solver)`` at
        t = 0 (if it is the start) and every ``output_every`` (steps are cut to
        land on those times), and ``on_step(solver)`` after every step.

        Raises SolverError if a step cannot be completed within the retries;
        the state is then the last good one (see :meth:`state`)."""
        if not self._has_state:
            raise RuntimeError("DynamicsSolver: no state yet; call set_state or use from_stationary")
        if self.compiled is not None:  # -rawehelix_ts_compiled: compiled_step.CompiledAdvance
            return self.compiled(t_end, on_step, on_output, output_every)
        ts = self.ts
        t0 = ts.getTime()
        eps = 1e-9 * max(1.0, t_end)
        outputs = []
        if output_every:
            n = int(math.floor((t_end - t0) / output_every + 1e-9))
            outputs = [t0 + k * output_every for k in range(1, n + 1)]
            if not outputs or outputs[-1] < t_end - eps:
                outputs.append(t_end)
        self._pending = outputs
        self._dt_wanted = None
        self._on_step, self._on_output = on_step, on_output

        def prestep(ts_):
            t, dt = ts_.getTime(), ts_.getTimeStep()
            if self._dt_wanted is not None:  # undo the last cut
                dt, self._dt_wanted = max(dt, self._dt_wanted), None
            while self._pending and self._pending[0] <= t + eps:
                self._pending.pop(0)
            if self._pending and t + dt > self._pending[0] - 1e-3 * dt:
                self._dt_wanted = dt
                dt = self._pending[0] - t
            # no step past the max time (PETSc 3.22 fails: "bad hmax"), and no
            # sliver of a step left before it (round-off after many equal steps)
            if t + dt > t_end - 1e-3 * dt:
                self._dt_wanted = self._dt_wanted or dt
                dt = t_end - t
            ts_.setTimeStep(dt)

        first_call = [True]

        def monitor(ts_, step, t, X):
            # TSSolve monitors its start state, then every accepted step
            if first_call[0]:
                first_call[0] = False
                if self._fresh:  # a state just set: it is the first output
                    self._fresh = False
                    self._accepted(t, first=True)
                return
            self._accepted(t)

        ts.setPreStep(prestep)
        ts.setMonitor(monitor)
        ts.setMaxTime(t_end)
        snes_before = ts.getSNESIterations()
        steps_before = ts.getStepNumber()
        try:
            ts.solve(ts.getSolution())
        except NonFiniteState:
            raise self._failure("the state became NaN or Inf") from None
        except PETSc.Error as err:
            errors.reraise_if_interrupted()  # Ctrl-C inside a callback (petsc4py >= 3.19)
            if isinstance(getattr(self, "_callback_error", None), NonFiniteState):
                raise self._failure("the state became NaN or Inf") from None
            raise self._failure(f"PETSc error {err}") from None
        finally:
            ts.cancelMonitor()
            # free the PETSc objects whose wrappers Python dropped (petsc4py >= 3.18
            # defers their destruction to this collective call; see _remember)
            PETSc.garbage_cleanup(compat.petsc_vec(self._state_functions()[0]).getComm())
            self.newton_iterations += ts.getSNESIterations() - snes_before
            self.steps += ts.getStepNumber() - steps_before
        reason = ts.getConvergedReason()
        if reason < 0:
            raise self._failure(f"TS stopped with {ts_reason_name(reason)}")
        self._restore_good()

    def _accepted(self, t, first=False):
        self.form.load_solution(self.ts)
        vec = compat.petsc_vec(self.form.u if self.form.second_order else self.form.x)
        finite = np.isfinite(vec.norm())
        if self.form.second_order:
            finite = finite and np.isfinite(compat.petsc_vec(self.form.v).norm())
        if not finite:
            self._callback_error = NonFiniteState()
            raise self._callback_error
        self._remember(t)
        if self.release is not None and not first:
            self.release.latch(self)
        if self._on_step is not None and not first:
            self._on_step(self)
        eps = 1e-9 * max(1.0, t)
        if self._on_output is not None and (first or (self._pending and abs(t - self._pending[0]) <= eps)):
            self.form.set_time(t)
            self._on_output(self)

    def _failure(self, why: str) -> SolverError:
        self._restore_good()
        t_s = self.q.time_s((self._good or (0.0,))[0])
        snes = self.ts.getSNES()
        return SolverError(
            f"dynamics stopped at t = {float(t_s):.6g} s (simulated): {why}; last SNES reason "
            f"{reason_name(snes.getConvergedReason())}, time step {self.q.time_s(self.ts.getTimeStep()):.3g} s. "
            f"Try a smaller first step (time.dt_s), more retries "
            f"(-{PREFIX}ts_max_snes_failures 20), adaptive steps (-{PREFIX}ts_adapt_type basic), "
            f"more Newton iterations (-{PREFIX}ts_snes_max_it 30) or more elements."
            + law_hint(self.params))


def law_hint(params) -> str:
    """The EI law's convexity limit, for a failure message ('' without a law)."""
    law = params.helix.EI_law
    return law.failure_hint(params.helix.EA_N) if law is not None else ""
