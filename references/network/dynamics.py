"""The network in time: the rigid rings' equations of motion, integrated by the
symplectic Strang splitting of their Hamiltonian ("kick-drift-kick", the rigid-body
leapfrog of Dullweber, Leimkuhler and McLachlan 1997), with the free flight exact.

Each interior ring carries its centre x, velocity v, rotation R and spatial angular
momentum L.  A step of h from t:

1. *kick* h/2: v += (h/2) F / m, L += (h/2) T, with F, T = -dE/dq (:func:`.energy.gradient`:
   the tethers, the bars, gravity) plus the drag's change from rest;
2. *drift* h: the free flight of every ring, exact: x += h v and, a ring being a
   symmetric top (diag(Jd, Jd, Jp)), R <- exp(h [L]x / Jd) R exp(h c [e3]x) with
   c = Pi_3 (1 / Jp - 1 / Jd), Pi_3 = e3 . R^T L (its body spin, constant in flight);
3. *kick* h/2 at x(t + h), implicit in the velocities where the force depends on them
   (the drag, the controller's k2): Newton on each ring's 3 (or 1) unknowns.

Why this scheme: it is explicit (one gradient per step, no Newton on the whole
network, no Hessian), second order and time-symmetric (the explicit and the implicit
half-kicks are each other's adjoints), and, without drag, symplectic: its energy
error stays bounded, O(h^2), over any time (backward error analysis), where an
implicit midpoint or Newmark on SO(3) conserves it only approximately and costs a
Newton per step.  Its price is the stability bound h < 2 / omega_max
(:func:`stable_step`), set by a bay's axial and tilt modes: about l / 1000 s for the
paper's tethers (0.94 ms at 17 rings of Table 2), below what the accuracy of the
slow dynamics needs, but a step costs one gradient (0.7-1.2 ms of numpy at 5-17 rings).

The ends (:class:`Drive`): the ground ring's centre held, its turn about the chord
held or driven by the controller of Eq. (40), m_0 = m_N(t) + k1 (theta_0 - alpha*
t) + k2 theta_0' (SI: the normalised gains times GJ / L0 and t_scale); the top ring's
centre held or on the circle of Eq. (70), its turn held or driven by the torque ramp
of Eq. (69).  A driven end ring turns about the chord only (one dof: its spin).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Callable

import numpy as np
import scipy.linalg as sla
from scipy.spatial.transform import Rotation

from rawehelix.references.network import energy as en
from rawehelix.references.network import machine
from rawehelix.operation.generator import RELEASE_RAMP_S
from rawehelix.references.network.network import Network, NetworkError

#: the step as a share of the stability bound 2 / omega_max (:func:`stable_step`)
STABILITY_SHARE = 0.5
#: the implicit half-kick's Newton on each ring's velocity: relative tolerance, iterations
KICK_TOL, KICK_ITERATIONS = 1e-13, 20


@dataclass(frozen=True)
class Controller:
    """The ground torque of Eq. (40), SI: m_0 = m_N(t) + k1 (theta_0 - target t)
    + k2 theta_0' + offset."""

    k1_Nm: float  # [N m / rad]
    k2_Nms: float  # [N m s / rad]
    target_rad_s: float  # alpha* [rad/s]
    offset_Nm: float = 0.0  # C [N m]

    def __post_init__(self):
        if not (self.k1_Nm >= 0 and self.k2_Nms >= 0 and math.isfinite(self.target_rad_s)):
            raise ValueError(f"Controller: gains >= 0 and a finite target, not {self}")

    def torque_Nm(self, theta: float, spin: float, t: float, top_Nm: float) -> float:
        return top_Nm + self.k1_Nm * (theta - self.target_rad_s * t) + self.k2_Nms * spin \
            + self.offset_Nm


