"""Folds and bifurcations of periodic orbits between two points of a branch
(:class:`~rawehelix.periodic_orbits.continuation.Branch`).

Folds (limit points of cycles) are where df1/ds changes sign; their arclength
by the secant on tau_f1, their f1 there by the cubic Hermite interpolant of
f1(s) (values and slopes tau_f1 at both points); ``f1_error_Hz`` is its
distance from the linear interpolant, an estimate of the error.  Period
doubling (a real multiplier through -1) and Neimark-Sacker (a complex pair
through the unit circle) are flagged where the count of multipliers of that
kind outside the unit circle changes, and located by bisection in arclength
between the two points (:func:`bisect_crossing`): each probe is a corrector
from the earlier point with a shorter step and a Floquet period.

An event reports the caller's observable (:class:`~rawehelix.periodic_orbits.problem.Observable`)
under its name, interpolated to the event (a fold) or at the probe past it.
"""

from __future__ import annotations

import time

import numpy as np

from rawehelix.errors import SolverError
from rawehelix.periodic_orbits.problem import UNIT_CIRCLE_TOL, Observable, Orbit

BISECTION_HZ = 1e-4  # PD / NS located to this width in f1 [Hz]
BISECTION_MAX = 12  # probes per bisection
FOLD_MARGIN = 0.02  # natural steps only while every multiplier is this far from +1
#: |Im mu| below this share of |mu|: a real multiplier (Hill's truncation leaves ~1e-9 on
#: the real ones; the monodromy's eigenvalues are real exactly)
REAL_TOL = 1e-6


def far_from_folds(mu) -> bool:
    """No multiplier within FOLD_MARGIN of +1: no fold (a real multiplier through
    +1) is near, so f1 parametrises the branch and solving at fixed f1 is sound."""
    mu = np.asarray(mu)
    return bool(mu.size == 0 or np.min(np.abs(mu - 1.0)) > FOLD_MARGIN)


def _kinds(mu) -> dict:
    """The multipliers' kinds as masks: real positive (fold), real negative (period
    doubling), complex (Neimark-Sacker)."""
    mu = np.asarray(mu, dtype=complex)
    real = np.abs(mu.imag) <= REAL_TOL * np.maximum(1.0, np.abs(mu))
    return {"fold": real & (mu.real > 0), "period_doubling": real & (mu.real < 0),
            "neimark_sacker": ~real}


def _unstable(mu) -> dict:
    """Multipliers outside the unit circle, by kind (real > 1, real < -1, complex)."""
    out = np.abs(mu) > 1.0 + UNIT_CIRCLE_TOL
    return {kind: int(np.sum(out & sel)) for kind, sel in _kinds(mu).items()}


def critical(mu) -> tuple[float, complex | None, str | None]:
    """(max |mu|, that mu, its kind) over the multipliers that are not real and positive:
    those whose passage through the unit circle is a period doubling or a Neimark-Sacker
    ((0, None, None): none).  max |mu| = 1 is where the orbit loses (or regains)
    stability other than at a fold, whichever multiplier does it."""
    mu = np.asarray(mu, dtype=complex)
    sel = mu[~_kinds(mu)["fold"]]
    if sel.size == 0:
        return 0.0, None, None
    m = complex(sel[int(np.argmax(np.abs(sel)))])
    return abs(m), m, next(k for k, v in _kinds([m]).items() if v[0])


def stability_changes(a: Orbit, b: Orbit) -> bool:
    """Whether a multiplier off the positive real axis is outside the unit circle at one
    of a and b and none at the other: a stability boundary other than a fold between them."""
    ua, ub = _unstable(a.multipliers), _unstable(b.multipliers)
    return (ua["period_doubling"] + ua["neimark_sacker"] == 0) != \
        (ub["period_doubling"] + ub["neimark_sacker"] == 0)


def unstable_changes(a: Orbit, b: Orbit) -> list[tuple[str, int]]:
    """(kind, count at a) of the period doublings and Neimark-Sackers between a and b."""
    ua, ub = _unstable(a.multipliers), _unstable(b.multipliers)
    return [(kind, ua[kind]) for kind in ("period_doubling", "neimark_sacker")
            if ua[kind] != ub[kind]]


