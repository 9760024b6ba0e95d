"""Stationary state with fixed ends (Sec. 5.1) by Newton's method (PETSc SNES).

Ends fixed by Eqs. (35), (36) and (66); alpha(0) = 0 pins the free rotation.
The first guess is the straight chord, or any state the caller sets.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import dolfinx
import numpy as np
import ufl
from mpi4py import MPI
from petsc4py import PETSc

from rawehelix import compat
from rawehelix.errors import SceneError
from rawehelix.parameters import Parameters
from rawehelix.solvers import fields
from rawehelix.forms.kinematics import tension
from rawehelix.solvers.discrete import RodDiscretisation
from rawehelix.solvers.planar import PlanarRod, planar_allowed
from rawehelix.solvers.snes import NewtonSolver, SolverError


def reduced(params: Parameters) -> bool:
    """The stationary state is solved on the planar (x, z) rod (solvers/planar.py):
    ``model.reduction = "auto"`` and a planar scene."""
    return params.model.reduction == "auto" and planar_allowed(params)


class SlackError(SolverError):
    """The solution has tension <= 0 somewhere."""


@dataclass
class StationaryResult:
    """A converged stationary state, gathered on rank 0 (None elsewhere)."""

    s: np.ndarray  # nodes of the centre line, normalised arc length
    centre_line: np.ndarray  # (n, 3) normalised positions
    s_tension: np.ndarray  # nodes of the tension field
    tension: np.ndarray  # normalised tension, Eq. (29)
    newton_iterations: int
    wall_s: float
    state: object = None  # RodState on every rank (full rod; None for the planar one)


class StationarySolver:
    """Newton for the stationary residual of Eqs. (30)-(31) on one discretisation."""

    #: what a slack state's message advises: the fixed top's tension is its elongation's
    SLACK_ADVICE = "increase ends.elongation"

    def __init__(self, params: Parameters, comm=MPI.COMM_WORLD, scene: str = "scene",
                 planar: bool = False):
        if params.lifter.active:  # the top held by a force: solvers/lifted.py's solver
            raise SceneError(
                params.name, "lifter.top",
                "'lifted' holds the top end by the lifter's force, which `rawehelix "
                "stationary` solves; this command (or ends.tension_N) holds the top at "
                "[ends]' position: set lifter.top = 'fixed', or give ends.elongation")
        self.params, self.scene = params, scene
        # planar: the reduced (x, z) model (solvers.planar), for planar torque-free scenes
        self.rod = PlanarRod(params, comm) if planar else RodDiscretisation(params, comm)
        self.F = self._with_spin_drag(self.rod.stationary_residual(), planar)
        self.newton = NewtonSolver(self.F, self.rod.w, self.rod.bcs, prefix="rawehelix_")
        self._observables(planar)

    def _with_spin_drag(self, F, planar: bool):
        """F plus the spin drag's torque (forms/spin_drag.py) of a relative equilibrium
        spinning at alpha_t = Omega (:meth:`set_spin`; 0 until set): the operating point's
        state.  F itself when the scene has no spin drag."""
        self.spin = None
        if planar or self.rod.q.spin_drag == 0:
            return F
        self.spin = dolfinx.fem.Constant(self.rod.mesh, PETSc.ScalarType(0.0))
        psi = self.rod.model.split(self.rod.test)["twist"]
        return F + self.rod.c.spin_drag.residual(self.spin, psi, self.rod.c, self.rod.measures[0])

    def set_spin(self, omega: float):
        """The spin Omega (normalised: rad per t_scale) of the relative equilibrium whose
        spin drag (forms/spin_drag.py) loads the twist equation; the stationary state
        (Sec. 5.1) has Omega = 0.  Without a spin drag there is nothing to set."""
        if self.spin is not None:
            self.spin.value = omega

    def _observables(self, planar: bool):
        """The tension field's space and expression (Eq. 29)."""
        p = self.rod.degree
        self.V_T = compat.scalar_space(self.rod.mesh, "DG", p - 1)
        self.tension_expr = (tension(self.rod.centre_line(), self.rod.c.sigma) if planar  # (29)
                             else self.rod.model.tension(self.rod.model.split(self.rod.w),
                                                         self.rod.c))
        self._mean_tension_form = None  # compiled on first use (mean_tension)

    def solve(self, first_guess=None) -> StationaryResult:
        """Solve from the chord (or ``first_guess``: s -> (n, 3) centre line)."""
        start = time.perf_counter()
        if first_guess is None:
            self.rod.set_chord()
        else:
            self.rod.set_centre_line(first_guess)
        try:
            its = self.newton.solve(f"stationary state of {self.scene}")
        except SolverError as err:
            raise SolverError(f"{self.scene}: {err}") from None
        result = self.gather()
        self._check_taut(result)
        result.newton_iterations = its
        result.wall_s = time.perf_counter() - start
        result.state = self.rod.get_state()  # None on the planar rod
        return result

    def mean_tension(self) -> float:
        """The mean of the tension along s, int_0^1 T ds~ (normalised, Eq. 29), in
        the current state; every rank gets it.  Collective."""
        if self._mean_tension_form is None:
            self._mean_tension_form = dolfinx.fem.form(self.tension_expr * ufl.dx(self.rod.mesh))
        local = dolfinx.fem.assemble_scalar(self._mean_tension_form)
        return float(self.rod.comm.allreduce(local, op=MPI.SUM))

    def set_end_torques(self, ground: float = 0.0, top: float = 0.0):
        """Torques at s = 0 and s = L0 (normalised by GJ / L0), Eqs. (38)-(39);
        the stationary state of Sec. 5.1 has none."""
        self.rod.c.m0.value = ground
        self.rod.c.mN.value = top

    def end_twist(self) -> float | None:
        """alpha(L0) - alpha(0) [rad] of the full rod's state, on rank 0 (None elsewhere).
        Collective."""
        rod = self.rod
        s, alpha = fields.gather(rod.w.sub(rod.model.index("twist")).collapse())
        return None if alpha is None else float(alpha[-1, 0] - alpha[0, 0])

    def _check_taut(self, result):
        """Eq. (22) is Hooke's law for a taut helix; a compressed one is slack
        (bars and tethers cannot carry it) and the model does not hold."""
        where = None
        if result.tension is not None and result.tension.min() <= 0:
            k = int(result.tension.argmin())
            where = (float(result.s_tension[k]), float(self.rod.q.tension_N(result.tension[k])))
        where = self.rod.comm.bcast(where, root=0)
        if where is not None:
            raise SlackError(
                f"{self.scene}: the stationary tension falls to {where[1]:.4g} N at "
                f"s = {self.rod.q.length_m(where[0]):.4g} m: the helix is slack, and the "
                f"tension law (22) does not hold for compression; {self.SLACK_ADVICE}")

    def gather(self) -> StationaryResult:
        s, x = self.rod.gather_centre_line()
        T = fields.interpolate_expression(self.tension_expr, self.V_T)
        sT, Tv = fields.gather(T)
        return StationaryResult(s, x, sT, None if Tv is None else Tv[:, 0], 0, 0.0)

    def residual_at(self, centre_line, director=None) -> float:
        """|F| at the state (r = centre_line(s), alpha = 0; the shearable rod's director,
        s -> (n, 3)): the FE residual of an outside solution such as the shooting one
        (paper Sec. 5.1)."""
        self.rod.set_centre_line(centre_line, director=director)
        return self.newton.residual_norm()


def sag(centre_line: np.ndarray, top: np.ndarray) -> float:
    """Largest distance of the centre line from the chord 0 -> top."""
    e = top / np.linalg.norm(top)
    along = centre_line @ e
    return float(np.max(np.linalg.norm(centre_line - np.outer(along, e), axis=1)))
