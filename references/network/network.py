"""The helix as a network: rigid rings joined by straight tension-only tethers (SI).

**Rings.**  ``rings`` rigid bodies along the chord, both end rings included, at the
unstretched spacing l = L0 / (rings - 1) (``section.rings``, or
``section.ring_spacing_m`` rounded to the nearest whole number of bays).  Each ring
has 6 dofs: its centre x_i and a rotation R_i in SO(3).  The rotation is stored as a
matrix and moved by the exponential map, R_i <- exp([w_i]x) R_i, with w_i the
increment's rotation vector in the fixed frame (:mod:`.energy`): a chart about the
current rotation, so no parametrisation singularity whatever the rings' rotation
(a twist to Tulloch's collapse is ~90 deg per bay), the Hessian in w at w = 0 is the
energy's exact second derivative (exp([w]x) p = p + w x p + w x (w x p) / 2 + O(w^3))
and symmetric, and at the small rotations of the modes w is the rotation itself.

Ring i's reference frame is the chord's, (e1, e2, e3) with e3 along the chord from the
ground to the top and e2 = j_E, turned about e3 by i delta_0: the lay, delta_0 = l
tan(beta) / R (members.py::Members.ring_twist at tau = 0).  Its attachment points are
rho_m = R (cos phi_m, sin phi_m, 0) in its frame, phi_m = 2 pi m / n.

**Tethers.**  Tether m of bay b joins point m of ring b to point m of ring b + 1: a
straight chord of unstretched-helix length l_t = sqrt(l^2 + (2 R sin(delta_0/2))^2)
(-> l / cos(beta) as l -> 0), its force k (L - l_0) / l_0 when taut and 0 when slack,
k = section.tether_EA_N (or the k of members.py whose taut section has helix.EA_N),
l_0 = l_t / (1 + P0 / k): the self-stress P0 sets the rest length.  The **bars**
(section.bar_EA_N > 0) join adjacent ring centres, elastic in tension and
compression, their rest length such that each bar balances its bay's self-stress
(EA_b (l - l_b0) / l_b0 = -n P0 l / l_t).

**Masses.**  Ring mass section.ring_mass_kg, default the helix's mass lumped at the
rings (M / (rings - 1), the end rings half); polar and diametral inertias
section.ring_polar_inertia_kgm2 and section.ring_diametral_inertia_kgm2, default a
hoop's, m R^2 and m R^2 / 2.  The tethers are massless.

**Loads.**  Gravity m g k_E on each ring, and the drag of Eq. (14) at rest,
-(rho_0 l_a C_D / 2) v_w0 |v_w0| i_E per unit length (Eq. 28 with v_A = v_w0 i_E),
a bay's share on its tethers: a uniform dead load along each tether, which is
exactly one on the ring centres (the n attachment points sum to the centre), so
each ring carries l of it (the end rings l / 2).  Both follow the model's
gravity and drag switches.  In time (:mod:`.dynamics`) the drag follows each ring's
velocity, -c_i |v_A| v_A with v_A = v - wind (``drag_kg_m``, ``wind_m_s``).

**Ends** (Eq. 66): the ground ring at 0 in its reference frame; the top ring at the
elongated chord (1 + eps0) L0 (cos Gamma0 (-i_E) + sin Gamma0 (-k_E)) (on the circle of
Eq. (70) at t = 0 when it has one, where every run starts), turned by an optional end
twist about e3; or, with an end torque (torque.top_Nm, the stationary
value of Eq. 69), the top ring's rotation about e3 free and loaded by that torque.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np

from rawehelix.errors import SolverError
from rawehelix.operation import wind
from rawehelix.parameters.checks import ParameterError
from rawehelix.parameters.section import check_network_rings


class NetworkError(SolverError):
    """The network's solve failed; the message says why and what to try."""


