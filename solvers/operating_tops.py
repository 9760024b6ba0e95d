"""The top end of an operating point (solvers/operating_point.py): what holds it, the
state under the rotor's torque and thrust, and the stability verdict about it.

* :class:`FixedTop` (``lifter.top = "fixed"``, the paper's Eqs. 35-36): the top held at
  [ends]' position; the thrust goes into the anchor.  The stationary solver of Sec. 5.1
  under the torques, the top tangent from the FE centre line, and the point's stability
  from the full linearisation (solvers/spin_modes.py).
* :class:`LiftedTop` (``lifter.top = "lifted"``): the top a point mass under its
  weight, the lifter's pull and the rotor's thrust (solvers/lifted.py), so that the
  helix's tension follows the thrust; along the rotor's axis "tangent" the thrust is a
  follower force on the solved end tangent.  The linearisation about a lifted top (its
  position free, the hub's mass, the follower's stiffness) is not written: its verdict
  is the rigid shaft's, and it says so (``stability_from``).

Each holds one rod for every wind speed: the scene at another wind differs only in the
helix's drag, a constant of the forms (RodDiscretisation.set_wind); a scene that
changes more gets new solvers.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rawehelix.solvers.spin_modes import RelativeEquilibrium, SpinModalSolver, stability


@dataclass
class TopState:
    """A solved state under the operating loads: its solver (for the twist and the
    limits), the StationaryResult, the unit top tangent (every rank) and the top's
    position [m] (lifted only)."""

    solver: object
    result: object
    tangent: np.ndarray
    top_m: np.ndarray | None = None


def top_tangent(s: np.ndarray, centre_line: np.ndarray, degree: int) -> np.ndarray:
    """The unit tangent at s = 1 of the FE centre line: the derivative there of the
    degree-p polynomial through the last cell's p + 1 Lagrange nodes (exact for the FE
    field)."""
    order = np.argsort(s)
    s, x = np.asarray(s)[order][-(degree + 1):], np.asarray(centre_line)[order][-(degree + 1):]
    t = np.array([np.polyval(np.polyder(np.polyfit(s, x[:, k], degree)), 1.0) for k in range(3)])
    return t / np.linalg.norm(t)


def _rewound(solver, params) -> bool:
    """``solver``'s rod set to ``params`` (another wind speed); False where ``params``
    changes more than the drag (a new rod is needed)."""
    if solver is None:
        return False
    try:
        solver.rod.set_wind(params)
    except ValueError:
        return False
    solver.params = params
    return True


class FixedTop:
    """The top held at [ends]' position (module docstring)."""

    stability_from = "linearisation"

    def __init__(self, comm):
        self.comm = comm
        self.stationary = self.modal = None

    def state(self, params, omega: float, torque_Nm: float, thrust_N: float) -> TopState:
        """The stationary state under the rotor's torque [N m] at the top (Eq. 39), the
        ground's twist held, spinning at ``omega`` [rad/s] (the spin drag); the thrust
        goes into the fixed top."""
        from rawehelix.solvers.stationary import StationarySolver
        if not _rewound(self.stationary, params):
            self.stationary = StationarySolver(params, self.comm, scene=params.name,
                                               planar=False)
            self.modal = SpinModalSolver(params, self.comm, scene=params.name,
                                         rod=self.stationary.rod)
        solver, q = self.stationary, params.normalised()
        m = torque_Nm / q.torque_scale  # (39), normalised by GJ / L0
        solver.set_end_torques(ground=m, top=m)  # alpha(0) held: m0 is its reaction
        solver.set_spin(omega * q.t_scale)  # the spin drag's distributed loss, if any
        result = solver.solve()
        tangent = None
        if self.comm.rank == 0:
            tangent = top_tangent(result.s, result.centre_line, solver.rod.degree)
        return TopState(solver, result, self.comm.bcast(tangent, root=0))

    def stability(self, state: TopState, omega: float, loads, rigid_shaft_stable: bool):
        """(stable, max Re lambda [1/s]) of the linearisation about ``state``."""
        return stability(RelativeEquilibrium(state.result.state, omega, loads), self.modal)


class LiftedTop:
    """The top held by the lifter (module docstring)."""

    stability_from = "rigid shaft"

    def __init__(self, comm, thrust_direction):
        self.comm, self.direction = comm, thrust_direction
        self.solver = None

    def state(self, params, omega: float, torque_Nm: float, thrust_N: float) -> TopState:
        """The lifted stationary state under the rotor's torque [N m] and thrust [N]
        (along the end tangent, or the rotor's fixed direction), spinning at ``omega``
        [rad/s]; warm from the last state after the first."""
        from rawehelix.solvers import lifted
        warm = _rewound(self.solver, params)
        along = (dict(tangent_thrust_N=float(thrust_N)) if self.direction is None
                 else dict(thrust_N=float(thrust_N) * np.asarray(self.direction)))
        self.solver, out = lifted.stationary(params, comm=self.comm, top_torque_Nm=torque_Nm,
                                             omega_rad_s=omega,
                                             solver=self.solver if warm else None, **along)
        return TopState(self.solver, out.result, out.end_tangent, out.top_m)

    def stability(self, state: TopState, omega: float, loads, rigid_shaft_stable: bool):
        """The rigid shaft's verdict (no growth rate): module docstring."""
        return rigid_shaft_stable, None


def of_params(params, comm, rotor):
    """The top of a scene: :class:`LiftedTop` where ``[lifter]`` lifts it, else
    :class:`FixedTop`."""
    if params.lifter.active:
        return LiftedTop(comm, rotor.thrust_direction())
    return FixedTop(comm)