@dataclass(frozen=True)
class Drive:
    """The ends in time (SI).  None: held (the stationary state's)."""

    top_position: Callable[[float], np.ndarray] | None = None  # the top ring's centre [m]
    top_velocity: Callable[[float], np.ndarray] | None = None  # its velocity [m/s]
    top_torque: Callable[[float], float] | None = None  # M_N(t) about the chord [N m]
    controller: Controller | None = None  # the ground's turn by Eq. (40)
    rotor: machine.RotorEnd | None = None  # Q(Omega, t) and J on the top ring (machine.py)
    generator: machine.GeneratorEnd | None = None  # tau(Omega) on the ground ring
    #: t [s] -> the wind at the rings (rings, 3) [m/s], a history; None: the network's steady one
    wind: Callable[[float], np.ndarray] | None = None

    def __post_init__(self):
        if (self.top_position is None) != (self.top_velocity is None):
            raise ValueError("Drive: give the top's position and velocity together")

    @classmethod
    def from_parameters(cls, params, f1_Hz: float | None = None, t_start_s: float = 0.0) -> "Drive":
        """A scene's ends as the FE runs them: the torque ramp of Eq. (69) at the top,
        the controller of Eq. (40) at the ground when it is active (else the ground's
        turn held), the top on the circle of Eq. (70) when it moves (at ``f1_Hz``
        when given, at phase 0 at ``t_start_s``, as a sweep restarts it); the rotor
        and the generator where the scene has them, and its wind in time (machine.py)."""
        q = params.normalised()
        if f1_Hz is not None:
            q = q.at_frequency(f1_Hz, t_start_s / q.t_scale)
        L0, ts, Mt = q.L0, q.t_scale, q.torque_scale  # [m], [s], GJ / L0 [N m]
        top = {}
        if q.moving_end:
            top = {"top_position": lambda t: L0 * q.top_position(t / ts),
                   "top_velocity": lambda t: L0 / ts * q.top_velocity(t / ts)}
        ctl = params.controller
        controller = (Controller(ctl.k1 * Mt, ctl.k2 * Mt * ts, q.spin_target / ts)
                      if ctl.active else None)
        heights = np.linspace(0.0, -L0 * q.top_position(0.0)[2],
                              params.model.section.ring_count(L0))  # the rings' z [m], up
        return cls(top_torque=lambda t: Mt * q.top_torque(t / ts), controller=controller,
                   wind=machine.wind_of(params, heights), **machine.ends_of(params), **top)


@dataclass
class Motion:
    """The network's state in time (SI): the rings' configuration (``state``: centres,
    rotations, the top's accumulated turn), velocities V (rings, 3) [m/s], the interior
    rings' spatial angular momenta L (rings, 3) [kg m^2/s] (the end rows unused), and
    the end rings' spins about the chord [rad/s] and the ground's turn [rad]."""

    t: float
    state: en.State
    V: np.ndarray
    L: np.ndarray
    ground_turn: float = 0.0
    ground_spin: float = 0.0
    top_spin: float = 0.0

    def copy(self) -> "Motion":
        return Motion(self.t, self.state.copy(), self.V.copy(), self.L.copy(),
                      self.ground_turn, self.ground_spin, self.top_spin)


def _rotations(w: np.ndarray) -> np.ndarray:
    """exp([w]x) of (k, 3) rotation vectors, (k, 3, 3)."""
    return Rotation.from_rotvec(w).as_matrix()


