"""The compiled steps' time data for a whole stretch of steps at once (issue 46):
the constants of F and the Dirichlet values g at each stage time, without a
Python ``set_time`` per step.

The forms' time data depend on t only through the ends' forcing laws: t itself,
the torque ramp m_N(t) of Eq. (69) and the circle of Eq. (70) (cos and sin of
its phase); each constant and each g is an affine function of these
:func:`features`.  :class:`TimeDataFit` finds that affine map once per scene (a
least-squares fit on the formulation's own ``set_time`` at a few times), checks
it at other times to round-off, and then evaluates a stretch as one matrix
product of the features' changes from the stretch's end, where set_time is
called once (so a constant set outside set_time, as the sweep's offset C of
Eq. (40), is read as it is now, and the form is left at the stretch's end).  A formulation with any other time data (a hook in ``time_data``: the
weather, a release, a prescribed end twist) or a fit that does not hold is not
fitted: :meth:`TimeDataFit.__call__` returns None and the caller uses set_time.
"""

from __future__ import annotations

import numba
import numpy as np

#: the fit must reproduce set_time at the check times to this (relative to the
#: largest value of each column, >= 1): round-off of the least-squares solve
FIT_TOL = 1e-12

# the times of the fit and of its check [normalised, from the stretch's start]: not
# multiples of each other, over a forcing period and the ramp's time scale
_FIT_TIMES = np.array([0.0, 0.013, 0.041, 0.097, 0.23, 0.61, 1.37, 2.9, 6.1, 13.3, 29.0, 71.0])
_CHECK_TIMES = np.array([0.0071, 0.173, 0.77, 4.3, 37.0])


def features(q, times) -> np.ndarray:
    """(len(times), 5): 1, t, m_N(t) (Eq. 69), cos and sin of the end's phase (Eq. 70)."""
    times = np.asarray(times, dtype=float)
    out = np.empty((times.size, 5))
    out[:, 0], out[:, 1] = 1.0, times
    out[:, 2] = [q.top_torque(t) for t in times.tolist()]
    phase = q.phase(times)
    out[:, 3], out[:, 4] = np.cos(phase), np.sin(phase)
    return out


@numba.njit(cache=True)
def _affine(phi, end, C):
    """end + (phi[k] - phi[-1]) C for each row k but the last (the stretch's end).
    Compiled, not numpy's matrix product: after the product (or a broadcast sum) at
    these sizes, the next compiled steps of a 4-step stretch ran 1.75 times slower
    (115-135 against 76 us a step, measured; not understood, not seen at 3 or 5)."""
    last = phi.shape[0] - 1
    out = np.empty((last, C.shape[1]))
    for k in range(last):
        for j in range(C.shape[1]):
            s = end[j]
            for i in range(C.shape[0]):
                s += (phi[k, i] - phi[last, i]) * C[i, j]
            out[k, j] = s
    return out


class TimeDataFit:
    """(constants of F, g) at many stage times by the affine map of :func:`features`
    (module docstring).  ``sample(t)`` returns the formulation's own (constants, g)
    at t (it calls set_time); ``form`` is the formulation (its ``rod.q``,
    ``moving_top`` and ``time_data`` decide when the fit is redone or refused)."""

    def __init__(self, form, sample):
        self.form, self.sample = form, sample
        self._key, self._map = None, None

    def _fit(self, t0: float):
        q = self.form.rod.q
        rows = [np.concatenate(self.sample(t0 + t)) for t in _FIT_TIMES]
        Phi = features(q, t0 + _FIT_TIMES)
        scale = np.abs(Phi).max(axis=0)
        scale[scale == 0] = 1.0
        C = np.linalg.lstsq(Phi / scale, np.array(rows), rcond=None)[0] / scale[:, None]
        check = np.array([np.concatenate(self.sample(t0 + t)) for t in _CHECK_TIMES])
        err = np.abs(features(q, t0 + _CHECK_TIMES) @ C - check)
        size = np.maximum(1.0, np.abs(np.vstack([rows, check])).max(axis=0))
        if not np.all(err <= FIT_TOL * size):
            return None
        # the least-squares round-off (~1e-20) on data a feature does not move: zero
        C[np.abs(C) * scale[:, None] <= FIT_TOL * size] = 0.0
        return C

    def __call__(self, times, t_end: float, split: int):
        """(cF, G) at ``times`` (cF: the first ``split`` columns) from set_time's at
        ``t_end`` (the form is left there), or None when the time data are not the
        forcing laws' alone (the caller then uses set_time)."""
        form = self.form
        if form.time_data:
            return None
        key = (form.rod.q, form.moving_top)
        if self._key is None or self._key[0] is not key[0] or self._key[1] != key[1]:
            self._key, self._map = key, self._fit(float(times[0]))
        if self._map is None:
            return None
        end = np.concatenate(self.sample(t_end))
        values = _affine(features(form.rod.q, np.append(times, t_end)), end, self._map)
        return values[:, :split], values[:, split:]
