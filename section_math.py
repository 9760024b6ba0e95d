"""The section laws' maths, written once for numpy and UFL (issue 42): each law takes a
math namespace ``m`` (:data:`NUMPY` here; forms/section_law.py::UFL_MATH, the same
names in UFL), so the FE rod's stored energy and the numpy law of the limits and the
lab fits are one definition.  The symbols are members.py's (its docstring has the
law); the registry that picks a law by name is section_laws.py.
"""

from __future__ import annotations

import math

import numpy as np


class NumpyMath:
    """The math each law below is written with, once (issue 42): numpy here, UFL in
    forms/section_law.py::UFL_MATH under the same names, so the FE rod's law and the
    limits' law are one definition."""

    sqrt = staticmethod(np.sqrt)
    ln = staticmethod(np.log)
    cos = staticmethod(np.cos)

    @staticmethod
    def array(x):
        return np.asarray(x, dtype=float)

    @staticmethod
    def select_nonneg(x, then, otherwise):
        """then where x >= 0, otherwise elsewhere."""
        return np.where(x >= 0, then, otherwise)

    @staticmethod
    def divisor(x):
        """x > 0 kept off 0 (round-off may zero it; both branches of a select are taken)."""
        return np.maximum(x, 1e-300)

    @staticmethod
    def unregularised(w) -> bool:
        """w = 0: the exact kink, max(e, 0) (numbers only: a UFL width is always > 0)."""
        return w == 0


NUMPY = NumpyMath()


def smooth_ramp(e, w, m=NUMPY):
    """<e>_w = (e + sqrt(e^2 + w^2)) / 2: max(e, 0) for w = 0, smooth for w > 0
    (``m``: the math, :data:`NUMPY` or forms/section_law.py::UFL_MATH)."""
    e = m.array(e)
    return 0.5 * (e + m.sqrt(e * e + w * w))


def ramp_energy(e, w, m=NUMPY):
    """Phi_w(e) = int_0^e <x>_w dx = (e^2 + e sqrt(e^2 + w^2) + w^2 ln((e + sqrt(e^2 + w^2)) / w)) / 4;
    for w = 0, max(e, 0)^2 / 2.  (<x>_w ~ w^2 / (4 |x|) in the slack, so Phi_w falls like
    w^2 ln|e| / 4 there: convex and nondecreasing, its offset from 0 below w^2.)"""
    e = m.array(e)
    if m.unregularised(w):
        return 0.5 * np.maximum(e, 0.0) ** 2
    root = m.sqrt(e * e + w * w)
    # e + root loses digits for e << -w: there it is w^2 / (root - e)
    plus = m.select_nonneg(e, e + root, w * w / m.divisor(root - e))
    return 0.25 * (e * e + e * root + w * w * m.ln(plus / w))


def ring_shear_stiffness(n: int, beta: float, k, f):
    """GA = n cos(beta) [k sin^2 beta + f (1 + cos^2 beta)] / 2 of a ring of n tethers of
    stiffness k at the force f each (members.py::Members.shear_stiffness derives it)."""
    cb, sb = math.cos(beta), math.sin(beta)
    return n * cb * (k * sb * sb + f * (1 + cb * cb)) / 2


