"""The scene's ``[wind]`` in time (issue 44): the refusals of ``wind.kind`` and its
keys, one line each, before any work, and the reading of a wind file
(operation/wind_series.py has the laws, operation/turbulence.py the turbulence)."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np

from rawehelix.operation import turbulence
from rawehelix.operation.turbulence import MAX_SAMPLES
from rawehelix.operation import wind as profile_law
from rawehelix.operation.wind import top_height_m
from rawehelix.operation.wind_series import (KINDS, TURBULENCE_CLASSES, WIND_CLASSES,
                                             extreme_speed_1yr, series_fault)
from rawehelix.parameters.checks import ParameterError, _non_negative, _positive
from rawehelix.parameters.tables import read_csv

#: each time key and the kinds that use it (another kind refuses it: a key that would
#: change nothing is a mistake worth a line)
KIND_KEYS = {"step_to_m_s": ("step",), "step_time_s": ("step",), "rise_time_s": ("step",),
             "gust_start_s": ("gust",), "wind_class": ("gust",),
             "turbulence_class": ("gust", "turbulent"), "hub_height_m": ("gust", "turbulent"),
             "seed": ("turbulent",), "turbulence_intensity": ("turbulent",),
             "duration_s": ("turbulent",), "time_step_s": ("turbulent",), "file": ("file",)}
#: a wind file's columns: time_s and one of these sets
FILE_COLUMNS = (("speed_m_s",), ("u_m_s", "v_m_s", "w_m_s"))
FILE_STEP_TOLERANCE = 1e-6  # a file's steps may differ by this fraction of its first [-]
MIN_SAMPLES = 16  # a turbulent series' fewest samples, duration_s / time_step_s [-]
MAX_SEED = 2**32 - 1  # numpy's legacy seeds (pyconturb's)


def check_section(w) -> None:
    """``[wind]``'s time keys alone (Wind.__post_init__, the wind on)."""
    if w.kind not in KINDS:
        raise ParameterError("wind.kind", w.kind, f"must be one of {KINDS}")
    for f in dataclasses.fields(w):
        kinds = KIND_KEYS.get(f.name)
        if kinds and w.kind not in kinds and getattr(w, f.name) != f.default:
            raise ParameterError(f"wind.{f.name}", getattr(w, f.name),
                                 f"is for wind.kind = {' or '.join(map(repr, kinds))} only "
                                 "(remove the key, or set that wind.kind)")
    if w.kind == "step":
        _non_negative("wind", w, "step_time_s", "rise_time_s")
        if w.step_to_m_s is None:
            raise ParameterError("wind.step_to_m_s", None, "is required with wind.kind = 'step' "
                                 "(the reference speed after the step) [m/s]")
        _non_negative("wind", w, "step_to_m_s")
    if w.kind in ("gust", "turbulent"):
        if w.turbulence_class not in TURBULENCE_CLASSES:
            raise ParameterError("wind.turbulence_class", w.turbulence_class,
                                 f"must be one of {tuple(TURBULENCE_CLASSES)} (IEC 61400-1)")
        if w.hub_height_m is not None:
            _positive("wind", w, "hub_height_m")
    if w.kind == "gust":
        if w.wind_class not in WIND_CLASSES:
            raise ParameterError("wind.wind_class", w.wind_class,
                                 f"must be one of {tuple(WIND_CLASSES)} (IEC 61400-1)")
        _non_negative("wind", w, "gust_start_s")
    if w.kind == "turbulent":
        _check_turbulent(w)
    if w.kind == "file":
        if w.file is None:
            raise ParameterError("wind.file", None, "is required with wind.kind = 'file' (a CSV "
                                 "with time_s and speed_m_s, or u_m_s, v_m_s, w_m_s)")
        if not (isinstance(w.file, str) and w.file.lower().endswith(".csv")):
            raise ParameterError("wind.file", w.file, "must be a CSV file's name (*.csv)")
        object.__setattr__(w, "_series", read_file(w.file))


