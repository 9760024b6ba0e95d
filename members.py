"""The tensegrity's members: their strains from the rod's strains, their forces, the
section's resultants and the structure's limits.  Pure numpy: the one definition of
the member law and of every limit criterion (issue 29).

The section (a scene's ``[section]``, parameters/section.py) is a ring of ``n``
tethers at radius R, evenly spaced, each laid at the angle beta to the axis (the
same hand: a TRPT's rings are turned by delta_0 = l tan(beta) / R against each
other), with axial stiffness k = EA of one tether [N], a self-stress P0 [N] (the
tethers' tension at zero rod strain, balanced by bars on the axis of stiffness
EA_b) and, optionally, a breaking force F_b.

**Kinematics.**  The rod's strains are the stretch eps = |r'| - 1, the curvature
kappa >= 0 (per unstretched length, in the bending plane) and the twist tau
[rad/m].  A tether at the angle phi from the bending plane's inner side follows,
per unit rod length, the axial stretch 1 + eps - R kappa cos(phi) and the
tangential advance R tau + tan(beta); its strain against its length at zero rod
strain, 1 / cos(beta) per unit rod length, is

    e(phi) = cos(beta) sqrt((1 + eps - R kappa cos phi)^2 + (R tau + tan beta)^2) - 1 + e0,

e0 = P0 / k.  The members are taken at phi_m = 2 pi m / n + psi, psi the ring's phase
against the bending plane: psi = 0 (the default, ``[section] ring = "worst"``) puts a
member on the bending plane (the phase at which the first member slackens soonest,
and the largest member force is largest; :func:`phase_spread` measures the other
phases); with ``ring = "turning"`` psi follows the directors (forms/section_law.py).

**The law.**  A tether carries tension only: its force is k <e>_w, the smooth
positive part <e>_w = (e + sqrt(e^2 + w^2)) / 2 of width w (the slack width, a
strain; <e>_0 = max(e, 0)).  Its energy per unit rod length is
(k / cos beta) Phi_w(e), Phi_w' = <.>_w (:func:`ramp_energy`), convex and
nondecreasing; e is convex in (eps, kappa, tau) (a norm of an affine map, less a
constant) where the axial stretch is positive, so the section's stored energy

    W(eps, kappa, tau) = sum_m (k / cos beta) Phi_w(e_m) + EA_b / 2 (eps + e_b0)^2 + Q_b0 tau

is convex, unlike EI = a T + b (parameters/eilaw.py).  The bars' prestrain e_b0
and torque Q_b0 balance the self-stress: N = Q = 0 at zero strain.  The resultants are its derivatives:
N = dW/d eps, M = dW/d kappa, Q = dW/d tau (:meth:`Members.resultants`).

**Closed forms** (:meth:`Members.taut_moduli`), all members taut, at zero strain
(w = 0, n >= 3): with K = n (k cos^3 beta + P0 cos beta sin^2 beta),
EA = K + EA_b, EI = K R^2 / 2, GJ = n cos(beta) R^2 (k sin^2 beta + P0 cos^2 beta):
the lay's elastic part and the tethers' tension's geometric part (at beta = 0,
GJ = N_t R^2 at the tethers' tension N_t: the torsional stiffness of Tulloch's
(2021) TRPT).  :meth:`Members.tangent` measures them at any state.

**Limits** (:data:`CRITERIA`, checked by :func:`limits`):

* ``slack``: a member's strain e <= 0 (its unregularised force is zero);
* ``breaking``: a member's force >= F_b;
* ``moment_saturation``: |M| >= N R c, c = max_m(-cos phi_m) the members'
  tension-limited moment (all tension on the outermost member);
* ``torsional_collapse``: the twist between adjacent rings, l (tau + tan(beta)/R),
  past the TRPT's critical deformation angle delta_crit (Tulloch 2021, Eq. 4.34,
  for tethers of length l_t between rings of radius R at spacing l; the anchor
  KiteTurbineDynamics.jl uses): the transmitted torque peaks there, and the
  segment runs away past it.

**The fallback** (:class:`ConeSection`, scene ``law = "saturating"``): the solid's EA
and EI inside the cone |M| <= c R N that the members' own resultants never leave.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

# the laws written once for numpy and UFL (section_math.py)
from rawehelix.section_math import Cone, TetherRing, ramp_energy, ring_shear_stiffness, smooth_ramp

#: the limit criteria, in the order of :func:`first_limit`'s ties
CRITERIA = ("slack", "breaking", "moment_saturation", "torsional_collapse")


def critical_twist(R: float, l_t: float) -> float:
    """Tulloch's (2021) critical deformation angle delta_crit [rad] of a TRPT segment
    of equal rings of radius R and tethers of length l_t (Eq. 4.34): cos delta_crit =
    (2 R^2 - l_t^2 + l_t sqrt(l_t^2 - 4 R^2)) / (2 R^2).  inf when l_t < 2 R: the
    lines cannot reach the axis, and no twist limit exists (the rings meet first)."""
    if l_t < 2 * R:
        return math.inf
    c = (2 * R * R - l_t * l_t + l_t * math.sqrt(l_t * l_t - 4 * R * R)) / (2 * R * R)
    return math.acos(max(-1.0, min(1.0, c)))


@dataclass(frozen=True)
class Members:
    """A ring of ``n`` tethers (SI); see the module docstring for each symbol."""

    n: int  # tethers around the section [-]
    R: float  # their radius [m]
    beta: float  # their lay angle to the axis [rad]
    k: float  # the axial stiffness EA of one tether [N]
    P0: float = 0.0  # self-stress: each tether's tension at zero rod strain [N]
    EA_b: float = 0.0  # the bars' axial stiffness, on the axis [N]
    breaking_N: float | None = None  # F_b, a tether's breaking force [N]; None: not set
    ring_spacing_m: float | None = None  # l, between adjacent rings [m]; None: not set
    width: float = 0.0  # w, the slack width (a strain) [-]

    def __post_init__(self):
        if self.n < 3:
            raise ValueError(f"n = {self.n}: a ring needs at least 3 tethers")
        if self.P0 > 0 and self.EA_b <= 0:
            raise ValueError("a self-stress P0 > 0 needs bars (EA_b > 0) to balance it")

    # -- geometry -------------------------------------------------------------------
    @property
    def phi(self) -> np.ndarray:
        """phi_m = 2 pi m / n from the bending plane's inner side."""
        return 2 * np.pi * np.arange(self.n) / self.n

    @property
    def e0(self) -> float:
        """The tethers' prestrain P0 / k."""
        return self.P0 / self.k

    @property
    def e_b0(self) -> float:
        """The bars' prestrain: EA_b e_b0 = -n P0 cos(beta) (N = 0 at zero strain)."""
        return -self.n * self.P0 * math.cos(self.beta) / self.EA_b if self.EA_b > 0 else 0.0

    @property
    def Q_b0(self) -> float:
        """The bars' (rings') torque at zero strain, -n P0 R sin(beta): it balances the
        self-stressed tethers' torque (Q = 0 at zero strain)."""
        return -self.n * self.P0 * self.R * math.sin(self.beta)

    @property
    def saturation(self) -> float:
        """c = max_m(-cos phi_m): the tension-limited moment is c N R."""
        return float(np.max(-np.cos(self.phi)))

    # -- the law ----------------------------------------------------------------------
    def phases(self, psi=0.0) -> np.ndarray:
        """phi_m + psi (..., n): the members' angles from the bending plane's inner side,
        psi the ring's phase (module docstring)."""
        return self.phi + np.asarray(psi, dtype=float)[..., None]

    def law(self) -> TetherRing:
        """The tethers' law in SI numbers (section_math.py::TetherRing, the FE rod's too),
        the twist read."""
        return TetherRing(self.n, self.R, self.beta, self.k, self.e0, self.EA_b, self.e_b0,
                          self.width, torsion=True)

    def _state(self, eps, kappa, tau, psi):
        """(eps, kappa, tau as arrays, the members' bends kappa cos(phi_m + psi), the phases)."""
        eps, kappa, tau = (np.asarray(x, dtype=float) for x in (eps, kappa, tau))
        phases = self.phases(psi)
        return eps, kappa, tau, [kappa * np.cos(phases[..., i]) for i in range(self.n)], phases

    def strains(self, eps, kappa, tau=0.0, psi=0.0):
        """e_m (..., n): each member's strain, slack where <= 0."""
        eps, kappa, tau, bends, _ = self._state(eps, kappa, tau, psi)
        return _members_axis(self.law().member_strains(eps, kappa, tau, bends))

    def forces(self, eps, kappa, tau=0.0, psi=0.0):
        """k <e_m>_w [N], (..., n)."""
        return self.k * smooth_ramp(self.strains(eps, kappa, tau, psi), self.width)

    def energy(self, eps, kappa, tau=0.0, psi=0.0):
        """W [N = J/m]: the members' and the bars' stored energy per unit rod length."""
        eps, kappa, tau, bends, _ = self._state(eps, kappa, tau, psi)
        return self.law().W(eps, kappa, tau, bends)

    def resultants(self, eps, kappa, tau=0.0, psi=0.0) -> dict:
        """N [N], M [N m] (>= 0 for kappa >= 0 at psi = 0), Q [N m]: dW/d(eps, kappa, tau);
        and the ring's torque about the axis from its phase, dW/d psi [N m] (zero at
        psi = 0 by symmetry, and whenever every member is taut and linear)."""
        eps, kappa, tau, bends, phases = self._state(eps, kappa, tau, psi)
        N, M1, M2, Q = self.law().resultants(
            eps, kappa, tau, bends,
            [(np.cos(phases[..., i]), np.sin(phases[..., i])) for i in range(self.n)])
        # dW/d psi: member m's bend kappa cos(phi_m + psi) turns by -kappa sin(...) d psi
        return {"N": N, "M": M1, "Q": Q, "W_psi": -kappa * M2}

    def tangent(self, eps=0.0, kappa=0.0, tau=0.0, h: float = 1e-7) -> dict:
        """The tangent moduli EA = dN/d eps, EI = dM/d kappa, GJ = dQ/d tau at a state
        (central differences of :meth:`resultants`, step h in each strain; kappa's
        step one-sided at kappa = 0, where M is odd in kappa)."""
        def d(i):
            x = [eps, kappa, tau]
            lo, hi = list(x), list(x)
            lo[i] -= h
            hi[i] += h
            key = "NMQ"[i]
            return (self.resultants(*hi)[key] - self.resultants(*lo)[key]) / (2 * h)
        return {"EA": float(d(0)), "EI": float(d(1)), "GJ": float(d(2))}

    def taut_moduli(self) -> dict:
        """The closed forms at zero strain, all taut, w = 0 (module docstring)."""
        cb, sb = math.cos(self.beta), math.sin(self.beta)
        K = self.n * (self.k * cb**3 + self.P0 * cb * sb**2)
        return {"EA": K + self.EA_b, "EI": K * self.R**2 / 2,
                "GJ": self.n * cb * self.R**2 * (self.k * sb**2 + self.P0 * cb**2)}

    def shear_stiffness(self, tether_force_N: float | None = None) -> float:
        """GA [N] of the ring under a shear strain gamma (the section's normal turned by
        gamma from the centre line's tangent, forms/shearable.py), all taut and linear:

            GA = n cos(beta) [k sin^2 beta + f (1 + cos^2 beta)] / 2,

        f each tether's force (default P0).  A shear gamma (along d1) adds to a tether
        at phi the tangential advance -gamma sin(phi) and the radial gamma cos(phi):
        its strain changes by -sin(beta) cos(beta) sin(phi) gamma to first order (the
        lay's elastic share, GJ_el / (2 R^2): a thin tube's shear coefficient 1/2) and
        by cos^2(beta) (1 - sin^2 beta sin^2 phi) gamma^2 / 2 to second order (the
        tension's geometric share); the bars on the axis turn with the section and add
        nothing.  :meth:`sheared_energy` checks it by differences."""
        f = self.P0 if tether_force_N is None else tether_force_N
        return ring_shear_stiffness(self.n, self.beta, self.k, f)

    def sheared_energy(self, gamma, tether_force_N: float | None = None):
        """The tethers' energy per unit length [J/m] at the shear strain gamma (along d1)
        and no other strain, each tether prestrained to the force f (default P0):
        (k / cos beta) Phi(e), e = cos(beta) l - 1 + f / k, l^2 = 1 + (tan(beta) -
        gamma sin phi)^2 + (gamma cos phi)^2 (w = 0)."""
        f = self.P0 if tether_force_N is None else tether_force_N
        gamma = np.asarray(gamma, dtype=float)[..., None]
        b = math.tan(self.beta) - gamma * np.sin(self.phi)
        e = math.cos(self.beta) * np.sqrt(1 + b * b + (gamma * np.cos(self.phi)) ** 2) - 1 + f / self.k
        return (self.k / math.cos(self.beta) * ramp_energy(e, 0.0)).sum(axis=-1)

    def first_slack_curvature(self, eps: float, tau: float = 0.0) -> float:
        """kappa at which the member on the inner side (phi = 0) slackens: e = 0,
        (1 + eps - R kappa)^2 = ((1 - e0) / cos beta)^2 - (R tau + tan beta)^2."""
        b = self.R * tau + math.tan(self.beta)
        a0 = math.sqrt(((1 - self.e0) / math.cos(self.beta)) ** 2 - b * b)
        return (1 + eps - a0) / self.R

    # -- for a solid section: the members' forces under given resultants ------------
    def linear_forces(self, N, M, Q=0.0):
        """The tethers' forces [N] (..., n) that carry N, M, Q in the taut, linear
        law (the diagnostic of a solid section: what a tensegrity would feel):
        P0 + k de_m, with de_m the linearised strain of the strains N / EA, M / EI,
        Q / GJ_el (the lay's share of the torque; 0 at beta = 0)."""
        taut = self.taut_moduli()
        cb, sb = math.cos(self.beta), math.sin(self.beta)
        N, M, Q = (np.asarray(x, dtype=float)[..., None] for x in (N, M, Q))
        eps, kappa = N / taut["EA"], M / taut["EI"]
        GJ_el = self.n * self.k * sb * sb * cb * self.R**2
        tau = Q / GJ_el if GJ_el > 0 else 0 * Q
        de = cb * cb * (eps - self.R * kappa * np.cos(self.phi)) + sb * cb * self.R * tau
        return self.P0 + self.k * de

    # -- limits ---------------------------------------------------------------------
    def critical_twist(self) -> float:
        """delta_crit [rad] between adjacent rings (:func:`critical_twist`), with the
        tethers' length l / cos(beta); inf without a ring spacing."""
        if self.ring_spacing_m is None:
            return math.inf
        return critical_twist(self.R, self.ring_spacing_m / math.cos(self.beta))

    def ring_twist(self, tau):
        """The twist between adjacent rings, l (tau + tan(beta) / R) [rad]; nan without l."""
        if self.ring_spacing_m is None:
            return np.full(np.shape(tau), np.nan)
        return self.ring_spacing_m * (np.asarray(tau, dtype=float) + math.tan(self.beta) / self.R)


