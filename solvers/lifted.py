"""The stationary state with a lifted top end (issue 43, ``[lifter] top = "lifted"``).

The ground end is held as in Eq. (35); the top end's position is an unknown, and
its condition is the natural force term of forms/lifter.py: the top is a point
mass (rotor plus hub) under its weight, the rotor's thrust and the lifter's force,
balanced by the helix's end force.  Twist and bending at the ends as in the fixed
case (alpha(0) = 0, the top's torque by Eq. 39, r'' = 0 by Eq. 37).

Newton starts from the straight chord to the first estimate of :func:`first_top`.
A lifter that cannot hold the helix and the top up is refused before any work
(:func:`check_holds`); a Newton that fails, or a state that sags below the ground
anchor, raises :class:`SagError`.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import dolfinx
import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from rawehelix import compat
from rawehelix.errors import SceneError
from rawehelix.forms import lifter
from rawehelix.forms.kinematics import d
from rawehelix.parameters import Parameters
from rawehelix.parameters.lifter import Lifter
from rawehelix.solvers import fields
from rawehelix.solvers.discrete import RodDiscretisation
from rawehelix.solvers.snes import NewtonSolver, SolverError
from rawehelix.solvers.stationary import StationaryResult, StationarySolver

DOWN = np.array([0.0, 0.0, 1.0])  # k_E of forms/kinematics.py as numpy: z points down (Sec. 2.1)


def lifter_direction(elevation_deg: float, azimuth_deg: float) -> np.ndarray:
    """The unit vector of a lifter's pull: ``elevation_deg`` above the horizontal,
    ``azimuth_deg`` about the vertical from -i_E (the paper's top end, Eq. 66, lies along
    azimuth 0: x < 0, downwind of the ground station) towards +j_E; z points down.  The
    one definition is parameters/lifter.py's ``Lifter.direction``."""
    return np.array(Lifter(top="lifted", force_N=1.0, elevation_deg=elevation_deg,
                           azimuth_deg=azimuth_deg).direction())


@dataclass(frozen=True)
class TopLoad:
    """The forces on the lifted top end, SI: the lifter's pull [N] (3,), the rotor's
    thrust [N] (3,) as a fixed vector (axis "wind") and/or its size [N] along the
    helix's end tangent (axis "tangent": a follower force, forms/lifter.py), and the
    top's mass [kg] (rotor plus hub) under gravity g [m/s^2]."""

    lifter_N: tuple
    thrust_N: tuple = (0.0, 0.0, 0.0)
    mass_kg: float = 0.0
    g_m_s2: float = 9.81
    tangent_thrust_N: float = 0.0

    def __post_init__(self):
        for name in ("lifter_N", "thrust_N"):
            value = np.asarray(getattr(self, name), dtype=float)
            if value.shape != (3,) or not np.all(np.isfinite(value)):
                raise ValueError(f"TopLoad.{name} must be 3 finite numbers [N], not {value}")
            object.__setattr__(self, name, tuple(float(x) for x in value))
        for name in ("mass_kg", "tangent_thrust_N"):
            if not (math.isfinite(getattr(self, name)) and getattr(self, name) >= 0):
                raise ValueError(f"TopLoad.{name} must be finite and >= 0, "
                                 f"not {getattr(self, name)}")

    def total_N(self) -> np.ndarray:
        """F = lifter + thrust + m g k_E [N]: the dead end force of forms/lifter.py (the
        tangent thrust, which turns with the end, comes on top)."""
        return np.add(self.lifter_N, self.thrust_N) + self.mass_kg * self.g_m_s2 * DOWN


def check_holds(params: Parameters, load: TopLoad, key: str = "lifter.force_N"):
    """Refuse (SceneError, exit 2) a lifter that cannot hold the helix and the top up:
    the upward part of lifter + thrust not above the weight of the helix and the top, so
    that the helix would leave its ground anchor downwards (into the ground).  In the
    stationary state drag is horizontal (the wind is), so the vertical balance of the
    helix and its top decides.  A thrust along the end tangent counts for nothing here
    (its direction is the solution's): the lifter must hold the machine at rest."""
    lift = -float(np.add(load.lifter_N, load.thrust_N)[2])
    weight = (load.mass_kg * load.g_m_s2
              + params.helix.mass_kg * params.environment.g_m_s2 * float(params.model.gravity))
    if not lift > weight:
        raise SceneError(
            params.name, key,
            f"the lifter cannot hold the helix up: the upward force of lifter and thrust, "
            f"{lift:.4g} N, is not above the weight of the helix and the top, {weight:.4g} N; "
            f"raise lifter.force_N or lifter.elevation_deg, or lower rotor.mass_kg")


