"""Analytic spectra of the classical continuous models, normalised (Eqs. 25-29).

Unit mass per unit length, s in [0, 1]; k = n pi.  With the tension T, the
bending mu (Eq. 26, off when model.bending is) and the torsional stiffness delta:

* longitudinal, fixed-fixed bar (Rao, *Vibration of Continuous Systems*, 2019,
  Sec. 9.3): about a straight state r' = (1 + eps) e the tension law (29) gives
  the axial stiffness sigma (1 + 2 eps) = sigma + 2 T, and the bending term of
  Eq. (33) acts on the axial component too:
  omega_n^2 = (sigma + 2 T) k^2 + mu k^4  (T = 0, mu = 0: n pi sqrt(sigma));
* lateral, pinned beam under tension (Rao, Sec. 11.5):
  omega_n^2 = T k^2 + mu k^4  (mu = 0: the taut string, n pi sqrt(T));
* torsional, free-free shaft (Rao, Sec. 8.3): omega_n = n pi sqrt(delta).

The FE scheme uses them to place the SLEPc target and size the Krylov space
(:func:`frequencies`, :func:`count_below`); the tests and the extremes study
check spectra against them.  numpy only.
"""

from __future__ import annotations

import math

import numpy as np

from rawehelix.models.kinematics import get as kinematics_named
from rawehelix.models.kinematics import paper_axial_strain  # noqa: F401 (the API's name)


def _mu(q) -> float:
    return q.bending * q.mu


def bar(q, n, tension: float = 0.0):
    """Fixed-fixed bar: omega_n^2 = (sigma + 2 T) (n pi)^2 + mu (n pi)^4."""
    k = np.asarray(n) * math.pi
    return np.sqrt((q.sigma + 2 * tension) * k**2 + _mu(q) * k**4)


def beam(q, n, tension: float):
    """Pinned beam under tension: omega_n^2 = T (n pi)^2 + mu (n pi)^4."""
    k = np.asarray(n) * math.pi
    return np.sqrt(tension * k**2 + _mu(q) * k**4)


def string(n, tension: float):
    """Taut string, the beam without bending: omega_n = n pi sqrt(T)."""
    return np.asarray(n) * math.pi * math.sqrt(tension)


def shaft(q, n):
    """Free-free shaft: omega_n = n pi sqrt(delta)."""
    return np.asarray(n) * math.pi * math.sqrt(q.delta)


def frequencies(q, tension: float, count: int, twist: bool = True) -> dict:
    """omega_n, n = 1..count, per family (no torsional ones without the twist field)."""
    n = np.arange(1, count + 1)
    lateral = beam(q, n, tension)
    return {
        "longitudinal": bar(q, n, tension),
        "lateral_in_plane": lateral,
        "lateral_out_of_plane": lateral,
        **({"torsional": shaft(q, n)} if twist else {}),
    }


def _below(stiffness: float, mu: float, omega: float) -> int:
    """How many k = n pi solve mu k^4 + stiffness k^2 <= omega^2."""
    if mu <= 0:
        k2 = omega**2 / stiffness
    else:
        k2 = (-stiffness + math.sqrt(stiffness**2 + 4 * mu * omega**2)) / (2 * mu)
    return int(math.sqrt(max(k2, 0.0)) / math.pi)


def count_below(q, tension: float, omega: float, twist: bool = True) -> int:
    """How many modes of all families have omega_n <= omega (lateral twice)."""
    mu = _mu(q)
    total = _below(q.sigma + 2 * tension, mu, omega) + 2 * _below(max(tension, 1e-300), mu, omega)
    if twist:
        total += int(omega / (math.pi * math.sqrt(q.delta)))
    return total


# -- the lab tests' cantilever (Sec. 4, solvers/cantilever.py), SI --------------------
#
# A segment of length L clamped at s = 0, a dead tension T along the axis and a
# small force F normal to it at s = L.  Linearised about the stretched straight
# state, the deflection w(s) obeys EI w'''' - T w'' = 0 with w(0) = w'(0) = 0,
# w''(L) = 0 and the end's shear T w'(L) - EI w'''(L) = F (Timoshenko & Gere,
# *Theory of Elastic Stability*, 1961, Sec. 1.11, the tie-beam), so that
#     w(L) = F/T (L - tanh(kL)/k),  k^2 = T/EI,
# and F L^3 / (3 EI) at T = 0.  The paper's Eq. (63), EI = F L^3 / (3 w(L)),
# then infers EI T L^2 / (3 EI (1 - tanh(kL)/(kL))) = EI + 2 T L^2 / 5 + O(T^2 L^4 / EI).
# The end's tension T_e sets T and EI of the transverse equation through the
# kinematics (:func:`cantilever_transverse`): the paper's (forms/rod.py) carry
# it as T r', |r'| = 1 + eps, so that T_e = EA eps (1 + eps), T = EA eps =
# T_e / (1 + eps) and EI stays; the extensible rod (forms/extensible.py) as T t,
# T = T_e, eps = T_e / EA, whose energy per unstretched length, linearised about
# r' = (1 + eps) e, has T_e / (1 + eps) w'^2 / 2 + EI / (1 + eps)^2 w''^2 / 2.

def cantilever_tip_deflection(force, tension, EI, length):
    """w(L) of the clamped segment under the end force F and the tension T (above)."""
    T = np.asarray(tension, dtype=float)
    kl2 = T * length**2 / EI
    small = kl2 < 1e-6  # tanh(x)/x = 1 - x^2/3 + 2 x^4/15: the T = 0 limit without round-off
    k = np.sqrt(np.where(small, 1.0, T) / EI)
    exact = np.where(small, 0.0, length - np.tanh(k * length) / k) / np.where(small, 1.0, T)
    series = length**3 / (3 * EI) * (1 - 2 * kl2 / 5)
    return force * np.where(small, series, exact)


def cantilever_apparent_EI(EI, tension, length):
    """The EI that Eq. (63) infers from the tensioned cantilever: F L^3 / (3 w(L))."""
    return length**3 / (3 * cantilever_tip_deflection(1.0, tension, EI, length))


def cantilever_transverse(tension, EI, EA, kinematics: str = "paper"):
    """(T, EI) of the transverse equation under the end tension T_e (above), as the
    kinematics of that name has it (models/kinematics.py)."""
    return kinematics_named(kinematics).cantilever_transverse(tension, EI, EA)


def cantilever_intrinsic_EI(apparent_EI, tension, length):
    """The EI whose tensioned cantilever Eq. (63) reads as ``apparent_EI`` (the
    inverse of :func:`cantilever_apparent_EI`; None if T L^2 / 3, the apparent EI of
    a string, already exceeds it)."""
    from scipy.optimize import brentq
    if apparent_EI <= tension * length**2 / 3:
        return None
    return brentq(lambda e: cantilever_apparent_EI(e, tension, length) - apparent_EI,
                  1e-9 * apparent_EI, apparent_EI, xtol=1e-12 * apparent_EI)


