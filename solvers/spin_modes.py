"""Modes of the helix about a relative equilibrium (an operating point), and its stability.

At an operating point the rod spins uniformly: U = the stationary state under the
operating torques (Eqs. 38-39), V = (0, Omega) in the twist, A = 0.  The dynamic
residual F(U, V, A) of Eqs. (30)-(31) linearised there gives

    K = F_U,   C = F_V (drag, structural damping, any coupling of the spin),   M = F_A,

(:mod:`.linearise`, assembled at V = (0, Omega)) plus the end components' lumped
terms on the twist (:mod:`rawehelix.forms.end_loads`): the rotor's spin inertia (M)
and aerodynamic damping -dQ/dOmega (C) at the top, the generator's dtau/dOmega (C)
and the paper's law Eq. (40) k1 (K), k2 (C) at the ground.  The modes are those of
the existing SLEPc path (:class:`~rawehelix.solvers.modal.ModalSolver`: the
quadratic eigenproblem, the families of :mod:`.classify`).

The rigid rotation of torque-free ends becomes the rigid shaft's mode: with J the
rotor's and the rod's polar inertia, lambda = (Q' - tau') / J (rigid_shaft's
stability d(Q - tau)/dOmega < 0); a positive real part is an unstable point.  The
flexible helix can lose a mode the rigid shaft keeps: with the paper's law holding
the speed, the ground's damper k2 barely reaches the rotor's mode on the helix's twist
(docs/explanation/campbell.md).  :func:`stability` and :func:`stability_at` give
(stable, max_real_part [1/s]) for an operating point's verdict.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import dolfinx.fem
from mpi4py import MPI
from petsc4py import PETSc

from rawehelix.forms.end_loads import EndLoadForms
from rawehelix.parameters import Parameters
from rawehelix.parameters.checks import ParameterError
from rawehelix.solvers.discrete import RodDiscretisation
from rawehelix.solvers.modal import ModalSolver, Mode
from rawehelix.solvers.state import RodState

#: max Re lambda (normalised, 1/t_scale) above which a point is unstable: the rigid
#: rotation's Jordan pair at zero splits by O(sqrt(eps)) in round-off (test_modal.py
#: measured 2.4e-6), so a neutral rotation must not read as a growing one
STABILITY_TOL = 1e-5
#: ... plus this share of |lambda|: an undamped mode's Re lambda is |lambda| times
#: round-off (measured 3.1e-9 |lambda| on a straight helix without gravity or drag, GJ =
#: 1e6 N m^2, N = 4: Re 4.2e-5 at |lambda| = 13520, normalised)
STABILITY_REL_TOL = 1e-7
#: |K e| / |K| (infinity norms) below which the uniform twist e is K's null vector
#: (measured 4.5e-13 / 1e7 on Table 2 at N = 4)
NULL_TOL = 1e-12


@dataclass(frozen=True)
class EndLoads:
    """What the end components add to the linearisation, in SI (or Eq. 40's gains)."""

    rotor_inertia_kgm2: float = 0.0  # J_top: the rotor's spin inertia at the top [kg m^2]
    rotor_dtorque_domega_Nms: float = 0.0  # dQ/dOmega of the aerodynamic torque [N m s]
    generator_dtorque_domega_Nms: float = 0.0  # dtau/dOmega of the generator [N m s]
    k1: float = 0.0  # Eq. (40)'s gain on the spin's angle (normalised, as controller.k1)
    k2: float = 0.0  # Eq. (40)'s gain on the ground's spin rate (normalised, controller.k2)

    def __post_init__(self):
        for name in ("rotor_inertia_kgm2", "rotor_dtorque_domega_Nms",
                     "generator_dtorque_domega_Nms", "k1", "k2"):
            value = getattr(self, name)
            if not math.isfinite(value):
                raise ParameterError(f"end loads {name}", value, "must be finite")
        for name in ("rotor_inertia_kgm2", "k1", "k2"):
            if getattr(self, name) < 0:
                raise ParameterError(f"end loads {name}", getattr(self, name), "must be >= 0")

    @classmethod
    def of_laws(cls, rotor, generator, omega_rad_s: float, v_n_m_s: float, rho_kg_m3: float,
                controller) -> "EndLoads":
        """The rotor's and the generator's laws (operation/rotor.py, operation/generator.py)
        linearised at the spin ``omega_rad_s`` and the wind ``v_n_m_s`` along the rotor's
        axis; ``generator`` None: no ground torque.  The paper's law (Eq. 40 with k1 > 0,
        ``generator.holds_speed``) enters by the scene's ``controller`` k1 and k2."""
        held = generator is not None and generator.holds_speed is not None
        dtau = 0.0 if generator is None or held else float(generator.dtorque_domega(omega_rad_s))
        return cls(rotor_inertia_kgm2=float(rotor.spin_inertia_kgm2),
                   rotor_dtorque_domega_Nms=float(rotor.dtorque_domega(omega_rad_s, v_n_m_s,
                                                                        rho_kg_m3)),
                   generator_dtorque_domega_Nms=dtau,
                   k1=controller.k1 if held else 0.0, k2=controller.k2 if held else 0.0)

    def normalised(self, q) -> dict:
        """The coefficients of forms/end_loads.py's terms for the groups ``q``."""
        J_rod = rod_polar_inertia_kgm2(q)
        # dQ/dOmega [N m s] -> d(Q / (GJ/L0)) / d(alpha_t~), alpha_t~ = t_scale Omega
        rate = q.torque_scale * q.t_scale
        return {"top_inertia": self.rotor_inertia_kgm2 / J_rod,
                "top_damping": -q.delta * self.rotor_dtorque_domega_Nms / rate,
                "ground_damping": q.delta * (self.generator_dtorque_domega_Nms / rate + self.k2),
                "ground_stiffness": q.delta * self.k1}


def rod_polar_inertia_kgm2(q) -> float:
    """J_rod = rho I_p L0 = (beta / delta) M L0^2 [kg m^2] (Eq. 27), M = Mg / g, g = L0/t_s^2."""
    M = q.force_scale * q.t_scale**2 / q.L0
    return q.beta / q.delta * M * q.L0**2


@dataclass
class RelativeEquilibrium:
    """An operating point as the linearisation takes it: the rod's state U (normalised,
    the stationary state under the operating torques), the spin Omega [rad/s] and the
    end components' :class:`EndLoads` there."""

    state: RodState
    spin_rad_s: float
    loads: EndLoads

    def __post_init__(self):
        if not math.isfinite(self.spin_rad_s):
            raise ParameterError("operating point spin_rad_s", self.spin_rad_s, "must be finite")


class SpinModalSolver(ModalSolver):
    """:class:`ModalSolver` with the end components' terms, about a relative equilibrium."""

    def __init__(self, params: Parameters, comm=MPI.COMM_WORLD, scene: str = "scene",
                 rod: RodDiscretisation | None = None):
        rod = rod if rod is not None else RodDiscretisation(params, comm)
        self.end_loads = EndLoadForms(
            rod.model, rod.mesh, lambda v: dolfinx.fem.Constant(rod.mesh, PETSc.ScalarType(v)))
        super().__init__(params, comm, scene, rod, ends=self.end_loads)

    def is_rigid_rotation(self, fractions: dict) -> bool:
        """With damping at the ends the free angle's zero is a simple eigenvalue next to
        the rigid shaft's real root (Q' - tau') / J, and SLEPc's vector for it is poor
        (backward errors 1e-3 to 7e-2 measured on rotor_example, N = 4; its twist's energy
        fraction 0.05 to 0.99): the check is on the rigid rotation itself, a uniform
        twist e, which must still be a null vector of K (no ground stiffness k1)."""
        K = self.K
        e = K.createVecRight()
        e.set(0.0)
        e.array[self._owned_twist()] = 1.0
        y = K.createVecLeft()
        K.mult(e, y)
        return y.norm(PETSc.NormType.INFINITY) <= NULL_TOL * K.norm(PETSc.NormType.INFINITY)

    def _owned_twist(self):
        n = self.K.getLocalSize()[1]
        twist = self.rod.dofs("twist")
        return twist[twist < n]

    def linearise_at(self, point: RelativeEquilibrium):
        """K, C, M about ``point`` (module docstring)."""
        self.end_loads.set(point.loads.normalised(self.q))
        return self.linearise(point.state, spin=point.spin_rad_s * self.q.t_scale)

    def max_real_part(self, modes: list[Mode]) -> float:
        """max Re lambda of ``modes`` [1/s]."""
        return max(m.eigenvalue.real for m in modes) / self.q.t_scale

    def stable(self, modes: list[Mode]) -> bool:
        """No mode grows: Re lambda <= STABILITY_TOL + STABILITY_REL_TOL |lambda| for every
        mode (normalised)."""
        return all(m.eigenvalue.real <= STABILITY_TOL + STABILITY_REL_TOL * abs(m.eigenvalue)
                   for m in modes)


def static_modal_solver(params: Parameters, comm=MPI.COMM_WORLD, scene: str = "scene"
                        ) -> ModalSolver:
    """``modes``' solver about the torque-free stationary state: with a scene's
    ``[rotor]``, its spin inertia lumped at the top's twist (the limit Omega -> 0 of the
    linearisation about an operating point); the plain :class:`ModalSolver` otherwise."""
    J = params.rotor.spin_inertia_kgm2 if params.rotor.active else 0.0
    if J == 0.0:
        return ModalSolver.from_stationary(params, comm, scene=scene)
    solver = SpinModalSolver.from_stationary(params, comm, scene=scene)
    solver.linearise_at(RelativeEquilibrium(solver.stationary_result.state, 0.0,
                                            EndLoads(rotor_inertia_kgm2=J)))
    return solver


def frequency_Hz(mode: Mode, q) -> float:
    """|Im lambda| / (2 pi t_scale)."""
    return abs(mode.eigenvalue.imag) / (2 * math.pi * q.t_scale)


def damping_ratio(mode: Mode) -> float:
    """zeta = -Re lambda / |lambda| (1 for a decaying real root, < 0 growing)."""
    lam = mode.eigenvalue
    return -lam.real / abs(lam) if lam != 0 else 0.0


def stability(point: RelativeEquilibrium, solver: SpinModalSolver, per_family: int = 2
              ) -> tuple[bool, float]:
    """(stable, max_real_part [1/s]) of ``point`` on ``solver``'s rod: the lowest
    ``per_family`` modes of each family and the slow real roots around them (the
    rigid shaft's (Q' - tau') / J among them)."""
    solver.linearise_at(point)
    modes = solver.solve(per_family=per_family, keep_vectors=False, require_families=False)
    return solver.stable(modes), solver.max_real_part(modes)


def stability_at(stationary, state: RodState, omega_rad_s: float, loads: EndLoads,
                 per_family: int = 2) -> tuple[bool, float]:
    """:func:`stability` of the relative equilibrium a StationarySolver ``stationary`` has
    just solved (``state``: its result's, under the operating torque) at the spin
    ``omega_rad_s`` [rad/s] with the end ``loads`` (:meth:`EndLoads.of_laws`): the modal
    solver is built on the stationary solver's rod."""
    solver = SpinModalSolver(stationary.params, stationary.rod.comm, stationary.scene,
                             rod=stationary.rod)
    return stability(RelativeEquilibrium(state, omega_rad_s, loads), solver, per_family)
