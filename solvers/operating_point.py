"""The operating point at a wind speed: the helix's relative equilibrium under a rotor at
the top and a generator at the ground (issue 43, part 2), solved, not simulated.

At a constant wind the state is alpha(s, t) = Omega t + phi(s) with the centre line
still: r_t = 0 and alpha_t = Omega uniform, so the inertia and the damping terms of
Eqs. (30)-(31) vanish and the centre line and phi are the stationary state (Sec. 5.1)
under the end torques: the rotor's Q(Omega, V_n) at the top along the end tangent
(Eq. 39), the ground's twist held (alpha(0) = 0, a Dirichlet end: its reaction is the
generator's torque), and with ``[spin_drag]`` the spinning tethers' distributed torque
-c Omega|Omega| along s (StationarySolver.set_spin), so that the ground's torque is
Q - c L0 Omega|Omega|.  Omega is the unknown that closes the torque balance
(solvers/rigid_shaft_branch.py): without the helix's distributed loss the twist moment
is constant along s, so Omega solves the rigid-shaft equation Q(Omega, V_n) = tau_gen
(Omega) + L(Omega) exactly, and the rod enters only through V_n, the wind along the
rotor's axis (operation/rotor.py ``normal_speed``): ``rotor.axis = "tangent"`` reads it
off the solved state's top tangent.

How it is solved: a fixed point a = g(a) on the axis factor a = V_n / V_hub, around the
SNES stationary solve (as solvers/tension_target.py wraps its secant around it):

    a_0 from the last point (or the chord); Omega_k the balance's root at a_k V_hub (scalar
    Newton, numpy); the stationary state under Q(Omega_k); g(a_k) its top tangent's;
    a_1 = g(a_0), then the secant on g(a) - a,

stopped when |g(a_k) - a_k| <= AXIS_TOL, after at most MAX_SOLVES stationary solves
(the issue's cost); the point reports that defect.  da/dQ is the top tangent's turn
per torque, ~1e-6 per N m on the paper's helix, so a_1 is within AXIS_TOL of a_0 after the first point and one solve
suffices; the first point takes two.  Each solve checks its converged reason
(solvers/snes.py) and its tension (SlackError).

Its stability is the full linearisation's (solvers/spin_modes.py ``stability``): the
rod's K, C, M about the solved state spinning at Omega, with the rotor's spin inertia
and -dQ/dOmega at the top, the generator's dtau/dOmega (or Eq. 40's k1, k2) at the
ground; one eigenproblem on the stationary solver's rod.  The rigid shaft's slope
d(Q - tau_gen - L)/dOmega is kept as ``slope_Nm_s`` (its verdict ``rigid_shaft_stable``):
with Eq. (40) holding the speed the two differ (docs/explanation/campbell.md).

The top end is solvers/operating_tops.py's: held at [ends]' position (Eqs. 35-36), or
lifted (``lifter.top = "lifted"``: the state of solvers/lifted.py under the lifter, the
top's weight and the rotor's thrust, so the tension follows the thrust; V_n from the
solved end tangent; its stability the rigid shaft's, ``stability_from``).
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np

from rawehelix.solvers import operating_tops
from rawehelix.solvers.spin_modes import EndLoads
from rawehelix.solvers.torque_balance import Drive, stable

#: the stationary solves an operating point may take (the issue's cost)
MAX_SOLVES = 3
#: the axis factor a = V_n / V_hub is converged to this
AXIS_TOL = 1e-10
def chord_axis_factor(drive: Drive, params) -> float:
    """a = V_n / V_hub along the chord's unit vector (Eq. 66, at the elevation Gamma0), or
    for a lifted top along the lifter's pull (the end tangent's direction at rest, on a
    cable): the first guess at the first point, and the window the branches are traced
    over."""
    if params.lifter.active:
        return float(drive.rotor.normal_speed(1.0, np.array(params.lifter.direction())))
    q = params.normalised()
    chord = np.array([-np.cos(q.Gamma0), 0.0, -np.sin(q.Gamma0)])
    return float(drive.rotor.normal_speed(1.0, chord))


def _next_axis_factor(tried) -> float:
    """The next a of the fixed point a = g(a): the secant on g(a) - a through the last two
    tries (the plain iterate g(a) after the first; the tangent's turn with the torque
    makes g nearly constant, but a laid tensegrity's tension follows the torque)."""
    if len(tried) < 2:
        return tried[-1][1]
    (a0, g0), (a1, g1) = tried[-2:]
    f0, f1 = g0 - a0, g1 - a1
    return g1 if f1 == f0 else a1 - f1 * (a1 - a0) / (f1 - f0)


@dataclasses.dataclass
class OperatingPoint:
    """A relative equilibrium at one wind speed, SI (arrays on rank 0)."""

    wind_m_s: float  # V at the reference height
    hub_wind_m_s: float  # V_hub
    v_n_m_s: float  # the wind along the rotor's axis
    omega_rad_s: float
    tsr: float
    torque_top_Nm: float  # Q
    torque_ground_Nm: float  # the generator's: Q - L
    loss_Nm: float
    thrust_N: float
    slope_Nm_s: float  # d(Q - tau_gen - L)/dOmega
    stable: bool  # the full linearisation's verdict (module docstring)
    twist_rad: float | None  # alpha(L0) - alpha(0)
    tension_N: np.ndarray | None  # T(s) [N]
    s_tension_m: np.ndarray | None
    stationary_solves: int
    axis_defect: float  # |a_last - a_used|: the fixed point's residual
    limits: dict | None = None  # the limits block (studies/analysis/structure_limits.py)
    wall_s: float = 0.0
    max_real_part_per_s: float | None = None  # max Re lambda of the linearisation [1/s]
    stability_from: str = "linearisation"  # or "rigid shaft" (a lifted top)
    top_m: np.ndarray | None = None  # the lifted top's position r(L0) [m] (z down)

    @property
    def rigid_shaft_stable(self) -> bool:
        """The rigid shaft's verdict, d(Q - tau_gen - L)/dOmega < 0."""
        return stable(self.slope_Nm_s)

    @property
    def power_W(self) -> float:
        return self.torque_ground_Nm * self.omega_rad_s

    @property
    def rotor_power_W(self) -> float:
        return self.torque_top_Nm * self.omega_rad_s


class OperatingPointSolver:
    """The relative equilibrium at a wind speed (module docstring).  ``scene_at(V)``:
    the scene at the wind V [m/s] (the helix's drag, Eq. 14); ``hub_speed(V)``: the
    rotor's wind [m/s]; ``limits(params, solver)``: the limits block of a solved state
    (None: not wanted).  Builds nothing until :meth:`solve`."""

    def __init__(self, scene_at, drive: Drive, hub_speed, comm, limits=None):
        self.scene_at, self.drive, self.hub_speed = scene_at, drive, hub_speed
        self.comm, self.limits = comm, limits
        self.a = None  # the last point's axis factor
        self.top = None  # solvers/operating_tops.py: what holds the top, its solvers

    def axis(self, tangent) -> float:
        """a = V_n / V_hub for the unit top tangent (the rotor's ``normal_speed``)."""
        return float(self.drive.rotor.normal_speed(1.0, tangent))

    def first_axis_factor(self, params) -> float:
        """a of the chord (Eq. 66) or the lifter's pull: the first guess at the first
        point."""
        return chord_axis_factor(self.drive, params)

    def solve(self, V: float, root) -> OperatingPoint:
        """The operating point at the wind V [m/s] on the branch whose root of the balance
        at V_n ``root(v_n)`` gives (Omega [rad/s]; OutsideTable where the branch has
        none).  SolverError if a stationary solve fails (SlackError: a slack helix)."""
        start = time.perf_counter()
        params = self.scene_at(V)
        q = params.normalised()
        if self.top is None:
            self.top = operating_tops.of_params(params, self.comm, self.drive.rotor)
        v_hub = float(self.hub_speed(V))
        a = self.a if self.a is not None else self.first_axis_factor(params)
        tried = []  # (a, g(a)): the fixed point's secant
        for solves in range(1, MAX_SOLVES + 1):
            v_n = a * v_hub
            omega = root(v_n)
            Q = self.drive.rotor_torque(omega, v_n)
            thrust = float(self.drive.rotor.thrust(omega, v_n, self.drive.rho_kg_m3))
            state = self.top.state(params, omega, Q, thrust)
            g = self.axis(state.tangent)
            defect = abs(g - a)
            tried.append((a, g))
            if defect <= AXIS_TOL:
                break
            a = _next_axis_factor(tried)
        a = tried[-1][1]
        self.a = a
        solver, result = state.solver, state.result
        twist = solver.end_twist()  # collective
        block = self.limits(params, solver) if self.limits else None  # collective
        loss = self.drive.loss_Nm(omega)
        slope = self.drive.slope_Nm_s(omega, v_n)
        loads = EndLoads.of_laws(self.drive.rotor, self.drive.generator, omega, v_n,
                                 self.drive.rho_kg_m3, params.controller)
        verdict, growth = self.top.stability(state, omega, loads, stable(slope))  # collective
        out = OperatingPoint(
            wind_m_s=float(V), hub_wind_m_s=v_hub, v_n_m_s=float(v_n), omega_rad_s=float(omega),
            tsr=float(self.drive.rotor.tsr_of(omega, v_n)), torque_top_Nm=Q,
            torque_ground_Nm=Q - loss, loss_Nm=loss, thrust_N=thrust,
            slope_Nm_s=float(slope), stable=verdict, twist_rad=twist,
            tension_N=None, s_tension_m=None, stationary_solves=solves, axis_defect=defect,
            limits=block, max_real_part_per_s=None if growth is None else float(growth),
            stability_from=self.top.stability_from, top_m=state.top_m)
        if self.comm.rank == 0:
            out.tension_N = q.tension_N(result.tension)
            out.s_tension_m = q.length_m(result.s_tension)
        out.wall_s = time.perf_counter() - start
        return out
