"""Period doublings and Neimark-Sackers of periodic orbits continued in a second
parameter p: the boundaries of the unstable bands of the design map (issue 31), on any
periodic-orbit problem (:class:`~rawehelix.periodic_orbits.problem.PeriodicOrbitProblem`,
by its multipliers: the monodromy's for shooting, Hill's for harmonic balance).

The orbit loses stability by a period doubling (PD, a real multiplier through -1) or a
Neimark-Sacker (NS, a complex pair through the unit circle) where the test function

    g(f1, p) = max |mu| - 1 over the multipliers that are not real and positive

(:func:`bifurcations.critical`; those are the folds', continued apart) passes zero, on the
orbit at fixed (f1, p): a PD or NS is not a fold, so f1 parametrises the branch there
(Kuznetsov 2004, Sec. 10.2, continuation of a codim-1 bifurcation by its test function).
One g for both kinds: the boundary stays the stability boundary where the critical pair
meets on the negative real axis and turns from NS into PD (near a 1:2 resonance, as the
tensegrity's band does), and where a second band overlaps the first (a corner of the
union's boundary); each point reports its critical multiplier and kind.

:func:`locate` brackets the zero in f1 at fixed p (between two branch points, or by a
search toward it) and closes the bracket by regula falsi (Illinois).  :func:`trace`
follows the zero set of g in the (f1, p) plane by local parametrisation: a predictor
along the secant of the last two points (f1 scaled by what one p step moves the curve
by), and a corrector at fixed p unless the curve runs nearly along f1 (a band's tip),
there at fixed f1 (each probe then a problem at its own p), so that it turns round it.  The corrector
searches toward the unstable side, which stays on one side of the direction of travel
along a boundary: a band's two boundaries are told apart by it.  Steps are halved where
the corrector fails or lands farther than REACH steps away, doubled back after a
success.  A feature of the boundary smaller than a step (a narrow band's tip poking out
of another band) can be cut across: the steps are the envelope's resolution in KEY.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from rawehelix.errors import SolverError
from rawehelix.periodic_orbits.bifurcations import critical

SECANT_HZ = 1e-6  # the crossing's f1 to this [Hz] (at fixed f1: p to this x p_step / F1_SCALE)
SECANT_MAX = 30  # regula falsi iterations a crossing
BRACKET_HZ = 2e-3  # the first step of the search for a bracket [Hz]
JUMP_HZ = 0.1  # the bracket's search goes no farther than this [Hz]
F1_SCALE_HZ, F1_SCALE_MAX_HZ = 0.05, 0.5  # the bounds of f1's scale against one p step
FIXED_P = 0.3  # the corrector at fixed p while the scaled tangent's p part is at least this
REACH = 3.0  # a step is halved where the new point lies farther than this x h from the last
MAX_POINTS = 200  # a trace stops (and says so) after this many points


@dataclasses.dataclass
class Crossing:
    """A PD or NS at parameter value p: f1 [Hz], the orbit there and its critical
    multiplier (``kind`` that multiplier's)."""

    kind: str
    p: float
    f1_Hz: float
    X: np.ndarray
    multiplier: complex
    resolution: int
    iterations: int
    side: float  # the sign of dg/df1 there: +1 where the unstable band lies above in f1

    def entry(self) -> dict:
        return {"value": self.p, "f1_Hz": self.f1_Hz, "kind": self.kind,
                "multiplier": [float(self.multiplier.real), float(self.multiplier.imag)],
                "iterations": self.iterations}


def test_function(multipliers) -> tuple[float, complex, str]:
    """(g, mu, kind): g = max |mu| - 1 over the multipliers that are not real and positive,
    that mu and its kind (SolverError where every multiplier is real and positive)."""
    modulus, mu, kind = critical(multipliers)
    if mu is None:
        raise SolverError("no multiplier off the positive real axis here")
    return modulus - 1.0, mu, kind


class _Line:
    """g along a line x -> (f1(x), p(x)), each probe an orbit at fixed (f1, p) from the
    nearest earlier probe's state (or X)."""

    def __init__(self, problem_at, X, resolution, at):
        self.problem_at, self.X, self.resolution, self.at = problem_at, X, resolution, at
        self.probes = []  # (x, g, orbit, mu, kind)

    def __call__(self, x):
        f1, p = self.at(x)
        start = min(self.probes, key=lambda q: abs(q[0] - x))[2].X if self.probes else self.X
        o = self.problem_at(p).orbit(start, f1, steps=self.resolution)
        try:
            g, mu, kind = test_function(o.multipliers)
        except SolverError:
            return None
        self.probes.append((x, g, o, mu, kind))
        return g


def _root(g_of, x0: float, rising: float | None, step: float, reach: float, tol: float,
          bracket=None, max_it: int = SECANT_MAX):
    """The zero of g_of(x) near x0: a bracket (``bracket``, or searched from x0 in steps
    doubled from ``step`` up to ``reach``, toward the zero: ``rising`` is the sign of dg/dx
    there, None to take it from a second probe), then Illinois to ``tol``.  Returns (x,
    the sign of dg/dx there, iterations); raises SolverError with the reason."""
    if bracket is not None:
        x_a, x_b = bracket
        g_a, g_b = g_of(x_a), g_of(x_b)
    else:
        x_a, g_a = x0, g_of(x0)
        if g_a is None:
            raise SolverError("no multiplier off the positive real axis")
        if rising is None:
            g_1 = g_of(x0 + step)
            if g_1 is None or g_1 == g_a:
                raise SolverError("g is flat")
            rising = float(np.sign(g_1 - g_a))
        direction, h, x_b, g_b = -float(np.sign(g_a)) * rising, step, x_a, g_a
        while g_b is not None and np.sign(g_b) == np.sign(g_a):
            if h > reach:
                raise SolverError(f"no crossing within {reach:.3g}")
            x_b, g_b = x_a + direction * h, g_of(x_a + direction * h)
            h *= 2
    if g_a is None or g_b is None or np.sign(g_a) == np.sign(g_b):
        raise SolverError("no sign change of g in the bracket")
    for its in range(1, max_it + 1):  # Illinois: the retained end's g halved when kept twice
        x_c = x_b - g_b * (x_b - x_a) / (g_b - g_a)
        g_c = g_of(x_c)
        if g_c is None:
            raise SolverError("g has no multiplier inside the bracket")
        if np.sign(g_c) == np.sign(g_b):
            g_a *= 0.5
        else:
            x_a, g_a = x_b, g_b
        x_b, g_b = x_c, g_c
        if abs(x_b - x_a) <= tol or g_c == 0.0:
            return x_c, float(np.sign(g_b - g_a) * np.sign(x_b - x_a)), its
    raise SolverError(f"regula falsi did not reach {tol:g} in {max_it} iterations")


def _crossing(line, x, its, side: float) -> Crossing:
    """The crossing at x on ``line`` from its probe there; ``side``: the sign of dg/df1."""
    _, _, o, mu, kind = min(line.probes, key=lambda q: abs(q[0] - x))
    f1, p = line.at(x)
    return Crossing(kind, p, float(f1), o.X, complex(mu), line.resolution, its, side)


def locate(problem, X, f1_Hz: float, resolution: int, p: float = 0.0,
           side: float | None = None, bracket: tuple | None = None,
           tol: float = SECANT_HZ) -> Crossing:
    """The crossing near (X, f1) at fixed p: a bracket in f1 (``bracket``, two f1 [Hz], or
    searched from f1 toward the zero ``side`` points to: +1 where g rises with f1), closed
    by regula falsi.  SolverError with the reason, or where (``side``) the crossing's g
    falls where ``side`` asks it to rise: the band's other boundary."""
    line = _Line(lambda _: problem, X, resolution, lambda x: (x, p))
    try:
        f1, rising, its = _root(line, f1_Hz, side, BRACKET_HZ, JUMP_HZ, tol, bracket)
    except SolverError as err:
        raise SolverError(f"stability boundary at p = {p:g} near f1 = {f1_Hz:.5g} Hz: "
                          f"{err}") from None
    if side is not None and rising != side:
        raise SolverError(f"stability boundary at p = {p:g}: the crossing at {f1:.5f} Hz is "
                          f"the band's other boundary")
    return _crossing(line, f1, its, rising)


def _first_tangent(problem_at, first: Crossing, s_p: float, to_stop: float):
    """(t, hand, s_f) at the first crossing: the f1 scale s_f [Hz] that one p step s_p
    moves the curve by (from g's gradient by differences: one orbit at f1 + BRACKET_HZ,
    one at p + s_p / 16; within F1_SCALE_HZ and F1_SCALE_MAX_HZ), the curve's unit tangent
    in the scaled plane (f1 / s_f, p / s_p) headed toward p_stop, and the hand (+1: left
    of t) on which g rises, the unstable side, kept all along the curve.  Where a
    difference has no multiplier to take: t along p, the hand from first.side."""
    line_f = _Line(problem_at, first.X, first.resolution, lambda x: (x, first.p))
    line_p = _Line(problem_at, first.X, first.resolution, lambda x: (first.f1_Hz, x))
    g_f, g_p = line_f(first.f1_Hz + BRACKET_HZ), line_p(first.p + to_stop * s_p / 16)
    if g_f is None or g_p is None or g_f == 0:
        return np.array([0.0, to_stop]), -to_stop * first.side, F1_SCALE_HZ
    # g = 0 at first: dg/df1 = g_f / BRACKET_HZ, dg/dp = g_p / (s_p / 16) toward p_stop
    slope_Hz = abs(g_p * 16 / s_p) / abs(g_f / BRACKET_HZ) * s_p  # f1 a p step moves
    s_f = min(max(slope_Hz, F1_SCALE_HZ), F1_SCALE_MAX_HZ)
    grad = np.array([g_f / BRACKET_HZ * s_f, g_p * 16 * to_stop])
    t = np.array([-grad[1], grad[0]]) / np.linalg.norm(grad)
    if t[1] * to_stop < 0:
        t = -t
    return t, float(np.sign(np.dot([-t[1], t[0]], grad))), s_f


def trace(problem_at, first: Crossing, p_stop: float, step: float,
          min_step: float | None = None, max_points: int = MAX_POINTS
          ) -> tuple[list[Crossing], str]:
    """The stability boundary through ``first`` (at first.p) toward ``p_stop`` in the
    (f1, p) plane (module docstring): ``problem_at(p)`` gives the periodic-orbit problem
    at p; steps of ``step`` in p (and the f1 it moves the curve by), halved where
    the corrector fails, down to ``min_step`` (default step / 64), doubled again after a
    success.  It ends at p_stop, back at first.p (a band's tip between the two), or where
    the steps give out.  Returns (the crossings, why the trace ended)."""
    s_p = abs(step)
    min_h = abs(min_step or s_p / 64) / s_p
    to_stop = 1.0 if p_stop >= first.p else -1.0
    u = lambda c: np.array([c.f1_Hz / s_f, c.p / s_p])  # noqa: E731 - scaled
    t, hand, s_f = _first_tangent(problem_at, first, s_p, to_stop)
    points, h = [first], 1.0
    while len(points) < max_points:
        last = points[-1]
        if len(points) >= 2:
            d = u(last) - u(points[-2])
            t = d / np.linalg.norm(d)
        guess = u(last) + h * t
        normal = hand * np.array([-t[1], t[0]])  # g rises along it
        p = guess[1] * s_p
        ends = [end for end, beyond in ((p_stop, (p - p_stop) * to_stop >= 0),
                                        (first.p, (p - first.p) * to_stop < 0)) if beyond]
        fixed_p = abs(t[1]) >= FIXED_P or bool(ends)
        if fixed_p:  # the corrector in f1 at p, landing on p_stop or back on first.p
            if ends:
                guess, p = u(last) + t * (ends[0] / s_p - u(last)[1]) / t[1], ends[0]
            line = _Line(problem_at, last.X, last.resolution,
                         lambda x, p=p: (x * s_f, p))
        else:  # in p at f1
            f1 = guess[0] * s_f
            line = _Line(problem_at, last.X, last.resolution,
                         lambda x, f1=f1: (f1, x * s_p))
        k = 0 if fixed_p else 1
        try:
            x, rising, its = _root(line, guess[k], float(np.sign(normal[k])) or None,
                                   BRACKET_HZ / s_f, 2 * h + JUMP_HZ / s_f, SECANT_HZ / s_f)
            got = _crossing(line, x, its, float(np.sign(normal[0])))  # g rises along normal
            if rising != np.sign(normal[k]) or np.linalg.norm(u(got) - u(last)) > REACH * h:
                raise SolverError("another boundary, or one beyond the step's reach")
            if (got.p - first.p) * to_stop < 0 or (got.p - p_stop) * to_stop > 0:
                raise SolverError("past an end: a shorter step lands on it")
        except SolverError:
            h /= 2
            if h < min_h:
                return points, (f"ended at p = {last.p:.6g}, f1 = {last.f1_Hz:.5f} Hz: the "
                                f"corrector found no crossing within {2 * h * s_p:.3g} in p "
                                f"or {2 * h * s_f:.3g} Hz beyond it")
            continue
        points.append(got)
        if got.p == p_stop:
            return points, "reached the end of the window"
        if got.p == first.p:
            return points, (f"came back to p = {got.p:.6g} at f1 = {got.f1_Hz:.5f} Hz: the "
                            f"band's tip lies between")
        h = min(1.0, 2 * h)
    return points, f"stopped after {max_points} points"