def _members_axis(per_member: list) -> np.ndarray:
    """The members' values [x_0, ..., x_n-1] on a last axis (..., n)."""
    return np.stack(np.broadcast_arrays(*per_member), axis=-1)


def phase_spread(members: Members, eps: float, kappa: float, tau: float = 0.0,
                 phases: int = 64) -> dict:
    """How much the fixed phase (a member on the bending plane) matters: the range of
    the moment and of the smallest member force over the bending plane's phase
    relative to the ring, psi in [0, 2 pi / n)."""
    psi = np.linspace(0, 2 * np.pi / members.n, phases, endpoint=False)
    M = members.resultants(eps + 0 * psi, kappa, tau, psi)["M"]
    f_min = members.forces(eps + 0 * psi, kappa, tau, psi).min(axis=-1)
    return {"M": (float(M.min()), float(M.max())), "f_min": (float(f_min.min()), float(f_min.max()))}


@dataclass(frozen=True)
class ConeSection:
    """The fallback law of issue 29 (scene ``law = "saturating"``): the solid's EA and
    EI inside the cone |M| <= c R N, N >= 0 of a tension-only section (c, R from the
    members: :attr:`Members.saturation`, whose own (N, M) lie in that cone).

    W(eps, kappa) is the conjugate of the complementary energy N^2/(2 EA) + M^2/(2 EI)
    restricted to the cone, hence convex; with x = eps + c R |kappa| (the outermost
    member's strain) and v = eps - EI |kappa| / (c R EA) (v >= 0: inside the cone),
    D = 1/EA + c^2 R^2/EI and S = EI + c^2 R^2 EA, it is

        W = x^2 / (2 D) + (c R EA)^2 v^2 / (2 S)      where v >= 0 (= EA eps^2/2 + EI kappa^2/2),
        W = x^2 / (2 D)                               where v < 0 < x (M = c R N: saturated),
        W = 0                                         where x <= 0 (all slack),

    i.e. W = Phi_0(x) / D + (c R EA)^2 Phi_0(v) / S with Phi_0(e) = max(e, 0)^2 / 2.  The
    regularised law takes Phi_w (:func:`ramp_energy`, the members' slack width w, both
    arguments strains): at kappa = 0 the two |kappa| terms' slopes cancel exactly
    (1/D = EA EI / S), so W_w is smooth there; W_w -> W as w -> 0."""

    EA: float  # [N]
    EI: float  # [N m^2]
    R: float  # the members' radius [m]
    c: float = 1.0  # the tension-limited moment is c N R [-]
    width: float = 0.0  # w, the regularisation width (a strain) [-]

    def __post_init__(self):
        for name in ("EA", "EI", "R", "c"):
            if not (np.isfinite(getattr(self, name)) and getattr(self, name) > 0):
                raise ValueError(f"ConeSection.{name} = {getattr(self, name)!r}: must be > 0")
        if self.width < 0:
            raise ValueError(f"ConeSection.width = {self.width!r}: must be >= 0")

    def _law(self) -> Cone:
        return Cone(self.EA, self.EI, self.c * self.R, self.width)

    def energy(self, eps, kappa):
        """W [N = J/m] per unit length (above; :class:`Cone`, the FE rod's law too)."""
        return self._law().W(np.asarray(eps, dtype=float), np.abs(np.asarray(kappa, dtype=float)))

    def resultants(self, eps, kappa) -> dict:
        """N = dW/d eps [N], M = dW/d kappa [N m] (the sign of kappa)."""
        kappa = np.asarray(kappa, dtype=float)
        N, M = self._law().dW(np.asarray(eps, dtype=float), np.abs(kappa))
        return {"N": N, "M": np.sign(kappa) * M}