def first_top(params: Parameters, load: TopLoad) -> np.ndarray:
    """The first estimate of r(1) (normalised): the straight rod along the mean internal
    force n = F + W/2 k_E (plus the tangent thrust along it), stretched by |n| / EA
    (Eq. 29)."""
    q = params.normalised()
    n = (load.total_N() + 0.5 * params.helix.mass_kg * params.environment.g_m_s2
         * float(params.model.gravity) * DOWN) / q.force_scale
    size = float(np.linalg.norm(n))
    n = n / size * (size + load.tangent_thrust_N / q.force_scale)  # the thrust along it
    size = float(np.linalg.norm(n))
    return (1.0 + size / q.sigma) * n / size


class SagError(SolverError):
    """The lifted helix found no stationary state above its ground anchor."""


@dataclass
class LiftedResult:
    """A converged lifted stationary state: the rod's result and the top (SI)."""

    result: StationaryResult
    top_m: np.ndarray  # r(L0) [m] (z down)
    load: TopLoad
    end_tangent: np.ndarray  # t(L0) = r'/|r'| at the top (the rotor's axis "tangent")

    @property
    def chord_elevation_deg(self) -> float:
        """The elevation of the chord 0 -> r(L0) above the horizontal [deg]."""
        x, y, z = self.top_m
        return math.degrees(math.atan2(-z, math.hypot(x, y)))


class LiftedStationarySolver(StationarySolver):
    """Newton for the stationary residual of Eqs. (30)-(31) with the lifted top: the
    fixed solver's rod without the top's position, plus the end term -F . v(1)."""

    #: the lifted top's tension is the lifter's (its elongation is not read)
    SLACK_ADVICE = "raise lifter.force_N"

    def __init__(self, params: Parameters, load: TopLoad, comm=MPI.COMM_WORLD,
                 scene: str = "scene"):
        self.params, self.scene, self.load = params, scene, load
        self.rod = RodDiscretisation(params, comm, free_top=True)
        mesh = self.rod.mesh
        self.F_top = dolfinx.fem.Constant(mesh, PETSc.ScalarType((0.0, 0.0, 0.0)))
        self.F_tangent = dolfinx.fem.Constant(mesh, PETSc.ScalarType(0.0))
        self.set_load(load)
        _, _, ds = self.rod.measures
        v = self.rod.model.split(self.rod.test)["centre_line"]
        r = self.rod.centre_line()
        self.F = self._with_spin_drag(
            self.rod.stationary_residual() + lifter.end_residual(self.F_top, r, v, ds)
            + lifter.follower_residual(self.F_tangent, r, v, ds), planar=False)
        self._tangent = None  # r' at the nodes, compiled on first use (end_tangent)
        self.newton = NewtonSolver(self.F, self.rod.w, self.rod.bcs, prefix="rawehelix_")
        self._observables(planar=False)

    def set_load(self, load: TopLoad):
        """The top's forces (SI), normalised by M g (Eq. 29); a new load needs no
        recompilation."""
        self.load = load
        self.F_top.value[:] = load.total_N() / self.rod.q.force_scale
        self.F_tangent.value = load.tangent_thrust_N / self.rod.q.force_scale

    def solve_lifted(self, first_guess=None, warm: bool = False) -> LiftedResult:
        """Solve from the chord to :func:`first_top` (or ``first_guess``: s -> (n, 3));
        ``warm``: from the state the solver holds (the last solution: a new load or
        torque of a continuation)."""
        check_holds(self.params, self.load)
        start = time.perf_counter()
        if first_guess is None:
            top = first_top(self.params, self.load)
            first_guess = lambda s: np.outer(s, top)  # noqa: E731
        if not warm:
            self.rod.set_centre_line(first_guess)
        try:
            its = self.newton.solve(f"lifted stationary state of {self.scene}")
        except SolverError as err:
            raise SagError(f"{err} The lifted top found no stationary state: the lifter may "
                           f"be too weak to hold the helix up (raise lifter.force_N or "
                           f"lifter.elevation_deg)") from None
        result = self.gather()
        self._check_above_ground(result)
        self._check_taut(result)
        result.newton_iterations = its
        result.wall_s = time.perf_counter() - start
        result.state = self.rod.get_state()
        top = None if result.centre_line is None else self.rod.q.length_m(result.centre_line[-1])
        top = self.rod.comm.bcast(top, root=0)
        return LiftedResult(result, top, self.load, self.end_tangent())

    def end_tangent(self) -> np.ndarray:
        """t(L0) = r'/|r'| at the top of the current state (every rank; collective): the
        rotor's axis "tangent"."""
        if self._tangent is None:
            rod = self.rod
            self._V_d = compat.vector_space(rod.mesh, "DG", rod.degree - 1, 3)
            self._tangent = d(rod.centre_line())
        _, values = fields.gather(fields.interpolate_expression(self._tangent, self._V_d))
        t = None if values is None else values[-1] / np.linalg.norm(values[-1])
        return self.rod.comm.bcast(t, root=0)

    def _check_above_ground(self, result):
        """z <= 0 everywhere (z points down, the anchor at z = 0): else the helix sags
        into the ground, where no stationary state of a free rod exists."""
        low = None if result.centre_line is None else float(result.centre_line[:, 2].max())
        low = self.rod.comm.bcast(low, root=0)
        if low > 1e-9:
            raise SagError(
                f"{self.scene}: the lifted helix sags {self.rod.q.length_m(low):.4g} m below "
                f"its ground anchor: the lifter does not hold it up; raise lifter.force_N or "
                f"lifter.elevation_deg")


