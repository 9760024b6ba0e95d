"""The wind in time and space (issue 44): a precomputed history V(z, t) the dynamics
evaluate each step, linear in time between its samples.

Along -i_E (Eq. 14's direction, the wind frame's u), at the height z [m] above the
helix's ground end and the time t [s]:

    V(z, t) = V_ref(t) f(z) + G(t) + u'(z, t)                                 [m/s]

f(z) the profile's V(z)/V_ref (operation/wind.py), V_ref(t) the reference speed's
history, G(t) a gust uniform in height and u' the turbulent fluctuation; the lateral
and vertical components (v, w) are the fluctuation's alone.  Each ``[wind] kind``:

* ``"steady"``: V_ref(t) = V_ref (the operating-points issue's wind, unchanged);
* ``"step"``: V_ref(t) from V_ref to V_2 at t_s with a half-cosine ramp of rise time
  t_r: V_ref + (V_2 - V_ref) (1 - cos(pi (t - t_s) / t_r)) / 2 on [t_s, t_s + t_r]
  (C1: no jump in V or dV/dt; t_r = 0 is a jump);
* ``"gust"``: IEC 61400-1 ed. 3's extreme operating gust (Sec. 6.3.2.2, Eqs. 16-17),
  from t_g:  G(t) = -0.37 V_gust sin(3 pi tau / T) (1 - cos(2 pi tau / T)),
  tau = t - t_g in [0, T], T = 10.5 s, V_gust = min(1.35 (V_e1 - V_hub),
  3.3 sigma_1 / (1 + 0.1 D / Lambda_1)), V_e1 = 0.8 * 1.4 V_ref,class,
  sigma_1 = I_ref (0.75 V_hub + 5.6), Lambda_1 = 0.7 z_hub (z_hub < 60 m) else 42 m.
  The same formula as NREL's IECWind and welib's ``welib/standards/IEC.py`` (EOG):
  two dips of -0.268 V_gust at tau = 0.234 T and 0.766 T, the peak +0.74 V_gust at
  tau = T/2, back to V_hub at T;
* ``"turbulent"``: u' of operation/turbulence.py (IEC Kaimal, IEC coherence,
  pyconturb) at the heights :data:`TURBULENCE_POINTS` of the hub's;
* ``"file"``: V_ref(t) = V_hub,file(t) / f(z_hub) (the profile spreads the file's hub
  speed in height), v and w the file's, uniform in height.

Before the first sample and after the last the history holds its end values (a
run longer than a turbulent or file history is refused at the scene's check).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from rawehelix.operation import turbulence
from rawehelix.operation import wind as profile_law
from rawehelix.operation.wind import WindProfile

#: I_ref of IEC 61400-1's turbulence classes (ed. 3 Table 1; A+ ed. 4) [-]
TURBULENCE_CLASSES = {"A+": 0.18, "A": 0.16, "B": 0.14, "C": 0.12}
#: V_ref of its wind turbine classes (ed. 3 Table 1) [m/s]
WIND_CLASSES = {"I": 50.0, "II": 42.5, "III": 37.5}
EOG_PERIOD_S = 10.5  # T, the extreme operating gust's duration (ed. 3 Eq. 17) [s]
#: (u, v, w) -> (x, y, z) of the ground frame E: downwind -i_E, lateral +j_E, up -k_E
FRAME_E = np.array([-1.0, 1.0, -1.0])

#: the heights of the turbulent points, as fractions of the hub's: along the helix's
#: chord to the top end, whose last point is the hub the rotor takes its wind at
TURBULENCE_POINTS = (0.25, 0.5, 0.75, 1.0)
#: the history's sampling of the step and the gust [s] (linear between: the gust's
#: largest |V''| ~ 0.37 V_gust (3 pi / T)^2 * 2 gives an error < 1e-3 V_gust)
LAW_STEP_S = 0.01


def ramp(t, start_s: float, rise_s: float):
    """The step's half-cosine ramp: 0 before ``start_s``, 1 after ``start_s + rise_s``,
    (1 - cos(pi (t - start_s) / rise_s)) / 2 between [-]."""
    t = np.asarray(t, float)
    if rise_s == 0:
        return (t >= start_s).astype(float)
    x = np.clip((t - start_s) / rise_s, 0.0, 1.0)
    return 0.5 * (1.0 - np.cos(math.pi * x))


def length_scale_m(hub_height_m: float) -> float:
    """Lambda_1, IEC 61400-1 ed. 3 Eq. (5): 0.7 z_hub below 60 m, else 42 m."""
    return 0.7 * hub_height_m if hub_height_m < 60.0 else 42.0


def sigma_1(i_ref: float, v_hub: float) -> float:
    """sigma_1 of the normal turbulence model, ed. 3 Eq. (11) [m/s]."""
    return i_ref * (0.75 * v_hub + 5.6)


def extreme_speed_1yr(v_ref: float) -> float:
    """V_e1 = 0.8 V_e50 = 0.8 * 1.4 V_ref at the hub, ed. 3 Eqs. (8), (10) [m/s]."""
    return 0.8 * 1.4 * v_ref


def gust_amplitude(v_hub: float, i_ref: float, v_ref: float, diameter_m: float,
                   hub_height_m: float) -> float:
    """V_gust, ed. 3 Eq. (16) [m/s]."""
    return min(1.35 * (extreme_speed_1yr(v_ref) - v_hub),
               3.3 * sigma_1(i_ref, v_hub) / (1.0 + 0.1 * diameter_m / length_scale_m(hub_height_m)))


def gust(tau, v_gust: float, period_s: float = EOG_PERIOD_S):
    """G(tau) of the extreme operating gust, ed. 3 Eq. (17); 0 outside [0, T] [m/s]."""
    tau = np.asarray(tau, float)
    inside = (tau >= 0) & (tau <= period_s)
    shape = np.sin(3 * math.pi * tau / period_s) * (1 - np.cos(2 * math.pi * tau / period_s))
    return np.where(inside, -0.37 * v_gust * shape, 0.0)


@dataclass(frozen=True)
class WindHistory:
    """V(z, t) (module docstring) from its samples.

    ``times_s`` (n,) increasing; ``reference_m_s`` V_ref(t) and ``gust_m_s`` G(t) at
    them (n,); ``fluctuation_m_s`` (n, m, 3) u', v', w' at ``heights_m`` (m,)
    increasing (m = 1: uniform in height), linear between heights and held below
    the lowest and above the highest."""

    profile: WindProfile
    times_s: np.ndarray
    reference_m_s: np.ndarray
    gust_m_s: np.ndarray
    heights_m: np.ndarray
    fluctuation_m_s: np.ndarray

    def __post_init__(self):
        n = len(self.times_s)
        if n < 2 or np.any(np.diff(self.times_s) <= 0):
            raise ValueError("WindHistory.times_s must hold >= 2 increasing times")
        if self.reference_m_s.shape != (n,) or self.gust_m_s.shape != (n,):
            raise ValueError("WindHistory: reference_m_s and gust_m_s must be (len(times_s),)")
        if self.fluctuation_m_s.shape != (n, len(self.heights_m), 3):
            raise ValueError("WindHistory.fluctuation_m_s must be (times, heights, 3)")

    @property
    def steady(self) -> bool:
        """The same wind at every time (V_ref and G constant, no fluctuation)."""
        return bool(np.ptp(self.reference_m_s) == 0 and np.ptp(self.gust_m_s) == 0
                    and not np.any(self.fluctuation_m_s))

    @property
    def duration_s(self) -> float:
        return float(self.times_s[-1])

    def _at(self, t: float):
        """(i, w): t lies at (1 - w) t_i + w t_{i+1}, clamped to the samples."""
        ts = self.times_s
        i = min(max(int(np.searchsorted(ts, t, side="right")) - 1, 0), len(ts) - 2)
        w = min(max((t - ts[i]) / (ts[i + 1] - ts[i]), 0.0), 1.0)
        return i, w

    def _series(self, x, i, w):
        return x[i] + w * (x[i + 1] - x[i]) if w else x[i]

    def parts(self, t: float):
        """(V_ref, G, u' v' w' at :attr:`heights_m` (m, 3)) at the time ``t`` [m/s]."""
        i, w = self._at(t)
        return (float(self._series(self.reference_m_s, i, w)),
                float(self._series(self.gust_m_s, i, w)),
                np.asarray(self._series(self.fluctuation_m_s, i, w), float))

    def speed(self, t: float, z_m):
        """(u, v, w) at the heights ``z_m`` (any shape) and the time ``t``: shape
        z.shape + (3,); u along -i_E [m/s]."""
        i, w = self._at(t)
        z = np.asarray(z_m, float)
        out = np.zeros(z.shape + (3,))
        out[..., 0] = self._series(self.reference_m_s, i, w) * self.profile.factor(z) \
            + self._series(self.gust_m_s, i, w)
        fluct = self._series(self.fluctuation_m_s, i, w)  # (m, 3)
        for k in range(3):
            if len(self.heights_m) == 1:
                out[..., k] += fluct[0, k]
            else:
                out[..., k] += np.interp(z, self.heights_m, fluct[:, k])
        return out

    def velocity_E(self, t: float, z_m):
        """The wind's velocity in the ground frame E (x, y, z; z down, Eq. 14's wind
        -v_w0 i_E): u along -i_E, v along +j_E, w up, along -k_E (u, v, w right-handed,
        pyconturb's) [m/s]; shape z.shape + (3,)."""
        return self.speed(t, z_m) * FRAME_E

    def along(self, t: float, z_m):
        """u(z, t), the component along -i_E [m/s]."""
        return self.speed(t, z_m)[..., 0]

    def mean_hub(self, t: float) -> float:
        """u at the hub at the time ``t`` without the turbulence's fluctuation u':
        V_ref(t) f(z_hub) + G(t), the wind a turbulent record fluctuates about [m/s]."""
        i, w = self._at(t)
        return self._hub_mean(self._series(self.reference_m_s, i, w),
                              self._series(self.gust_m_s, i, w))

    def _hub_mean(self, reference: float, gust: float) -> float:
        """V_ref f(z_hub) + G [m/s] of a time's reference speed and gust."""
        return float(reference * self.profile.factor(self.profile.hub_height_m) + gust)

    def hub_u(self, t: float) -> float:
        """u at the hub at the time ``t`` [m/s]: :meth:`along` at the hub height, the
        same operations on its scalars (a dynamic run asks it at every step)."""
        return self.hub_of(*self.parts(t))

    def hub_of(self, reference: float, gust: float, fluct) -> float:
        """u at the hub [m/s] of a time's :meth:`parts`."""
        z = self.profile.hub_height_m
        return self._hub_mean(reference, gust) + float(
            fluct[0, 0] if len(self.heights_m) == 1 else np.interp(z, self.heights_m, fluct[:, 0]))

    def hub(self, t) -> np.ndarray:
        """u at the hub at the times ``t`` [m/s]."""
        return np.array([self.hub_u(float(s)) for s in np.atleast_1d(t)])


def sampled(profile: WindProfile, times_s, reference_m_s=None, gust_m_s=None,
            heights_m=(0.0,), fluctuation_m_s=None) -> WindHistory:
    """A history from its samples; the parts not given are V_ref constant, no gust,
    no fluctuation."""
    t = np.asarray(times_s, float)
    ref = np.full(t.shape, profile.speed_m_s) if reference_m_s is None else np.asarray(reference_m_s, float)
    g = np.zeros(t.shape) if gust_m_s is None else np.asarray(gust_m_s, float)
    h = np.asarray(heights_m, float)
    fl = np.zeros((len(t), len(h), 3)) if fluctuation_m_s is None else np.asarray(fluctuation_m_s, float)
    return WindHistory(profile, t, ref, g, h, fl)


def steady(profile: WindProfile) -> WindHistory:
    """The profile's wind, constant in time (np.interp of equal samples is exact)."""
    return sampled(profile, (0.0, 1.0))


def step(profile: WindProfile, to_m_s: float, start_s: float, rise_s: float) -> WindHistory:
    """V_ref ramps to ``to_m_s`` (module docstring)."""
    end = start_s + rise_s
    n = max(2, int(math.ceil(rise_s / LAW_STEP_S)) + 1)
    t = np.unique(np.concatenate([[0.0], start_s + np.linspace(0.0, rise_s, n), [end + 1.0]]))
    ref = profile.speed_m_s + (to_m_s - profile.speed_m_s) * ramp(t, start_s, rise_s)
    return sampled(profile, t, reference_m_s=ref)


def extreme_operating_gust(profile: WindProfile, v_gust: float, start_s: float,
                           period_s: float = EOG_PERIOD_S) -> WindHistory:
    """G(t - start_s) of amplitude ``v_gust`` (module docstring)."""
    n = int(math.ceil(period_s / LAW_STEP_S)) + 1
    t = np.unique(np.concatenate([[0.0], start_s + np.linspace(0.0, period_s, n),
                                  [start_s + period_s + 1.0]]))
    return sampled(profile, t, gust_m_s=gust(t - start_s, v_gust, period_s))


def from_file(profile: WindProfile, times_s, hub_m_s, lateral_m_s=None,
              vertical_m_s=None) -> WindHistory:
    """The file's hub speed spread by the profile, V_ref(t) = V_hub(t) / f(z_hub);
    its lateral and vertical components uniform in height."""
    t = np.asarray(times_s, float)
    f_hub = float(profile.factor(profile.hub_height_m))
    fl = np.zeros((len(t), 1, 3))
    for k, comp in ((1, lateral_m_s), (2, vertical_m_s)):
        if comp is not None:
            fl[:, 0, k] = comp
    return sampled(profile, t, reference_m_s=np.asarray(hub_m_s, float) / f_hub,
                   fluctuation_m_s=fl)


def series_fault(times_s, values: dict, tolerance: float = 1e-6):
    """What makes a supplied time series unusable, or None: fewer than two rows,
    non-finite values, time not increasing, a non-uniform step (a gap) beyond
    ``tolerance`` of the first step.  (row, column, what); row 1-based."""
    t = np.asarray(times_s, float)
    if len(t) < 2:
        return 0, "time_s", f"has {len(t)} row(s); it needs at least 2"
    for name, col in {"time_s": t, **values}.items():
        bad = np.flatnonzero(~np.isfinite(np.asarray(col, float)))
        if len(bad):
            return int(bad[0]) + 1, name, f"{name} is not a finite number"
    dt = np.diff(t)
    if np.any(dt <= 0):
        i = int(np.flatnonzero(dt <= 0)[0])
        return i + 2, "time_s", (f"time_s must increase (row {i + 2}: {t[i + 1]:g} s after "
                                 f"{t[i]:g} s)")
    gaps = np.flatnonzero(np.abs(dt - dt[0]) > tolerance * dt[0])
    if len(gaps):
        i = int(gaps[0])
        return i + 2, "time_s", (f"the step must be uniform (a gap or uneven step: "
                                 f"{dt[i]:g} s from row {i + 1} to {i + 2}, the first step "
                                 f"{dt[0]:g} s); resample the file to one step")
    return None


def _steady_of(params, profile: WindProfile) -> WindHistory:
    return steady(profile)


def _step_of(params, profile: WindProfile) -> WindHistory:
    w = params.wind
    return step(profile, w.step_to_m_s, w.step_time_s, w.rise_time_s)


def _gust_of(params, profile: WindProfile) -> WindHistory:
    w = params.wind
    diameter = 2 * params.rotor.radius_m if params.rotor.active else 0.0  # D [m]
    v_gust = gust_amplitude(profile.hub_speed, TURBULENCE_CLASSES[w.turbulence_class],
                            WIND_CLASSES[w.wind_class], diameter, profile.hub_height_m)
    return extreme_operating_gust(profile, v_gust, w.gust_start_s)


def _turbulent_of(params, profile: WindProfile) -> WindHistory:
    w = params.wind
    z_hub, v_hub = profile.hub_height_m, profile.hub_speed
    heights = z_hub * np.asarray(TURBULENCE_POINTS)
    t, fl = turbulence.fluctuations(heights, z_hub, v_hub, turbulence_sigma(params, v_hub),
                                    length_scale_m(z_hub), w.duration_s, w.time_step_s, w.seed)
    return sampled(profile, t, heights_m=heights, fluctuation_m_s=fl)


def _file_of(params, profile: WindProfile) -> WindHistory:
    s = params.wind.series
    return from_file(profile, s["time_s"], s.get("speed_m_s", s.get("u_m_s")),
                     s.get("v_m_s"), s.get("w_m_s"))


#: each ``[wind] kind`` and how a scene's history of it is built
HISTORIES = {"steady": _steady_of, "step": _step_of, "gust": _gust_of,
             "turbulent": _turbulent_of, "file": _file_of}


def from_params(params) -> WindHistory:
    """The scene's wind history (``params.wind.kind``, :data:`HISTORIES`); the hub at
    wind.hub_height_m or the top end's height, D = 2 R of ``[rotor]`` (0 without a
    rotor).  The wind off: the paper's uniform wind, steady."""
    w = params.wind
    profile = profile_law.from_params(params)
    if not w.active:
        return steady(profile)
    if w.hub_height_m is not None:
        profile = dataclasses.replace(profile, hub_height_m=w.hub_height_m)
    return HISTORIES[w.kind](params, profile)


def moving(params) -> WindHistory | None:
    """The scene's wind history when it changes in time; None when it is steady (the
    [wind] section off, or a history whose samples are all one wind)."""
    if not params.wind.active:
        return None
    history = from_params(params)
    return None if history.steady else history


#: the kinds, in the order a scene's reference lists them
KINDS = tuple(HISTORIES)


def turbulence_sigma(params, v_hub: float) -> float:
    """sigma_u [m/s]: wind.turbulence_intensity V_hub, else IEC's NTM sigma_1 of the class."""
    w = params.wind
    if w.turbulence_intensity is not None:
        return w.turbulence_intensity * v_hub
    return sigma_1(TURBULENCE_CLASSES[w.turbulence_class], v_hub)


def hub_spectrum(params, history: WindHistory):
    """(f, Welch estimate, target) of u at the hub of a turbulent history (the figure's
    data; operation/turbulence.py's :func:`~turbulence.welch` and
    :func:`~turbulence.target`)."""
    w = params.wind
    z_hub, v_hub = history.profile.hub_height_m, history.profile.hub_speed
    u = history.fluctuation_m_s[:-1, -1, 0] + v_hub
    f, estimate = turbulence.welch(u, w.time_step_s)
    length = turbulence.LENGTH_RATIOS[0] * length_scale_m(z_hub)
    return f, estimate, turbulence.target(f, turbulence_sigma(params, v_hub), length, v_hub,
                                          w.duration_s, w.time_step_s)
