"""Resonance tracking along a branch of periodic orbits: the step guards that the
caller (studies/orbits.py) gives :class:`~rawehelix.periodic_orbits.continuation.Branch`,
and the peaks and superharmonic resonances they report.

:class:`Peaks`: the step adapts so that the observable (T max) changes by at
most ``step`` (relative) between two points: a corrected point past it is
refused (before its Floquet period) and retried with a step scaled to the
change, and the next step is capped by the same linear prediction.  So a peak
of T max is approached in steps of at most that fraction and is not stepped
over.  A local maximum of the observable between three points is refined by
correctors at the vertex of their parabola (:meth:`Peaks.refine`).

:class:`Sites`: superharmonic resonances k:1 (k f1 = f_n of a driven natural
frequency) are where a Floquet multiplier mu = exp(lambda T1) of that mode
passes the positive real axis: its angle is 2 pi f_n / f1 (mod 2 pi), its
distance |mu - 1| (about the modal damping over a period there, 1 - |mu|) sets
the resonance's width, and the resolvent (M - I)^-1 its height.  A narrow one
lies between two points of the T max step unseen, so the caller names the
``sites`` (:class:`Site`: f_n / k with f_n from the linearisation) and, within
``SITE_WINDOW`` of a site, the step moves the site's multiplier's angle
(d theta / d f1 = 2 pi f_n / f1^2) by at most ``angle_step`` |mu - 1| (the
multiplier's distance to +1 at the last point), so the points close in
geometrically on the crossing; a step that would jump a window is cut to
land at its edge.  The site's multiplier is tracked from point to point
(:func:`track`): the lightly damped one (|mu| >= ``LIGHT``) nearest the
predicted angle 2 pi (f_n / f1 - k) where a run in the window begins, then
the one nearest the last one's angle moved by the predicted rotation, so
that the many other lightly damped multipliers (70 of 156 at N = 4), which
rotate at other rates, are not taken for it.  Only near the linearisation's
state (the orbit's mean T(0) within LINEAR_SHIFT of its tension,
:meth:`Site.holds_at`): on the primary resonance's S-curve a site's prediction
means nothing (at N = 4 the 3:1 site of a 38.1 Hz lateral mode, 12.70 Hz, lies
on it, and 10 "superharmonic" minima of |mu - 1| were reported there).
Where the tracked multiplier's angle changes sign between two points of a
window, the resonance is located by the angle's zero, interpolated linearly
in 1/f1 (:func:`superharmonic_between`), and reported in ``peaks`` with kind
``superharmonic``, its f1, |mu - 1| there and T max and T max - T min
interpolated to it.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from rawehelix import fits
from rawehelix.errors import SolverError
from rawehelix.periodic_orbits.continuation import StepGuard
from rawehelix.periodic_orbits.problem import Observable, Orbit

TENSION_STEP = 0.05  # the largest relative change of T max between two branch points
PEAK_PROBES = 8  # correctors per peak refinement
PEAK_TOL = 1e-6  # a peak's T max located to this relative change between two vertices
SITE_WINDOW = 0.05  # the step control acts within this relative distance of a site's f1
ANGLE_STEP = 1.0  # within a window: the angle's change per step over |mu - 1|
LIGHT = 0.5  # multipliers of modulus below this are not a site's (damped over a period)
SITE_ANGLE = 0.5  # a site's multiplier: within this of its predicted angle [rad]
RUN = 200  # the points a site's multiplier is tracked over (the last of the branch)
SUPERHARMONIC_ORDERS = (2, 3)  # k of the k:1 resonances the sites are made for
LINEAR_SHIFT = 0.1  # sites act on orbits whose mean T(0) is within this of the linearised one


class Peaks(StepGuard):
    """The observable's relative step and its local maxima (module docstring)."""

    def __init__(self, observable: Observable, step: float = TENSION_STEP):
        if not 0 < step < 1:
            raise SolverError(f"continuation: tension_step {step} must be in (0, 1)")
        self.observable, self.step = observable, step
        self.change = 0.0  # of the observable at the last point admitted

    def admit(self, prev: Orbit, orbit: Orbit | None, samples) -> float | None:
        value = (self.observable.of_orbit(orbit) if orbit is not None
                 else self.observable.samples_value(samples))
        self.change = change = abs(value / self.observable.of_orbit(prev) - 1.0)
        if change > self.step:  # moved too far: a shorter step, scaled to the change
            return max(0.2, 0.8 * self.step / change)
        return None

    def cap(self, points, f1_s: float, ds: float, last_ds: float | None) -> float:
        """The next change of the observable, predicted linearly, within the bound."""
        if last_ds is None or not self.change > 0:
            return ds
        return min(ds, last_ds * 0.8 * self.step / self.change)

    def events(self, branch, a: Orbit, b: Orbit, st, steps) -> list[dict]:
        z, of = branch.points[-2], self.observable.of_orbit
        if of(a) > of(z) and of(a) >= of(b):
            return [self.refine(branch, z, a, b, st, steps)]
        return []

    def refine(self, branch, z: Orbit, a: Orbit, b: Orbit, st, steps) -> dict:
        """A local maximum of the observable at or near a (z < a >= b): the vertex
        of the parabola through (s, value) of the three, in arclength s from a
        along its tangent, then correctors at the vertex, each keeping the highest
        point and its neighbours in s (a bracket), until the value changes by
        less than PEAK_TOL."""
        of = self.observable.of_orbit
        Y = lambda o: np.concatenate([o.X, [o.f1_Hz]])  # noqa: E731
        s_z = float((branch.w**2 * st.tau) @ (Y(z) - Y(a)))
        pts = [(s_z, of(z), z.f1_Hz), (0.0, of(a), a.f1_Hz), (st.ds, of(b), b.f1_Hz)]
        best, probes, located = pts[1], 0, "point"
        while probes < PEAK_PROBES:
            x, y = np.array([p[0] for p in pts]), np.array([p[1] for p in pts])
            if fits.undetermined(fits.polynomial(x, 2), 3):  # two of the three at one s
                break
            c2, c1, _ = np.polyfit(x, y, 2)
            if not c2 < 0:
                break
            sv = -c1 / (2 * c2)
            if not min(x) < sv < max(x):
                break
            got = branch.correct(a, st.tau, st.A, st.gf, sv, steps)
            probes += 1
            if got is None:
                break
            _, f1, _, _, samples, _ = got
            T = float(self.observable.samples_value(samples))
            previous = best
            if T > best[1]:
                best, located = (sv, T, f1), "refined"
            # the highest of the four and its neighbours on either side in s: a bracket
            # (dropping the lowest could drop the only point beyond the vertex)
            pts = sorted(pts + [(sv, T, f1)])
            top = int(np.argmax([p[1] for p in pts]))
            top = min(max(top, 1), len(pts) - 2)
            pts = pts[top - 1:top + 2]
            if abs(T / previous[1] - 1) <= PEAK_TOL:
                break
        return {"f1_Hz": best[2], self.observable.name: best[1], "kind": "peak",
                "located": located, "probes": probes, "bracket_Hz": [z.f1_Hz, b.f1_Hz]}