class Integrator:
    """The splitting of the module docstring for a network (its own end torque
    ignored: the drive's is used) from a start state at rest or moving."""

    def __init__(self, net: Network, drive: Drive, dt_s: float):
        if not (dt_s > 0 and math.isfinite(dt_s)):
            raise ValueError(f"Integrator: dt_s = {dt_s!r} must be > 0")
        self.net = dataclasses.replace(net, end_torque_Nm=None)  # the drive's torque instead
        self.drive, self.dt = drive, dt_s
        m, J = net.mass_matrix_blocks(np.broadcast_to(np.eye(3), (net.count, 3, 3)))
        self.m = m  # [kg]
        self.Jd = J[:, 0, 0]  # diametral [kg m^2]
        self.Jp = J[:, 2, 2].copy()  # polar [kg m^2]
        if drive.rotor is not None:
            self.Jp[-1] += drive.rotor.inertia_kgm2  # the rotor spins with the top ring
        self.e3 = net.frame[:, 2]
        self.drag0 = self._drag(np.zeros((net.count, 3)), None)  # in the dead loads already
        self.top_turns = drive.top_torque is not None or drive.rotor is not None
        self.ground_turns = drive.controller is not None or drive.generator is not None
        self.released_at = None  # a generator's release [s] (machine.py), None before it
        self.steps = 0
        self._g = None  # (motion, t, forces) at its configuration: one gradient per step

    # -- forces ------------------------------------------------------------------
    def _air(self, t: float | None) -> np.ndarray:
        """The wind at the rings at t [s] (the drive's history), or the network's steady one."""
        w = self.net.wind_m_s if t is None or self.drive.wind is None else self.drive.wind(t)
        return np.broadcast_to(w, (self.net.count, 3))

    def _drag(self, V: np.ndarray, t: float | None) -> np.ndarray:
        """-c |v_A| v_A (rings, 3) [N], v_A = V - wind at t (Eq. 28; None: the steady one)."""
        if self.net.drag_kg_m is None:
            return np.zeros_like(V)
        vA = V - self._air(t)
        return -self.net.drag_kg_m[:, None] * np.linalg.norm(vA, axis=1)[:, None] * vA

    def _forces(self, s: en.State):
        """(F (rings, 3) [N], T (rings, 3) [N m]): -dE/dq of the conservative forces."""
        g = en.gradient(self.net, s).reshape(self.net.count, en.DOFS)
        return -g[:, :3], -g[:, 3:]

    def spin(self, mo: Motion) -> np.ndarray:
        """Every ring's spin about its own axis R e3 [rad/s] (the ends': about the chord)."""
        R, L = mo.state.R, mo.L
        Pi = np.einsum("rji,rj->ri", R, L)  # R^T L
        omega_body = Pi / np.column_stack([self.Jd, self.Jd, self.Jp])
        out = omega_body[:, 2].copy()
        out[0], out[-1] = mo.ground_spin, mo.top_spin
        return out

    def ground_torque_Nm(self, mo: Motion) -> float:
        """The torque held at the ground about the chord [N m]: the controller's, or
        (its turn held) the tethers' moment on the ground ring."""
        d = self.drive
        if d.generator is not None:
            return self._engaged(mo.t) * d.generator.torque(mo.ground_spin)[0]
        if d.controller is None:
            return float(self._forces(mo.state)[1][0] @ self.e3)
        return d.controller.torque_Nm(mo.ground_turn, mo.ground_spin, mo.t, self._top(mo.t))

    def _top(self, t: float) -> float:
        return 0.0 if self.drive.top_torque is None else self.drive.top_torque(t)

    def _engaged(self, t: float) -> float:
        """The generator's share 0..1: 1 without a release speed, else 0 until the
        ground first spins at it and a linear ramp over RELEASE_RAMP_S after."""
        g = self.drive.generator
        if g is None or g.release_rad_s is None:
            return 1.0
        if self.released_at is None:
            return 0.0
        return float(np.clip((t - self.released_at) / RELEASE_RAMP_S, 0.0, 1.0))

    # -- the splitting -----------------------------------------------------------
    def _kick(self, mo: Motion, h: float, implicit: bool):
        """v, L and the ends' spins by h with the forces at mo's configuration; the
        velocity-dependent ones at the start (explicit) or the end (implicit)."""
        if self._g is None or self._g[0] is not mo or self._g[1] != mo.t:
            self._g = (mo, mo.t, self._forces(mo.state))  # the next step's first kick reuses it
        F, T = self._g[2]
        inner = slice(1, self.net.count - 1)
        m = self.m[inner, None]
        V = mo.V[inner] + h * (F[inner] + self._drag(mo.V, mo.t)[inner] - self.drag0[inner]) / m
        if implicit:  # Newton from the explicit kick
            V = self._implicit_drag(mo.V[inner], F[inner], h, V, mo.t)
        mo.V[inner] = V
        mo.L[inner] += h * T[inner]
        rotor, generator, t = self.drive.rotor, self.drive.generator, mo.t
        if rotor is not None:  # Q(Omega) at the top's spin (machine.py), Eq. (39)
            Tz = T[-1] @ self.e3 + self._top(t)
            mo.top_spin = machine.spin_kick(
                mo.top_spin, self.Jp[-1], h,
                lambda s: (lambda q: (Tz + q[0], q[1]))(rotor.torque(s, t)), implicit)
        elif self.drive.top_torque is not None:
            mo.top_spin += h * (T[-1] @ self.e3 + self._top(mo.t)) / self.Jp[-1]
        if generator is not None:  # tau(Omega) at the ground's spin, Eq. (38)
            Tz, e = T[0] @ self.e3, self._engaged(t)
            mo.ground_spin = machine.spin_kick(
                mo.ground_spin, self.Jp[0], h,
                lambda s: (lambda g: (Tz - e * g[0], -e * g[1]))(generator.torque(s)), implicit)
        c = self.drive.controller if generator is None else None  # the generator's instead
        if c is not None:
            t, J, Tz = mo.t, self.Jp[0], T[0] @ self.e3
            rest = Tz - c.torque_Nm(mo.ground_turn, 0.0, t, self._top(t))  # less k2 spin
            if implicit:
                mo.ground_spin = (mo.ground_spin + h * rest / J) / (1 + h * c.k2_Nms / J)
            else:
                mo.ground_spin += h * (rest - c.k2_Nms * mo.ground_spin) / J

    def _implicit_drag(self, V0, F, h, V, t):
        """V = V0 + h (F + D(V) - D(0)) / m on the interior rings, Newton from V."""
        net = self.net
        if net.drag_kg_m is None or not np.any(net.drag_kg_m):
            return V
        inner = slice(1, net.count - 1)
        c, m = net.drag_kg_m[inner, None], self.m[inner, None]
        air = self._air(t)[inner]
        for _ in range(KICK_ITERATIONS):
            vA = V - air
            a = np.linalg.norm(vA, axis=1)[:, None]
            r = V - V0 - h * (F - c * a * vA - self.drag0[inner]) / m
            # dD/dV = -c (|v_A| I + v_A v_A^T / |v_A|)
            Jac = np.eye(3) + (h * c / m)[:, :, None] * (
                a[:, :, None] * np.eye(3)
                + vA[:, :, None] * vA[:, None, :] / np.maximum(a, 1e-300)[:, :, None])
            dV = np.linalg.solve(Jac, r[..., None])[..., 0]
            V = V - dV
            if np.max(np.abs(dV)) <= KICK_TOL * (1.0 + np.max(np.abs(V))):
                return V
        raise NetworkError("the network's drag half-step did not converge: the step is too "
                           "large for the drag; lower time.dt_s")

    def _drift(self, mo: Motion, h: float):
        """Every ring's free flight over h, exact (module docstring)."""
        s, net = mo.state, self.net
        inner = slice(1, net.count - 1)
        s.X[inner] += h * mo.V[inner]
        R, L = s.R[inner], mo.L[inner]
        Pi3 = np.einsum("ri,ri->r", R[:, :, 2], L)  # e3 . R^T L
        c = Pi3 * (1 / self.Jp[inner] - 1 / self.Jd[inner])
        body = _rotations(np.outer(h * c, [0.0, 0.0, 1.0]))
        s.R[inner] = _rotations(h * L / self.Jd[inner, None]) @ R @ body
        if self.top_turns:
            s.R[-1] = _rotations((h * mo.top_spin * self.e3)[None])[0] @ s.R[-1]
            s.theta += h * mo.top_spin
        if self.ground_turns:
            s.R[0] = _rotations((h * mo.ground_spin * self.e3)[None])[0] @ s.R[0]
            mo.ground_turn += h * mo.ground_spin
        mo.t += h
        if self.drive.top_position is not None:
            s.X[-1] = self.drive.top_position(mo.t)
            mo.V[-1] = self.drive.top_velocity(mo.t)

    def step(self, mo: Motion, h: float | None = None) -> Motion:
        """One step of h (default dt_s) in place; returns mo."""
        h = self.dt if h is None else h
        with np.errstate(all="ignore"):  # a diverging motion is caught below
            self._kick(mo, h / 2, implicit=False)
            self._drift(mo, h)
            self._kick(mo, h / 2, implicit=True)
        self.steps += 1
        g = self.drive.generator
        if (g is not None and g.release_rad_s is not None and self.released_at is None
                and mo.ground_spin >= g.release_rad_s):
            self.released_at = mo.t
        if not (np.all(np.isfinite(mo.state.X)) and np.all(np.isfinite(mo.L))):
            raise NetworkError(
                f"the network's motion diverged at t = {mo.t:.4g} s (step {self.steps}): the "
                f"step {h:.3g} s is past the stability bound of its stiffest bay; lower "
                "time.dt_s")
        return mo

    def advance(self, mo: Motion, until_s: float, every_s: float,
                on_output: Callable[[Motion], None] | None = None) -> Motion:
        """Steps to ``until_s``, landing on every multiple of ``every_s`` (the last step
        before each cut to land), calling ``on_output(mo)`` at the start and there."""
        if on_output is not None:
            on_output(mo)
        while mo.t < until_s * (1 - 1e-12):
            target = min(round(mo.t / every_s) * every_s + every_s, until_s)
            if target <= mo.t * (1 + 1e-12):
                target += every_s
            n = max(1, math.ceil((target - mo.t) / self.dt * (1 - 1e-12)))
            h = (target - mo.t) / n
            for _ in range(n):
                self.step(mo, h)
            if on_output is not None:
                on_output(mo)
        return mo

    # -- energy --------------------------------------------------------------------
    def kinetic_J(self, mo: Motion) -> float:
        """The rings' kinetic energy [J] (the top ring's own motion included)."""
        inner = slice(1, self.net.count - 1)
        Pi = np.einsum("rji,rj->ri", mo.state.R[inner], mo.L[inner])
        Jb = np.column_stack([self.Jd, self.Jd, self.Jp])[inner]
        return float(0.5 * np.sum(self.m[:, None] * mo.V ** 2) + 0.5 * np.sum(Pi * Pi / Jb)
                     + 0.5 * self.Jp[0] * mo.ground_spin ** 2
                     + 0.5 * self.Jp[-1] * mo.top_spin ** 2)

    def total_energy_J(self, mo: Motion) -> float:
        """Kinetic plus potential (:func:`.energy.energy`: strain, gravity, drag at rest) [J]."""
        return self.kinetic_J(mo) + en.energy(self.net, mo.state)

    def drag_power_W(self, mo: Motion) -> float:
        """The drag's power beyond its value at rest (which the potential holds) [W]."""
        return float(np.sum((self._drag(mo.V, mo.t) - self.drag0)[1:-1] * mo.V[1:-1]))


