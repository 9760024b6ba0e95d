"""Harmonic balance's stability step: when an orbit of a continued branch gets a full
Hill solve (:mod:`.hill`, 0.45 s of a 0.6 s point at N = 8, 3.7 s at N = 32) and when it
carries the multipliers of the last one.

* :data:`EVERY_POINT`: Hill's method at every point (the reference);
* :data:`GUARDED`: Hill's method where the verdict can change, the last Hill's
  multipliers carried elsewhere.  The verdict (max |mu| < 1) changes where a real
  multiplier passes +1 (a fold: the continuation's test function, the sign of df1/ds,
  equivalently of det dG/dX: on the Fig. 8 curve at N = 8 the sign of det dG/dX matched
  the parity of the real multipliers above 1 at all 135 points), or where one off the
  positive real axis passes the unit circle (period doubling, Neimark-Sacker): where
  its ln|mu| = Re lambda T passes zero.  The step predicts those from their drift, not
  their distance: ln|mu| of the K_TOP largest (sorted), their secants per unit
  distance along the branch (:meth:`Track.distance`) between the last three Hill
  solves, and Hill is due where one's predicted distance to the circle (|ln|mu||
  less its fastest approach of the two secants x the distance) is no longer above
  SAFETY x its predicted drift (the larger |secant| x the distance), or the distance
  reaches D_MAX.  On the Fig. 8 curve the least damped exponents' real parts stay
  constant to 1e-12 from 15 to 6.7 Hz, so a multiplier 0.0016 from the circle (N = 32)
  is carried as safely as one 0.0063 from it (N = 8).  Hill is also due at a branch's
  first point, at the first point past a fold, at the window's end, at a bisection's
  probe, and where the continuation's next step may be natural (a natural step's point,
  or two slow correctors in a row: periodic_orbits/continuation.py), which reads the
  multipliers: a natural step at fixed f1 is taken only where none is near +1, and a
  real one appears out of a complex pair 0.15 Hz before the fold at N = 2.  A carried
  point says so in its ``accuracy["stability"]``, with the f1 of the Hill solve it
  carries (``hill_f1_Hz``).

Limitation: Hill's shift-invert finds the exponents near its shifts only (0, i w / 2 and
the averaged system's least damped), so one that enters that set between two solves is
first seen at the next (at most D_MAX away); a period doubling or Neimark-Sacker faster
than its prediction is seen late, at the next Hill solve, and bisected between that
point and the one before.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from rawehelix.periodic_orbits.bifurcations import REAL_TOL
from rawehelix.registry import Registry

K_TOP = 3  # the largest moduli off the positive real axis tracked
SAFETY = 2.0  # x the drift predicted to a point that its distance to the circle must exceed
D_MAX = 0.5  # the distance from the last Hill solve (Track.distance) at which one is due


def _fold_kind(mu: np.ndarray) -> np.ndarray:
    """The real positive multipliers (periodic_orbits/bifurcations.py's kinds)."""
    return (np.abs(mu.imag) <= REAL_TOL * np.maximum(1.0, np.abs(mu))) & (mu.real > 0)


def log_moduli(mu) -> np.ndarray:
    """ln|mu| = Re lambda T of the K_TOP largest multipliers off the positive real axis,
    largest first, padded with -inf (Hill's shift-invert finds a few): each one's signed
    distance to the unit circle."""
    mu = np.asarray(mu, dtype=complex)
    off = mu[~_fold_kind(mu) & (mu != 0)]
    v = np.sort(np.log(np.abs(off)))[::-1][:K_TOP]
    return np.pad(v, (0, K_TOP - v.size), constant_values=-np.inf)


@dataclasses.dataclass(frozen=True)
class HillPoint:
    """A Hill solve's orbit: its multipliers, f1 [Hz], unknown X and harmonics H."""

    multipliers: np.ndarray
    f1_Hz: float
    X: np.ndarray
    H: int

    def __post_init__(self):
        if not (self.f1_Hz > 0 and self.H >= 1 and self.X.size % (2 * self.H + 1) == 0):
            raise ValueError(f"a Hill point needs f1 > 0 and X of (2 H + 1) n entries: f1 = "
                             f"{self.f1_Hz}, H = {self.H}, {self.X.size} entries")


@dataclasses.dataclass
class Track:
    """The guarded step's memory along a branch: the last Hill solve, the points since,
    and the secants of :func:`log_moduli` per unit :meth:`distance` between the last
    three solves (``secants``: the newest first; one or none before the third)."""

    last: HillPoint
    since: int = 0
    secants: tuple = ()

    def __post_init__(self):
        if self.since < 0:
            raise ValueError(f"points since the last Hill solve: {self.since} < 0")

    def distance(self, X, f1_Hz: float, H: int, embed) -> float:
        """The orbit (X at H harmonics, f1) from the last Hill solve's: the relative change
        of the coefficients and of f1 in quadrature (``embed(X, H)``: X at H harmonics)."""
        top = max(H, self.last.H)
        X, X0 = embed(X, top), embed(self.last.X, top)
        return float(np.hypot(np.linalg.norm(X - X0) / max(np.linalg.norm(X0), 1e-300),
                              (f1_Hz - self.last.f1_Hz) / self.last.f1_Hz))

    def hill(self, point: HillPoint, distance: float) -> None:
        """A new Hill solve at ``distance`` from the last: its secant kept."""
        if distance > 0:
            new, old = log_moduli(point.multipliers), log_moduli(self.last.multipliers)
            both = np.isfinite(new) & np.isfinite(old)
            secant = np.zeros(K_TOP)
            secant[both] = (new[both] - old[both]) / distance
            self.secants = (secant,) + self.secants[:1]
        self.last, self.since = point, 0

    def predicted(self, distance: float) -> tuple[np.ndarray, np.ndarray]:
        """At ``distance`` from the last solve: (the tracked moduli's predicted distance
        to the circle, their predicted drift), the worse of the last two secants each:
        |ln|mu|| less its fastest approach, and the largest |secant|, x distance."""
        v = log_moduli(self.last.multipliers)
        known = np.isfinite(v)
        s = np.array(self.secants or (np.zeros(K_TOP),))[:, known]
        toward = np.max(-np.sign(v[known]) * s, axis=0)  # > 0: moving to the circle
        return np.abs(v[known]) - toward * distance, np.max(np.abs(s), axis=0) * distance


class StabilityStep:
    """Whether a point needs a full Hill solve, given the last one (one instance per name)."""

    name: str = ""
    #: what a point's ``accuracy["stability"]`` says of a carried point
    carries: bool = False

    def due(self, track: Track | None, distance: float, event: bool, natural: bool) -> bool:
        """Hill at this point? ``track``: the branch's last Hill solve and drift (None:
        none yet), ``distance``: the point's from that solve (:meth:`Track.distance`),
        ``event``: a fold just passed, the window's end or a bisection's probe,
        ``natural``: the continuation's next step may be a natural one (fixed f1), which
        reads this point's multipliers (no fold near)."""
        return True


class EveryPoint(StabilityStep):
    name = "every_point"


class Guarded(StabilityStep):
    name = "guarded"
    carries = True

    def due(self, track, distance, event, natural) -> bool:
        if track is None or event or natural:
            return True
        if distance >= D_MAX:
            return True
        gap, drift = track.predicted(distance)
        return bool(np.any(gap <= SAFETY * drift))


EVERY_POINT, GUARDED = EveryPoint(), Guarded()
#: the stability steps by name (studies/orbit_method.py's harmonic balance picks one)
STABILITY_STEPS: Registry[StabilityStep] = Registry("stability step", (EVERY_POINT, GUARDED))
