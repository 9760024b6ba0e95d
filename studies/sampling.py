"""The design of a parameter study and its analysis: the varied keys
(``--vary KEY=START:STOP:COUNT``), the design's points (grid, Latin hypercube,
Saltelli's Sobol' design), the normalised sensitivities d ln Q / d ln p from
the finite-difference points and SALib's variance-based indices
(:mod:`rawehelix.studies.study` runs them).
"""

from __future__ import annotations

import itertools
import math
import warnings
from dataclasses import dataclass

import numpy as np

from rawehelix.errors import SceneError

SAMPLES = ("grid", "lhs", "sobol")
SEED = 0  # of the LHS and Sobol' designs and SALib's bootstrap


@dataclass(frozen=True)
class Variable:
    key: str
    start: float
    stop: float
    count: int | None = None


def parse_vary(text: str) -> Variable:
    """``KEY=START:STOP[:COUNT]`` (COUNT: grid points, >= 2)."""
    key, sep, spec = str(text).partition("=")
    parts = spec.split(":")
    try:
        if not sep or not key.strip() or len(parts) not in (2, 3):
            raise ValueError
        start, stop = float(parts[0]), float(parts[1])
        count = int(parts[2]) if len(parts) == 3 else None
    except ValueError:
        raise SceneError("--vary", text, "must be KEY=START:STOP:COUNT, e.g. "
                         "helix.EI_Nm2=3000:6000:4") from None
    if count is not None and count < 1:
        raise SceneError("--vary", text, "COUNT must be an integer >= 1")
    if not (math.isfinite(start) and math.isfinite(stop)):
        raise SceneError("--vary", text, "START and STOP must be finite numbers")
    return Variable(key.strip(), start, stop, count)


def design(variables: list[Variable], sample: str, points: int | None, seed: int = SEED):
    """The design's points, (n, d), in the box of the variables."""
    lo = np.array([v.start for v in variables])
    hi = np.array([v.stop for v in variables])
    d = len(variables)
    if sample == "grid":
        missing = [v.key for v in variables if v.count is None]
        if missing:
            raise SceneError("--vary", missing[0], "a grid needs KEY=START:STOP:COUNT")
        axes = [np.linspace(v.start, v.stop, v.count) for v in variables]
        return np.array(list(itertools.product(*axes)), dtype=float).reshape(-1, d)
    if points is None or points < 1:
        raise SceneError("--points", points, f"--sample {sample} needs --points N >= 1")
    if sample == "lhs":
        from scipy.stats import qmc
        return qmc.scale(qmc.LatinHypercube(d=d, seed=seed).random(points), lo, hi)
    if sample == "sobol":
        from SALib.sample import sobol
        if np.any(hi <= lo):
            raise SceneError("--vary", variables[int(np.argmax(hi <= lo))].key,
                             "--sample sobol needs START < STOP")
        return sobol.sample(problem(variables), points, calc_second_order=False, seed=seed)
    raise SceneError("--sample", sample, f"must be one of {', '.join(SAMPLES)}")


def problem(variables: list[Variable]) -> dict:
    """SALib's description of the box."""
    return {"num_vars": len(variables), "names": [v.key for v in variables],
            "bounds": [[v.start, v.stop] for v in variables]}


def design_size(variables: list[Variable], sample: str, points) -> int:
    """The number of design points, before the design is built."""
    if sample == "grid":
        return math.prod(v.count or 1 for v in variables)
    return (points or 0) * (len(variables) + 2 if sample == "sobol" else 1)


def sensitivities(records: dict, base: dict, wanted: list[str], fd_step: float) -> dict:
    """d ln Q / d ln p at the base point: {Q: {key: value or None}}."""
    out = {}
    step = math.log((1 + fd_step) / (1 - fd_step)) if 0 < fd_step < 1 else None
    for name in wanted:
        row = {}
        q0 = records.get("base", {}).get("values", {}).get(name)
        for key in base:
            minus = records.get(f"fd_{key}_minus", {}).get("values", {}).get(name)
            plus = records.get(f"fd_{key}_plus", {}).get("values", {}).get(name)
            ok = None not in (q0, minus, plus, step) and q0 != 0
            row[key] = (plus - minus) / (q0 * step) if ok else None
        out[name] = row
    return out


def variance_indices(sample: str, variables, X, Y, seed: int = SEED) -> dict | None:
    """SALib's indices of one quantity's values Y on the design X, or the reason there are none."""
    if sample == "grid":
        return None
    if not np.all(np.isfinite(Y)):
        return {"note": f"{int(np.sum(~np.isfinite(Y)))} failed points: no indices"}
    prob = problem(variables)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", FutureWarning)  # SALib's call of pandas.unique
            r, keys, method = _salib(sample, prob, X, Y, seed)
    except (ValueError, ZeroDivisionError, IndexError) as err:
        return {"note": f"SALib: {err}"}
    return {"method": method, **{v.key: {k: float(r[k][i]) for k in keys}
                                 for i, v in enumerate(variables)}}


def _salib(sample: str, prob: dict, X, Y, seed: int):
    if sample == "sobol":
        from SALib.analyze import sobol
        return (sobol.analyze(prob, Y, calc_second_order=False, seed=seed),
                ("S1", "S1_conf", "ST", "ST_conf"), "Sobol' (Saltelli design, SALib.analyze.sobol)")
    from SALib.analyze import rbd_fast
    return (rbd_fast.analyze(prob, X, Y, seed=seed), ("S1", "S1_conf"),
            "RBD-FAST first-order (SALib.analyze.rbd_fast)")
