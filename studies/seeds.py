"""Statistics over seeds (issue 44): a study that varies ``wind.seed`` (an integer
key, ``rawehelix study SCENE --vary wind.seed=1:6:6 --vary wind.speed_m_s=...``) gets,
for each value of its other keys, the mean, the standard deviation (the seeds'
sample one, ddof = 1) and the maximum over the seeds of each quantity, and the
operating-points curve of the same scene (``rawehelix operate``) at the wind speeds
it varies, for the figure (studies/present/seeds_figure.py).  Failed points are left
out of their group's statistics (``seeds`` counts those that gave the quantity)."""

from __future__ import annotations

import numpy as np

SEED_KEY = "wind.seed"
WIND_KEY = "wind.speed_m_s"
#: the operating curve's fields beside a quantity of a seed study (operate's POINT_KEYS)
CURVE_FIELDS = {"power_mean_W": "power_W", "tension_s0_max_N": "tension_max_N",
                "tension_L0_max_N": "tension_max_N"}


def varies_seed(variables) -> bool:
    return any(v.key == SEED_KEY for v in variables)


def statistics(records: dict, variables, wanted, wind_m_s: float | None = None
               ) -> list[dict] | None:
    """Per value of the keys other than the seed (in point order): ``keys`` (with
    ``wind.speed_m_s`` = ``wind_m_s``, the scene's, when the study does not vary it),
    and for each quantity {seeds, mean, std, max} (None where no seed gave it); None
    for a study that does not vary the seed."""
    if not varies_seed(variables):
        return None
    others = [v.key for v in variables if v.key != SEED_KEY]
    groups: dict[tuple, list] = {}
    for r in records.values():
        if r["kind"] == "design":
            groups.setdefault(tuple(r["overrides"][k] for k in others), []).append(r)
    out = []
    for values, members in groups.items():
        keys = dict(zip(others, values))
        if WIND_KEY not in keys and wind_m_s is not None:
            keys[WIND_KEY] = float(wind_m_s)
        row = {"keys": keys, "quantities": {}}
        for name in wanted:
            y = np.array([r["values"][name] for r in members if r["values"][name] is not None],
                         dtype=float)
            row["quantities"][name] = {
                "seeds": int(len(y)),
                "mean": float(y.mean()) if len(y) else None,
                "std": float(y.std(ddof=1)) if len(y) > 1 else None,
                "max": float(y.max()) if len(y) else None}
        out.append(row)
    return out


def winds(rows: list[dict]) -> list[float]:
    """The wind speeds of a seed study's rows (sorted)."""
    return sorted({float(r["keys"][WIND_KEY]) for r in rows if WIND_KEY in r["keys"]})


def operating_curve(params, speeds, comm) -> dict:
    """The operating points of the scene at ``speeds`` [m/s] (studies/operate.py):
    {wind_m_s: [...], <operate's fields>: [...]} of its first branch, or {"error": why}
    when the scene has none (no rotor, no point in the table, a failed solve)."""
    from rawehelix.errors import SceneError, SolverError
    from rawehelix.studies import operate
    try:
        winds_ = operate.check_winds(speeds)
        result = operate.compute(params, winds_, comm, operate.plan(params, winds_))
    except (SceneError, SolverError, ValueError) as err:
        return {"error": f"{type(err).__name__}: {err}"}
    points = [p for p in result.summary["points"] if p.get("branch", 0) == 0]
    fields = ["wind_m_s", *sorted(set(CURVE_FIELDS.values()))]
    return {k: [p.get(k) for p in points] for k in fields}


__all__ = ["CURVE_FIELDS", "SEED_KEY", "WIND_KEY", "operating_curve", "statistics", "varies_seed",
           "winds"]
