"""Harmonic balance's stability step: when an orbit of a continued branch gets a full
Hill solve (:mod:`.hill`, 0.5 s of a 0.65 s point at N = 8) and when it carries the
multipliers of the last one.

* :data:`EVERY_POINT`: Hill's method at every point (the reference);
* :data:`GUARDED`: Hill's method where the verdict can change, the last Hill's
  multipliers carried elsewhere.  The verdict (max |mu| < 1) changes where a real
  multiplier passes +1 (a fold: the continuation's test function, the sign of
  df1/ds, equivalently of det dG/dX: on the Fig. 8 curve at N = 8 the sign of det dG/dX
  matched the parity of the real multipliers above 1 at all 135 points), or where one
  off the positive real axis passes the unit circle (period doubling, Neimark-Sacker).
  Hill is due at a branch's first point, at the first point past a fold, at the window's
  end, at a bisection's probe, every STRIDE points, while the last Hill had a real
  multiplier within FOLD_GUARD of +1 (a fold is near: the natural steps read it) and
  while its largest multiplier off the positive real axis is within EDGE of the unit
  circle.  A carried point says so in its ``accuracy["stability"]``, with the f1 of
  the Hill solve it carries (``hill_f1_Hz``).

Limitation: a period doubling or Neimark-Sacker that begins and ends between two Hill
points is not seen, and one that begins is seen at the next Hill point (at most STRIDE
points late), its bisection between that point and the one before.  Off the positive
real axis the multipliers of the Fig. 8 curve move by at most 0.006 between points and
stay 0.006 or more inside the circle.
"""

from __future__ import annotations

import numpy as np

from rawehelix.periodic_orbits.bifurcations import REAL_TOL
from rawehelix.registry import Registry

STRIDE = 15  # points: a carried point is at most this many points after a Hill solve
FOLD_GUARD = 0.05  # |mu - 1| of a real positive multiplier below which Hill is due
EDGE = 2e-3  # 1 - |mu| off the positive real axis below which Hill is due


def _fold_kind(mu: np.ndarray) -> np.ndarray:
    """The real positive multipliers (periodic_orbits/bifurcations.py's kinds)."""
    return (np.abs(mu.imag) <= REAL_TOL * np.maximum(1.0, np.abs(mu))) & (mu.real > 0)


class StabilityStep:
    """Whether a point needs a full Hill solve, given the last one (one instance per name)."""

    name: str = ""
    #: what a point's ``accuracy["stability"]`` says of a carried point
    carries: bool = False

    def due(self, last_mu: np.ndarray | None, since: int, event: bool) -> bool:
        """Hill at this point? ``last_mu``: the last Hill's multipliers (None: none yet),
        ``since``: points since it, ``event``: a fold just passed, the window's end or
        a bisection's probe."""
        return True


class EveryPoint(StabilityStep):
    name = "every_point"


class Guarded(StabilityStep):
    name = "guarded"
    carries = True

    def due(self, last_mu, since, event) -> bool:
        if last_mu is None or event or since >= STRIDE:
            return True
        mu = np.asarray(last_mu, dtype=complex)
        fold = _fold_kind(mu)
        near_fold = np.any(np.abs(mu[fold] - 1.0) < FOLD_GUARD)
        near_edge = np.any(np.abs(mu[~fold]) > 1.0 - EDGE)
        return bool(near_fold or near_edge)


EVERY_POINT, GUARDED = EveryPoint(), Guarded()
#: the stability steps by name (studies/orbit_method.py's harmonic balance picks one)
STABILITY_STEPS: Registry[StabilityStep] = Registry("stability step", (EVERY_POINT, GUARDED))