@dataclass(frozen=True)
class Ring:
    """One ring's mass [kg] and inertias about its axis and a diameter [kg m^2]."""

    mass_kg: float
    polar_kgm2: float
    diametral_kgm2: float

    def __post_init__(self):
        for name in ("mass_kg", "polar_kgm2", "diametral_kgm2"):
            if not (math.isfinite(getattr(self, name)) and getattr(self, name) > 0):
                raise ValueError(f"Ring.{name} = {getattr(self, name)!r}: must be > 0")


def rotation_about(axis: np.ndarray, angle: float) -> np.ndarray:
    """exp(angle [axis]x), axis a unit vector (Rodrigues)."""
    a = np.asarray(axis, dtype=float)
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K


@dataclass(frozen=True)
class Network:
    """A ring-and-tether network (module docstring); every array SI."""

    n: int  # tethers per bay [-]
    radius_m: float  # R [m]
    k_N: float  # one tether's EA [N]
    l0_m: float  # a tether's rest length [m]
    chord_m: np.ndarray  # the top ring's centre, the ground's at 0 [m]
    lay_rad: float  # delta_0, the rings' reference turn per bay [rad]
    rings: tuple  # Ring of each ring, ground first
    loads_N: np.ndarray  # (rings, 3) dead forces on the ring centres [N]
    bar_EA_N: float = 0.0  # EA_b [N]; 0: no bars
    bar_l0_m: float = 1.0  # a bar's rest length [m]
    end_twist_rad: float = 0.0  # the top ring's turn about e3 beyond the lay [rad]
    end_torque_Nm: float | None = None  # None: top rotation fixed; else its torque about e3 [N m]
    spacing_m: float = field(default=0.0)  # l, the unstretched spacing [m] (information)
    #: each ring's drag c_i [kg/m], its force -c_i |v_A| v_A at the apparent wind
    #: v_A = x_t - wind (Eq. 28 over its length of helix); None: no drag in time
    drag_kg_m: np.ndarray | None = None
    #: the air's velocity at each ring (rings, 3), or one for all (3,) [m/s]
    wind_m_s: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def __post_init__(self):
        if self.n < 3 or len(self.rings) < 2:
            raise ValueError("a network needs n >= 3 tethers and at least 2 rings")
        if not (self.k_N > 0 and self.l0_m > 0 and self.radius_m > 0):
            raise ValueError("k_N, l0_m and radius_m must be > 0")
        if np.shape(self.loads_N) != (len(self.rings), 3):
            raise ValueError("loads_N must be (rings, 3)")

    # -- geometry -------------------------------------------------------------------
    @property
    def count(self) -> int:
        """The rings, both ends included."""
        return len(self.rings)

    @property
    def frame(self) -> np.ndarray:
        """(e1, e2, e3) as columns: e3 along the chord, e2 = j_E (or i_E for a
        vertical chord), e1 = e2 x e3."""
        e3 = self.chord_m / np.linalg.norm(self.chord_m)
        e2 = np.array([0.0, 1.0, 0.0])
        if abs(e2 @ e3) > 0.99:
            e2 = np.array([1.0, 0.0, 0.0])
        e2 = e2 - (e2 @ e3) * e3
        e2 /= np.linalg.norm(e2)
        return np.column_stack([np.cross(e2, e3), e2, e3])

    @functools.cached_property
    def attachments(self) -> np.ndarray:
        """rho_m (n, 3) in a ring's own frame."""
        phi = 2 * np.pi * np.arange(self.n) / self.n
        return self.radius_m * np.column_stack([np.cos(phi), np.sin(phi), 0 * phi])

    def reference(self) -> tuple[np.ndarray, np.ndarray]:
        """(X (rings, 3), R (rings, 3, 3)): the straight elongated chord, each ring in
        its reference frame, the top one turned by the end twist; Newton's first guess."""
        N, E = self.count, self.frame
        X = np.outer(np.linspace(0.0, 1.0, N), self.chord_m)
        R = np.array([E @ rotation_about([0, 0, 1], i * self.lay_rad) for i in range(N)])
        R[-1] = rotation_about(E[:, 2], self.end_twist_rad) @ R[-1]
        return X, R

    def mass_matrix_blocks(self, R: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(m_i (rings,), J_i (rings, 3, 3)): each ring's mass and its inertia tensor in
        the fixed frame at rotation R_i, R_i diag(Jd, Jd, Jp) R_i^T."""
        m = np.array([r.mass_kg for r in self.rings])
        body = np.array([np.diag([r.diametral_kgm2, r.diametral_kgm2, r.polar_kgm2])
                         for r in self.rings])
        return m, np.einsum("rij,rjk,rlk->ril", R, body, R)

    # -- construction ---------------------------------------------------------------
    @classmethod
    def from_parameters(cls, params, rings: int | None = None, end_twist_rad: float = 0.0,
                        end_torque_Nm: float | None = None) -> "Network":
        """The network of a scene (``params``: :class:`rawehelix.parameters.Parameters`)
        with its ``[section]``'s rings (``rings`` overrides them); the end torque is
        the scene's torque.top_Nm when nonzero, unless ``end_torque_Nm`` is given."""
        h, sec, env, ends, model = (params.helix, params.model.section, params.environment,
                                    params.ends, params.model)
        N = rings if rings is not None else sec.ring_count(h.length_m)
        check_network_rings(sec, h, N)  # the lay alone would collapse its bays
        if ends.elongation is None:
            raise ParameterError("ends.tension_N", ends.tension_N,
                                 "--scheme network needs ends.elongation (the chord's stretch)")
        members = sec.members(h)  # k: the section's, or the one whose taut EA is helix.EA_N
        n, R, k, P0 = members.n, members.R, members.k, members.P0
        L0 = h.length_m
        l = L0 / (N - 1)  # the unstretched spacing [m]
        lay = l * math.tan(members.beta) / R  # delta_0 [rad]
        l_t = math.hypot(l, 2 * R * math.sin(lay / 2))  # a tether's chord [m]
        bar_EA, bar_l0 = members.EA_b, l
        if bar_EA > 0:
            bar_l0 = l / (1 - n * P0 * (l / l_t) / bar_EA)  # balances the self-stress
        # Eq. (66), z down, on the circle of Eq. (70) at t = 0 as every run starts
        chord = L0 * np.asarray(params.normalised().top_position(0.0), dtype=float)
        share = np.full(N, l)  # each ring's length of helix [m]
        share[[0, -1]] = l / 2
        M_ring = sec.ring_mass_kg
        masses = M_ring * np.ones(N) if M_ring is not None else h.mass_kg * share / L0
        ring_list = tuple(Ring(m, sec.ring_polar_inertia_kgm2 or m * R * R,
                               sec.ring_diametral_inertia_kgm2 or m * R * R / 2) for m in masses)
        g = env.g_m_s2 * float(model.gravity)
        c = float(model.drag) * env.air_density_kg_m3 * h.drag_length_m * h.drag_coefficient / 2
        # the wind at each ring's height on the straight chord (z up = -k_E): the scene's
        # [wind] profile at t = 0, else environment.wind_speed_m_s (operation/wind.py)
        V = np.asarray(wind.from_params(params).speed_at(np.linspace(0.0, -chord[2], N)), float)
        V = np.broadcast_to(V, (N,))
        q = c * V * np.abs(V)  # Eq. (14) [N/m], along -i_E
        loads = np.outer(masses * g, [0.0, 0.0, 1.0]) + np.outer(share * q, [-1.0, 0.0, 0.0])
        if end_torque_Nm is None and params.torque.top_Nm != 0:
            end_torque_Nm = params.torque.top_Nm
        return cls(n=n, radius_m=R, k_N=k, l0_m=l_t / (1 + P0 / k), chord_m=chord, lay_rad=lay,
                   rings=ring_list, loads_N=loads, bar_EA_N=bar_EA, bar_l0_m=bar_l0,
                   end_twist_rad=end_twist_rad, end_torque_Nm=end_torque_Nm, spacing_m=l,
                   drag_kg_m=c * share, wind_m_s=np.outer(-V, [1.0, 0.0, 0.0]))