class TetherRing:
    """The tethers' law W(eps, kappa, tau) of the module docstring, written once for the
    FE rod (normalised numbers or UFL constants, ``m`` = UFL_MATH: forms/section_law.py)
    and numpy (:data:`NUMPY`): n members at the phases ``phi``, each bending by its
    ``bends`` (kappa cos phi_m unless given), tau read with ``torsion`` only."""

    def __init__(self, n: int, R, beta: float, k, e0, EA_b, e_b0, width, torsion: bool = False,
                 ring_turns: bool = False, m=NUMPY):
        self.n, self.R, self.beta, self.k, self.e0 = n, R, beta, k, e0
        self.EA_b, self.e_b0, self.width, self.torsion = EA_b, e_b0, width, torsion
        self.ring_turns, self.m = ring_turns, m
        # the bars' torque at zero strain, -n P0 R sin(beta) (Members.Q_b0)
        self.Q_b0 = -n * k * e0 * R * math.sin(beta)
        self.phi = [2 * math.pi * i / n for i in range(n)]
        cb, sb = math.cos(beta), math.sin(beta)
        # K R^2 / 2, K = n (k cos^3 beta + P0 cos beta sin^2 beta), P0 = k e0 (closed forms)
        self.taut_bending = n * k * cb * (cb * cb + e0 * sb * sb) * R * R / 2

    def _members(self, eps, kappa, tau=0, bends=None):
        """[(a_m, b, l_m, e_m)] of members.py::Members._stretch and strains."""
        cb, tb = math.cos(self.beta), math.tan(self.beta)
        b = self.R * tau + tb if self.torsion else tb
        bends = [kappa * math.cos(phi) for phi in self.phi] if bends is None else bends
        out = []
        for bend in bends:
            a = 1 + eps - self.R * bend
            l = self.m.sqrt(a * a + b * b) if self.torsion or tb != 0 else a  # a > 0: the stretch
            out.append((a, b, l, cb * l - 1 + self.e0))
        return out

    def member_strains(self, eps, kappa, tau=0, bends=None):
        return [e for *_, e in self._members(eps, kappa, tau, bends)]

    def W(self, eps, kappa, tau=0, bends=None):
        tethers = sum(ramp_energy(e, self.width, self.m)
                      for *_, e in self._members(eps, kappa, tau, bends))
        W = self.k / math.cos(self.beta) * tethers + 0.5 * self.EA_b * (eps + self.e_b0)**2
        return W + self.Q_b0 * tau if self.torsion else W

    def member_forces(self, eps, kappa, tau=0, bends=None):
        """[(f_m a_m / l_m, b / l_m)]: dW/da_m and the members' share of the torque's lever."""
        return [(self.k * smooth_ramp(e, self.width, self.m) * a / l,
                 self.k * smooth_ramp(e, self.width, self.m) * b / l)
                for a, b, l, e in self._members(eps, kappa, tau, bends)]

    def resultants(self, eps, kappa, tau=0, bends=None, phases=None):
        """(N, M1, M2, Q): N = dW/d eps, the moment (M1, M2) = -R sum_m dW/da_m (cos, sin)
        of member m's phase in the members' frame (M1 = dW/d kappa) and Q = dW/d tau;
        ``phases`` [(cos, sin)] per member, phi_m's unless given (a ring's phase psi)."""
        forces = self.member_forces(eps, kappa, tau, bends)
        phases = [(math.cos(p), math.sin(p)) for p in self.phi] if phases is None else phases
        N = self.EA_b * (eps + self.e_b0) + sum(fa for fa, _ in forces)
        M1 = sum(-self.R * c * fa for (c, _), (fa, _) in zip(phases, forces))
        M2 = sum(-self.R * s * fa for (_, s), (fa, _) in zip(phases, forces))
        return N, M1, M2, self.Q_b0 + sum(self.R * fb for _, fb in forces)

    def dW(self, eps, kappa, tau=0, bends=None):
        """(N, M) of members.py::Members.resultants (M at the worst phase)."""
        N, M, _, _ = self.resultants(eps, kappa, tau, bends)
        return N, M

    def shear_stiffness(self, eps, kappa, helix_GA):
        """GA = n cos(beta) [k sin^2 beta + f (1 + cos^2 beta)] / 2 at the members' mean
        force f = mean_m k <e_m>_w (members.py::Members.shear_stiffness), not the helix's."""
        f = sum(self.k * smooth_ramp(e, self.width, self.m)
                for e in self.member_strains(eps, kappa)) / self.n
        return ring_shear_stiffness(self.n, self.beta, self.k, f)

    def torque(self, eps, kappa, tau, bends=None):
        """Q = dW/d tau = sum_m k <e_m>_w R b / l_m + Q_b0 (members.py::Members.resultants)."""
        return self.resultants(eps, kappa, tau, bends)[3]


class Cone:
    """The saturating law (members.py::ConeSection's, written once for numpy and the FE rod):
    A = EA, B = EI, rho = c R, w the width; kappa >= 0.  With g = eps + rho kappa and
    h = eps - B kappa / (rho A): W = (A B Phi_w(g) + (rho A)^2 Phi_w(h)) / (B + rho^2 A)."""

    torsion = ring_turns = False  # the twist is the helix's GJ; no member phase
    phi = None

    def __init__(self, A, B, rho, width, m=NUMPY):
        self.A, self.B, self.rho, self.width, self.m = A, B, rho, width, m
        self.taut_bending = B

    def _gh(self, eps, kappa):
        return eps + self.rho * kappa, eps - self.B * kappa / (self.rho * self.A)

    def W(self, eps, kappa, tau=0, bends=None):
        A, B, rho = self.A, self.B, self.rho
        g, h = self._gh(eps, kappa)
        return (A * B * ramp_energy(g, self.width, self.m)
                + (rho * A)**2 * ramp_energy(h, self.width, self.m)) / (B + rho * rho * A)

    def dW(self, eps, kappa, tau=0, bends=None):
        """(N, M) = dW/d(eps, kappa)."""
        A, B, rho = self.A, self.B, self.rho
        g, h = self._gh(eps, kappa)
        G, H = smooth_ramp(g, self.width, self.m), smooth_ramp(h, self.width, self.m)
        return ((A * B * G + (rho * A)**2 * H) / (B + rho * rho * A),
                rho * A * B * (G - H) / (B + rho * rho * A))

    def shear_stiffness(self, eps, kappa, helix_GA):
        """The helix's GA: the cone has no member of its own to shear."""
        return helix_GA