def solve(params: Parameters, load: TopLoad, comm=MPI.COMM_WORLD,
          top_torque: float = 0.0) -> tuple[LiftedStationarySolver, LiftedResult]:
    """The lifted stationary state of ``params`` under ``load``; ``top_torque``
    (normalised by GJ / L0, Eq. 39) at the top, held by the ground (alpha(0) = 0)."""
    solver = LiftedStationarySolver(params, load, comm, scene=params.name)
    solver.set_end_torques(ground=top_torque, top=top_torque)
    return solver, solver.solve_lifted()


def top_load(params: Parameters, thrust_N=(0.0, 0.0, 0.0),
             tangent_thrust_N: float = 0.0) -> TopLoad:
    """The top's forces of a scene with ``[lifter] top = "lifted"``: the lifter's
    ``force_N`` along ``Lifter.direction``, the rotor's (and hub's) ``rotor.mass_kg``
    under gravity, and the rotor's thrust: a vector [N] (3,) and/or a size [N] along the
    end tangent (0: the rotor at rest)."""
    lift = params.lifter
    return TopLoad(lifter_N=lift.force_N * np.array(lift.direction()),
                   thrust_N=thrust_N, mass_kg=params.rotor.mass_kg,
                   g_m_s2=params.environment.g_m_s2 * float(params.model.gravity),
                   tangent_thrust_N=tangent_thrust_N)


def stationary(params: Parameters, thrust_N=(0.0, 0.0, 0.0), comm=MPI.COMM_WORLD,
               top_torque_Nm: float = 0.0, omega_rad_s: float = 0.0,
               solver: LiftedStationarySolver | None = None, tangent_thrust_N: float = 0.0):
    """The lifted stationary state (or relative equilibrium) of a scene under the rotor's
    thrust: ``(solver, LiftedResult)``; SI in, the operating point's entry.

    ``thrust_N`` (3,) [N] the rotor's thrust as a fixed vector (axis "wind"), or
    ``tangent_thrust_N`` [N] its size along the end tangent, which Newton turns with the
    top (axis "tangent": ``result.end_tangent`` is that axis); ``top_torque_Nm`` the rotor's torque
    [N m] at the top, held by the ground's twist (alpha(0) = 0, Eq. 39); ``omega_rad_s``
    the spin [rad/s] of the relative equilibrium, read by the spin drag only
    (``[spin_drag]``, forms/spin_drag.py).  ``solver``: a solver of the same scene from
    an earlier call, which restarts from its last state (a continuation in the wind
    speed: no recompilation, a warm start).  Refuses a lifter that cannot hold the
    helix up (SceneError, before any work); raises SagError if Newton finds no state."""
    q = params.normalised()
    load = top_load(params, thrust_N, tangent_thrust_N)
    check_holds(params, load)  # before any work
    warm = solver is not None
    if solver is None:
        solver = LiftedStationarySolver(params, load, comm, scene=params.name)
    solver.set_load(load)
    m = top_torque_Nm / q.torque_scale  # (39)
    solver.set_end_torques(ground=m, top=m)
    solver.set_spin(omega_rad_s * q.t_scale)
    return solver, solver.solve_lifted(warm=warm)