def bisect_crossing(probe, s_b: float, count_a: int, kind: str, f1_width: float = BISECTION_HZ,
                    max_probes: int = BISECTION_MAX):
    """Bisection in arclength s in (0, s_b) for the change of the count of
    ``kind`` multipliers outside the unit circle, from ``count_a`` at s = 0.
    ``probe(s)`` -> (f1, multipliers, info).  Returns (s_lo, s_hi, f1_lo,
    f1_hi, info_hi, probes): the bracket that holds the change, the probe
    just past it, and the number of probes used.  Stops when the bracket is
    under ``f1_width`` in f1 or after ``max_probes``."""
    lo, hi, f_lo, f_hi, info_hi = 0.0, s_b, None, None, None
    probes = 0
    while probes < max_probes and (f_lo is None or f_hi is None or abs(f_hi - f_lo) > f1_width):
        mid = 0.5 * (lo + hi)
        f1, mu, info = probe(mid)
        probes += 1
        if _unstable(np.asarray(mu))[kind] == count_a:
            lo, f_lo = mid, f1
        else:
            hi, f_hi, info_hi = mid, f1, info
    return lo, hi, f_lo, f_hi, info_hi, probes


def locate(branch, a: Orbit, b: Orbit, st, kind: str, count_a: int, steps,
           observable: Observable | None = None) -> dict:
    """PD / NS between a and b by bisection in arclength (each probe: the
    ``branch``'s corrector from a with a shorter step and the Floquet period there)."""

    def probe(s):
        got = branch.correct(a, st.tau, st.A, st.gf, s, steps)
        if got is None:
            raise SolverError(f"continuation: the corrector failed while bisecting a "
                              f"{kind} between {a.f1_Hz:.5f} and {b.f1_Hz:.5f} Hz")
        X, f1, its, res, _, _ = got
        o = branch.problem.finish(X, f1, its, res, time.perf_counter(), steps)
        branch.problem.stability(o, event=True)
        return o.f1_Hz, o.multipliers, o

    lo, hi, f_lo, f_hi, o, probes = bisect_crossing(probe, st.ds, count_a, kind)
    f_lo = a.f1_Hz if f_lo is None else f_lo
    if o is None:
        o = b
    f_hi = o.f1_Hz
    out = {"f1_Hz": 0.5 * (f_lo + f_hi)}
    if observable is not None:
        out[observable.name] = observable.of_orbit(o)
    out.update({"kind": kind, "f1_error_Hz": 0.5 * abs(f_hi - f_lo), "probes": probes,
                "multiplier": _crossing(o.multipliers, kind)})
    return out


def _crossing(mu, kind) -> list[float]:
    """The multiplier of ``kind`` nearest the unit circle (re, im)."""
    mu = np.asarray(mu)
    sel = _kinds(mu)[kind]
    if not np.any(sel):
        return []
    m = mu[sel][np.argmin(np.abs(np.abs(mu[sel]) - 1.0))]
    return [float(m.real), float(m.imag)]


def fold_between(a: Orbit, b: Orbit, ta: float, tb: float, ds: float,
                 observable: Observable | None = None) -> dict:
    """A fold between a and b, where df1/ds goes from ta to tb (opposite signs):
    s* by the secant on df1/ds, f1(s*) by the cubic Hermite interpolant of f1(s)
    over [0, ds]; the error estimate is its distance from the linear one; the
    observable interpolated linearly at s*."""
    w = ta / (ta - tb)
    fa, fb = a.f1_Hz, b.f1_Hz
    h00, h10, h01, h11 = (2 * w**3 - 3 * w**2 + 1, w**3 - 2 * w**2 + w, -2 * w**3 + 3 * w**2,
                          w**3 - w**2)
    hermite = h00 * fa + h10 * ds * ta + h01 * fb + h11 * ds * tb
    linear = fa + w * (fb - fa)
    out = {"f1_Hz": float(hermite)}
    if observable is not None:
        va, vb = observable.of_orbit(a), observable.of_orbit(b)
        out[observable.name] = va + w * (vb - va)
    out.update({"kind": "fold", "f1_error_Hz": float(abs(hermite - linear)),
                "bracket_Hz": [fa, fb]})
    return out