def _check_turbulent(w) -> None:
    if not turbulence.available():
        raise ParameterError("wind.kind", w.kind, "needs the package pyconturb: run 'make "
                             "install' (or pip install --no-deps pyconturb==2.7.4)")
    if isinstance(w.seed, bool) or not isinstance(w.seed, int) or not 0 <= w.seed <= MAX_SEED:
        raise ParameterError("wind.seed", w.seed, f"must be an integer from 0 to {MAX_SEED}")
    if w.turbulence_intensity is not None:
        ti = w.turbulence_intensity
        if not (0 < ti <= 1 and math.isfinite(ti)):
            raise ParameterError("wind.turbulence_intensity", ti, "must lie in (0, 1] "
                                 "(sigma_u / V_hub; IEC's class B at 10 m/s: 0.18)")
    _positive("wind", w, "duration_s", "time_step_s")
    samples = w.duration_s / w.time_step_s
    if not MIN_SAMPLES <= samples <= MAX_SAMPLES:
        raise ParameterError("wind.time_step_s", w.time_step_s,
                             f"must give {MIN_SAMPLES} to {MAX_SAMPLES} samples over "
                             "wind.duration_s (duration_s / time_step_s)")


def read_file(name: str) -> dict:
    """A wind file's columns as numpy arrays, checked (operation/wind_series.series_fault):
    ParameterError("wind.file", ...) naming the line."""
    header = _header(Path(name))
    columns = next((c for c in FILE_COLUMNS if all(x in header for x in c)), FILE_COLUMNS[0])
    values, lines = read_csv("wind.file", Path("."), name, ("time_s",) + columns)
    data = {k: np.asarray(v, float) for k, v in values.items()}
    fault = series_fault(data["time_s"], {c: data[c] for c in columns}, FILE_STEP_TOLERANCE)
    if fault:
        row, _, what = fault
        where = f"line {lines[row - 1]}: " if row else ""
        raise ParameterError("wind.file", name, f"{where}{what}")
    return data


def _header(path: Path) -> list[str]:
    """The names of a CSV's first non-comment line (read_csv reports a missing file)."""
    try:
        for line in path.read_text(encoding="utf-8").splitlines():
            if line.strip() and not line.lstrip().startswith("#"):
                return [h.strip() for h in line.split(",")]
    except (OSError, UnicodeDecodeError):
        pass
    return []


def hub_height(params) -> float:
    """z_hub [m]: wind.hub_height_m, else the top end's height."""
    given = params.wind.hub_height_m
    return top_height_m(params) if given is None else given


def check(params) -> None:
    """What the wind's history cannot run with (the whole scene; the wind on)."""
    w = params.wind
    hub = dataclasses.replace(profile_law.from_params(params), hub_height_m=hub_height(params))
    v_hub = hub.hub_speed
    if w.kind in ("gust", "turbulent") and not v_hub > 0:
        raise ParameterError("wind.speed_m_s", w.speed_m_s, f"gives V = {v_hub:g} m/s at the "
                             f"hub ({hub.hub_height_m:g} m): wind.kind = {w.kind!r} needs a "
                             "wind > 0 there")
    if w.kind == "gust":
        v_e1 = extreme_speed_1yr(WIND_CLASSES[w.wind_class])
        if not v_hub < v_e1:
            raise ParameterError("wind.speed_m_s", w.speed_m_s,
                                 f"gives V_hub = {v_hub:g} m/s, not below V_e1 = {v_e1:g} m/s "
                                 f"of wind.wind_class = {w.wind_class!r} (IEC's gust needs "
                                 "V_hub < V_e1: a stronger class, I or II)")
    fault = too_short(params, params.time.until_s, "time.until_s")
    if fault:
        raise ParameterError(*fault)
    if w.kind == "file":
        if not hub.factor(hub.hub_height_m) > 0:
            raise ParameterError("wind.profile", w.profile,
                                 f"is 0 at the hub ({hub.hub_height_m:g} m): it cannot spread "
                                 "the file's hub speed in height")


def synthesis_samples(params) -> int:
    """The samples a run's turbulence synthesis makes at each of its points (0 for the
    other kinds: their histories are a few thousand numbers)."""
    w = params.wind
    if not (w.active and w.kind == "turbulent"):
        return 0
    return int(w.duration_s / w.time_step_s) + 1


def too_short(params, until_s: float, key: str):
    """(key, value, what) when the wind's series ends before a run to ``until_s``
    (``key``: time.until_s, or the command's --until), else None."""
    w = params.wind
    if not w.active:
        return None
    if w.kind == "turbulent" and w.duration_s < until_s:
        return ("wind.duration_s", w.duration_s, f"is shorter than the run, {key} = "
                f"{until_s!r}: give a longer series (or a shorter run)")
    if w.kind == "file":
        t = w.series["time_s"]
        if t[0] > 0 or t[-1] < until_s:
            return ("wind.file", w.file, f"covers {t[0]:g} to {t[-1]:g} s; the run needs 0 "
                    f"to {key} = {until_s!r} s (a longer file, or a shorter run)")
    return None
