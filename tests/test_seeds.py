"""Issue 44, statistics over seeds: ``wind.seed`` as a study key (studies/seeds.py),
the run's statistics as named quantities (studies/quantities.py, studies/simulate.py's
``statistics``), the figure against the wind speed, and the refusal of a seed study
too big for the memory before any work (studies/resources.py)."""

from __future__ import annotations

import numpy as np
import pytest

from rawehelix.errors import SceneError
from rawehelix.studies import resources, scene, seeds, study
from rawehelix.studies.sampling import Variable

WANTED = ("power_mean_W", "member_force_min_N")


def _records():
    """Three seeds at two wind speeds, one point failed (None)."""
    rng = np.random.default_rng(7)
    out, i = {}, 0
    for v in (6.0, 8.0):
        for seed in (1, 2, 3):
            values = {q: float(rng.normal(100 * v, 10)) for q in WANTED}
            if (v, seed) == (8.0, 2):
                values["power_mean_W"] = None
            out[f"p{i:05d}"] = {"kind": "design", "values": values,
                                "overrides": {"wind.seed": seed, "wind.speed_m_s": v}}
            i += 1
    return out


def test_statistics_over_seeds_are_numpys_per_wind_speed():
    """mean, std (ddof 1) and max over the seeds of each quantity, per wind speed, equal
    numpy's over the same values; a failed point leaves its seed out of its quantity;
    a study that does not vary the seed has none."""
    records = _records()
    variables = [Variable("wind.seed", 1, 3, 3), Variable("wind.speed_m_s", 6, 8, 2)]
    rows = seeds.statistics(records, variables, WANTED)
    assert [r["keys"] for r in rows] == [{"wind.speed_m_s": 6.0}, {"wind.speed_m_s": 8.0}]
    for row in rows:
        v = row["keys"]["wind.speed_m_s"]
        for q in WANTED:
            y = [r["values"][q] for r in records.values()
                 if r["overrides"]["wind.speed_m_s"] == v and r["values"][q] is not None]
            got = row["quantities"][q]
            assert got["seeds"] == len(y)
            assert got["mean"] == pytest.approx(np.mean(y), rel=1e-14)
            assert got["std"] == pytest.approx(np.std(y, ddof=1), rel=1e-14)
            assert got["max"] == max(y)
    assert rows[1]["quantities"]["power_mean_W"]["seeds"] == 2
    assert seeds.winds(rows) == [6.0, 8.0]
    assert seeds.statistics(records, [Variable("wind.speed_m_s", 6, 8, 2)], WANTED) is None


def test_a_seed_study_gives_statistics_a_figure_and_a_report(tmp_path):
    """`study turbulent_rated --vary wind.seed=1:2:2` at N = 2, 0.3 s of a 2 s series:
    each seed's run gives the seven quantities; two seeds differ; the summary's seeds
    row is their statistics; seeds.png is written; the report says them."""
    names = ["power_mean_W", "tension_s0_max_N", "tension_L0_max_N", "member_force_min_N",
             "moment_ratio_max", "twist_max_rad_m", "slack_time_fraction"]
    source = study.Source("turbulent_rated", elements=2, overrides={
        "time.until_s": 0.3, "wind.duration_s": 2.0})
    result = study.compute(source, [study.parse_vary("wind.seed=1:2:2")], names, tmp_path,
                           fd_step=0)
    result.write(tmp_path)
    assert not result.summary["failed"]
    power = result.column("power_mean_W")
    assert len(power) == 2 and power[0] != power[1] and np.all(power > 100)
    (row,) = result.summary["seeds"]
    assert row["quantities"]["power_mean_W"]["mean"] == pytest.approx(power.mean(), rel=1e-14)
    assert 0 <= row["quantities"]["slack_time_fraction"]["max"] <= 1
    # operate at the scene's wind, 6.6131 m/s: 310.09 W (its V_n along the stationary
    # state's end tangent; the chord's gives the rigid shaft's 314.16 W)
    curve = result.summary["operating_curve"]
    assert curve["wind_m_s"] == [6.6131] and curve["power_W"][0] == pytest.approx(314.16, rel=3e-2)
    assert (tmp_path / "seeds.png").stat().st_size > 1000
    assert "over 2 seeds at wind.speed_m_s = 6.6131: power_mean_W" in study.report(result)


def test_a_seed_study_too_big_for_the_memory_is_refused_before_work(monkeypatch):
    """A simulate point's outputs (time.output_every_s) past the memory, and a turbulent
    synthesis on 4 ranks at once past a (pretend) 4 GB machine: one SceneError each,
    naming the key to change, from the points' check before any is run."""
    p = scene.load("turbulent_rated", elements=2)
    with pytest.raises(SceneError, match=r"output steps of 1e-06 s need about 300 GB"):
        resources.check_quantities(p.replace(time={"output_every_s": 1e-6}), ["power_mean_W"])
    monkeypatch.setattr(resources, "machine_bytes", lambda: 4e9)
    fine = p.replace(wind={"time_step_s": 0.05})
    resources.check_quantities(fine, ["power_mean_W"], copies=4)
    dense = p.replace(wind={"time_step_s": 0.001})  # 600001 samples, 0.84 GB a run
    resources.check_quantities(dense, ["power_mean_W"], copies=1)
    with pytest.raises(SceneError, match=r"6e\+05 samples of turbulence \(4 runs at once: fewer "
                                         r"ranks\) need about 4.39 GB.*--set wind.time_step_s="):
        resources.check_quantities(dense, ["power_mean_W"], copies=4)