@dataclasses.dataclass(frozen=True)
class Site:
    """Where a k:1 superharmonic resonance of the natural frequency f_n is expected."""

    f_n_Hz: float
    k: int
    tension_N: float | None = None  # T(0) of the linearised state (None: not checked)

    @property
    def f1_Hz(self) -> float:
        return self.f_n_Hz / self.k

    def angle(self, f1: float) -> float:
        """The mode's multiplier's predicted angle at f1, in (-pi, pi]."""
        return float(np.angle(np.exp(2j * np.pi * (self.f_n_Hz / f1 - self.k))))

    def near(self, f1: float) -> bool:
        return abs(f1 / self.f1_Hz - 1.0) <= SITE_WINDOW

    def holds_at(self, orbit: Orbit) -> bool:
        """The orbit's mean tension at s = 0 is within LINEAR_SHIFT of the
        linearised state's, so f_n (~ sqrt(T) for the lateral modes) has moved
        by less than the window: on a resonance's S-curve (T several times the
        stationary) the prediction means nothing."""
        if self.tension_N is None:
            return True
        mean = 0.5 * (orbit.tension_max_N + orbit.tension_min_N)
        return abs(mean / self.tension_N - 1.0) <= LINEAR_SHIFT


def sites_for(frequencies_Hz, f1_lo: float, f1_hi: float,
              orders=SUPERHARMONIC_ORDERS, tension_N: float | None = None) -> list[Site]:
    """The k:1 sites f_n / k of the natural frequencies f_n inside [f1_lo, f1_hi]
    (of the linearisation about a state whose tension at s = 0 is ``tension_N``);
    sites closer than a tenth of the window (a lateral pair) are one."""
    out = []
    for site in sorted((Site(float(f), int(k), tension_N) for f in frequencies_Hz for k in orders
                        if f1_lo <= f / k <= f1_hi), key=lambda x: x.f1_Hz):
        if not out or site.f1_Hz / out[-1].f1_Hz - 1.0 > 0.1 * SITE_WINDOW:
            out.append(site)
    return out


class MaxStep(StepGuard):
    """A step moves f1 by at most ``f1_step_Hz`` (None: any): where stability is judged at
    the branch's points, an unstable band narrower than their spacing falls between two
    of them (the envelope's ticks)."""

    def __init__(self, f1_step_Hz: float | None = None):
        self.f1_step_Hz = f1_step_Hz

    def cap(self, points, f1_s: float, ds: float, last_ds: float | None) -> float:
        if self.f1_step_Hz is None or abs(f1_s) < 1e-12:
            return ds
        return min(ds, self.f1_step_Hz / abs(f1_s))