def bay_tension_N(net: Network, s: en.State, bay: int = 0) -> float:
    """A bay's axial force [N] (0: at the ground, -1: at the top): its tethers' and bar's
    forces along the line of its ring centres (the continuum's T there)."""
    b = bay % (net.count - 1)
    d = en.tether_chords(net, s)[2][b]
    ub = s.X[b + 1] - s.X[b]
    ub = ub / np.linalg.norm(ub)
    u = d / np.linalg.norm(d, axis=-1)[:, None]
    return float(en.tether_forces(net, s)[b] @ (u @ ub) + en.bar_forces(net, s)[b])


def at_rest(start: en.State, t: float = 0.0, drive: Drive | None = None) -> Motion:
    """A motion from a configuration at rest (the top on its circle moving with it)."""
    n = len(start.X)
    mo = Motion(t, start.copy(), np.zeros((n, 3)), np.zeros((n, 3)))
    if drive is not None and drive.top_position is not None:
        mo.state.X[-1] = drive.top_position(t)
        mo.V[-1] = drive.top_velocity(t)
    return mo


def stable_step(net: Network, state: en.State) -> float:
    """The stability bound 2 / omega_max [s] of the splitting at ``state``: omega_max
    the largest frequency of the linearisation (every interior ring's 6 dofs and the
    end rings' turns; dense eigvalsh)."""
    _, H = en.gradient_hessian(dataclasses.replace(net, end_torque_Nm=0.0), state)
    N = net.count
    keep = list(range(en.DOFS, en.DOFS * (N - 1)))
    e3 = net.frame[:, 2]
    E = np.zeros((en.DOFS * N, len(keep) + 2))
    E[keep, np.arange(len(keep))] = 1.0
    E[3:6, -2] = e3
    E[en.DOFS * (N - 1) + 3:, -1] = e3
    K = E.T @ H.toarray() @ E
    m, J = net.mass_matrix_blocks(state.R)
    M = sla.block_diag(*[sla.block_diag(mi * np.eye(3), Ji) for mi, Ji in zip(m, J)])
    Mf = E.T @ M @ E
    lam = sla.eigvalsh(K, Mf, subset_by_index=[len(K) - 1, len(K) - 1])[0]
    return 2.0 / math.sqrt(max(lam, 1e-300))


def default_step(net: Network, state: en.State, dt_s: float | None = None) -> float:
    """STABILITY_SHARE of :func:`stable_step`, or ``dt_s`` when smaller [s]."""
    h = STABILITY_SHARE * stable_step(net, state)
    return h if dt_s is None else min(h, dt_s)