class Sites(StepGuard):
    """The step closes in on the superharmonic ``sites`` (module docstring)."""

    def __init__(self, sites=(), angle_step: float = ANGLE_STEP):
        self.sites, self.angle_step = tuple(sites), angle_step

    def cap(self, points, f1_s: float, ds: float, last_ds: float | None) -> float:
        """The next step from the last of ``points`` cut by the sites: within a
        window, the site's multiplier's angle moves by at most angle_step |mu - 1|;
        a window ahead is not jumped (the step lands just inside its edge)."""
        if not self.sites or abs(f1_s) < 1e-12:
            return ds
        f1, ahead = points[-1].f1_Hz, float(np.sign(f1_s))
        for site in self.sites:
            if site.near(f1):
                mu = track(site, points[-RUN:])[-1]
                if mu is not None:
                    rate = 2 * np.pi * site.f_n_Hz / f1**2  # |d theta / d f1| [rad/Hz]
                    ds = min(ds, self.angle_step * abs(mu - 1.0) / rate / abs(f1_s))
                continue
            edge = site.f1_Hz * (1.0 - ahead * 0.9 * SITE_WINDOW)  # just inside the window
            if ahead * (edge - f1) > 0 and ahead * (f1 + ds * f1_s - edge) > 0:
                ds = min(ds, abs(edge - f1) / abs(f1_s))
        return ds

    def events(self, branch, a: Orbit, b: Orbit, st, steps) -> list[dict]:
        found = (superharmonic_between(site, (branch.points + [b])[-RUN:]) for site in self.sites)
        return [x for x in found if x]


def track(site: Site, points) -> list:
    """The site's multiplier at each of ``points`` (None outside its window): at the
    first point of a run inside the window, the lightly damped one (|mu| >= LIGHT)
    nearest the predicted angle 2 pi (f_n / f1 - k); at each next point, the one
    nearest the last one's angle moved by the predicted 2 pi f_n (1/f1 - 1/f1_last),
    so that other modes passing by are not taken for it.  A run restarts where
    none is within SITE_ANGLE of the prediction."""
    out, last = [], None
    for o in points:
        mu = np.asarray(o.multipliers)
        mu = mu[np.abs(mu) >= LIGHT]
        if not site.near(o.f1_Hz) or mu.size == 0 or not site.holds_at(o):
            out.append(None)
            last = None
            continue
        if last is None:
            want = site.angle(o.f1_Hz)
        else:
            want = np.angle(last[0]) + 2 * np.pi * site.f_n_Hz * (1 / o.f1_Hz - 1 / last[1])
        miss = np.abs(np.angle(mu * np.exp(-1j * want)))
        k = int(np.argmin(miss))
        if miss[k] > SITE_ANGLE:
            out.append(None)
            last = None
            continue
        out.append(complex(mu[k]))
        last = (out[-1], o.f1_Hz)
    return out


def superharmonic_between(site: Site, points) -> dict | None:
    """The site's resonance between the last two ``points`` (a, b), where the
    angle of the site's tracked multiplier changes sign: k f1 passes the orbit's
    own f_n there.  Located by linear interpolation of the angle in 1/f1 (theta =
    2 pi (f_n / f1 - k) is linear in 1/f1 while f_n holds), with |mu|, T max and
    T max - T min interpolated linearly in the same weight; ``distance`` is
    |mu - 1| there, | |mu| - 1 |.  (The former vertex of the parabola through
    |mu - 1|^2 of three points moved by 1.7e-3 Hz at the N = 8 2:1 site when the
    points were twice as far apart; this zero moved by 2e-5 Hz.)"""
    if len(points) < 2:
        return None
    a, b = points[-2:]
    mus = track(site, points)[-2:]
    if any(m is None for m in mus):
        return None
    ta, tb = np.angle(mus)
    if not ((ta > 0 >= tb or ta < 0 <= tb) and abs(ta - tb) < np.pi):
        return None
    w = ta / (ta - tb)
    at = lambda va, vb: float(va + w * (vb - va))  # noqa: E731
    fv = 1.0 / at(1.0 / a.f1_Hz, 1.0 / b.f1_Hz)
    mu = complex(at(abs(mus[0]), abs(mus[1])), 0.0)  # on the positive real axis there
    return {"f1_Hz": fv, "kind": "superharmonic", "order": site.k, "f_n_Hz": site.f_n_Hz,
            "distance": abs(mu.real - 1.0),
            "tension_max_N": at(a.tension_max_N, b.tension_max_N),
            "oscillation_N": at(a.tension_max_N - a.tension_min_N,
                                b.tension_max_N - b.tension_min_N),
            "multiplier": [mu.real, mu.imag], "bracket_Hz": [a.f1_Hz, b.f1_Hz]}
