"""The limits block of a sweep's points and of an orbit branch's points (issue 29,
studies/analysis/branch_limits.py): carried, stored, loaded from before it existed, and the
orbit's moment ratio against a brute-force integration of the same orbit."""

import json
from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI

from rawehelix.members import CRITERIA
from rawehelix.studies.analysis import branch_limits

# FE at N = 2: a few seconds a point (tests/test_sweep.py's FE_TINY)
from rawehelix.studies.store import checkpoints, sweep_store
from rawehelix.studies import scene, sweep
TINY = {"lead_in_s": 0.2, "min_periods": 2, "max_periods": 3, "record_periods": 1,
        "periodic_tolerance": 0.1}
DOCS_SWEEP = Path(__file__).resolve().parents[1] / "docs" / "sweep" / "fe_N8" / "summary.json"


def fe_tiny():
    return scene.load("mobile_end", scheme="fe", elements=2, degree=2).replace(
        sweep=TINY, time={"dt_s": 2e-3})


def test_a_sweep_point_carries_the_block_and_tracking_changes_no_number(tmp_path):
    params = fe_tiny()
    on = sweep.compute(params, [8.0], comm=MPI.COMM_SELF)
    off = sweep.compute(params, [8.0], comm=MPI.COMM_SELF, track=False)
    (p,), (q,) = on.points, off.points
    for key in ("tension_max_N", "tension_min_N", "tension_mean_N", "periods"):
        assert p[key] == q[key]  # the sampler copies dofs and restores them bit for bit
    block = p["limits"]
    assert block["status"] == "recorded"
    # one recorded period at samples_per_period output times
    assert block["samples"] == params.sweep.samples_per_period * TINY["record_periods"]
    assert p["moment_ratio_max"] == block["moment_ratio_max"]["value"] > 0
    assert p["slack_fraction_max"] == block["slack_fraction_max"]
    assert p["first_limit"] == (block["first_limit"] or {}).get("kind")
    assert q["limits"]["status"].startswith("not recorded") and q["moment_ratio_max"] is None
    summary = on.summary["limits"]
    assert summary["moment_ratio_max"]["f1_Hz"] == 8.0
    assert summary["moment_ratio_max"]["value"] == p["moment_ratio_max"]
    on.write(tmp_path)
    written = json.loads((tmp_path / "summary.json").read_text())
    assert written["points"][0]["limits"] == json.loads(json.dumps(block))
    assert (tmp_path / "sweep.png").exists()


def test_the_spline_reference_says_its_block_is_not_available():
    params = scene.load("mobile_end", scheme="spline", elements=2).replace(
        sweep={**TINY, "lead_in_s": 0.5})
    (p,) = sweep.compute(params, [9.0], comm=MPI.COMM_SELF).points
    assert p["limits"]["status"] == branch_limits.NOT_AVAILABLE
    assert p["moment_ratio_max"] is None and p["slack_fraction_max"] is None


def test_a_sweep_stored_before_the_block_still_loads(tmp_path):
    """A checkpoint whose points have no block (resealed without it, as an older
    rawehelix wrote them) resumes with nothing computed, each block 'not recorded'
    and no number; the shipped docs/sweep/fe_N8 summary (written before) plots."""
    params = scene.load("mobile_end", scheme="spline", elements=2).replace(
        sweep={**TINY, "lead_in_s": 0.5})
    first = sweep.compute(params, [9.0, 9.5], comm=MPI.COMM_SELF, checkpoint=tmp_path)
    assert first.summary["computed_now"] == 2
    store = sweep_store.DirectoryStore(tmp_path, {"fingerprint": sweep_store.fingerprint(params)})
    for path in sorted((tmp_path / "points").glob("f1_*.json")):
        record, stamp = checkpoints.read(path, store.fingerprint, store.options,
                                         sweep_store.SCHEMA)
        old = {k: v for k, v in record["entry"].items()
               if k not in ("limits",) + branch_limits.FLAT}
        path.write_text(json.dumps(checkpoints.seal({**record, "entry": old}, store.fingerprint,
                                                    store.options, stamp["files"])))
    again = sweep.compute(params, [9.0, 9.5], comm=MPI.COMM_SELF, checkpoint=tmp_path)
    assert again.summary["computed_now"] == 0
    for p, q in zip(again.points, first.points):
        assert p["tension_max_N"] == q["tension_max_N"]
        assert p["limits"]["status"] == branch_limits.NOT_RECORDED
        assert all(p[k] is None for k in branch_limits.FLAT)
    assert again.summary["limits"]["points_without"] == 2
    assert again.summary["limits"]["moment_ratio_max"] is None
    old = [branch_limits.loaded(p) for p in json.loads(DOCS_SWEEP.read_text())["points"]]
    assert all(p["limits"]["status"] == branch_limits.NOT_RECORDED for p in old)
    assert sweep.sweep_png(tmp_path / "old.png", old, {}, "old") is not None


def test_the_summary_block_finds_the_first_limit_by_f1():
    def point(f1, ratio, kind):
        block = {"status": "recorded", "slack_fraction_max": 0.0,
                 "moment_ratio_max": {"value": ratio, "s_m": 1.0, "t_s": 0.1},
                 "first_limit": {"kind": kind, "s_m": 2.0, "t_s": 0.2} if kind else None}
        return branch_limits.with_block({"f1_Hz": f1}, block)
    points = [point(1.0, 0.2, None), point(2.0, 0.7, "slack"), point(3.0, 1.5, "slack"),
              point(4.0, 0.9, "moment_saturation"), branch_limits.loaded({"f1_Hz": 5.0})]
    out = branch_limits.over_points(points)
    assert out["first_limit"]["f1_Hz"] == 2.0 and out["first_limit"]["kind"] == "slack"
    assert out["moment_ratio_max"]["value"] == 1.5 and out["moment_ratio_max"]["f1_Hz"] == 3.0
    assert out["first_f1_moment_ratio_above_0.5_Hz"] == 2.0
    assert out["first_f1_moment_ratio_above_1_Hz"] == 3.0
    assert out["points_recorded"] == 4 and out["points_without"] == 1


@pytest.mark.long  # 7.6 s: make test's budget (2026-12-05); make test keeps
# test_the_orbits_summary_carries_the_branch_block_and_resumes_it and the sweep point's block
def test_an_orbit_point_carries_the_observables_and_agrees_with_brute_force():
    """The shooting orbit's moment_ratio_max over one period (AlphaMap.sections, the
    generalised-alpha stepper's period from the orbit's state) against the sweep's
    (PETSc TS alpha2 integrated from the stationary state until periodic, the
    Tracker over its last period at its 64 output times): two computations.  N = 4,
    10 Hz, dt = 1 ms (100 steps a period, all sampled by the orbit).  Measured
    2026-12-03: moment ratio 5.5208 (slack fraction 1/2), the two within 1.3e-6,
    T max within 1.4e-7; asserted to 1e-4 and 1e-5 (the sweep's periodicity test at
    1e-4 of the oscillation, the sampling at the same steps)."""
    from rawehelix.solvers.orbits import AlphaMap
    params = scene.load("mobile_end", elements=4).replace(time={"dt_s": 1e-3})
    m = AlphaMap(params)
    orbit = m.orbit(m.X_stationary, 10.0, lead_in=5)
    limits = branch_limits.OrbitLimits(m, params)
    entry = limits.entry(orbit)
    assert entry["tension_max_N"] == orbit.tension_max_N
    assert entry["limits"]["status"] == "recorded"
    assert entry["moment_ratio_max"] == entry["limits"]["moment_ratio_max"]["value"]
    assert entry["slack_fraction_max"] == entry["limits"]["slack_fraction_max"]
    assert {ob.name for ob in limits.observables} == {"moment_ratio_max", "slack_fraction_max"}
    with pytest.raises(ValueError, match="finished orbit only"):
        limits.observables[0].samples_value(np.zeros(3))
    brute = params.replace(sweep={"record_periods": 1, "periodic_tolerance": 1e-4})
    (p,) = sweep.compute(brute, [10.0], comm=MPI.COMM_SELF).points
    assert p["periodic"]
    assert p["tension_max_N"] == pytest.approx(orbit.tension_max_N, rel=1e-5)
    assert p["moment_ratio_max"] == pytest.approx(entry["moment_ratio_max"], rel=1e-4)
    assert p["slack_fraction_max"] == entry["slack_fraction_max"]


def test_the_orbits_summary_carries_the_branch_block_and_resumes_it(tmp_path):
    """`orbits` (N = 4, 9.0 -> 9.1 Hz): every branch point carries its block, the
    summary the branch's (the extremes over the points, the first limit by f1); a
    resumed branch (points read back from the store) gets the same blocks."""
    from rawehelix.studies import orbits
    params = scene.load("mobile_end", elements=4).replace(time={"dt_s": 1e-3})
    first = orbits.compute(params, 9.0, 9.1, outdir=tmp_path, superharmonics=())
    again = orbits.compute(params, 9.0, 9.1, outdir=tmp_path, superharmonics=())
    assert len(first.branch) >= 2
    for p, q in zip(first.branch, again.branch):
        assert p["limits"]["status"] == "recorded"
        assert p["moment_ratio_max"] == p["limits"]["moment_ratio_max"]["value"]
        assert q["moment_ratio_max"] == p["moment_ratio_max"]
    block = first.summary["limits"]
    top = max(first.branch, key=lambda p: p["moment_ratio_max"])
    assert block["moment_ratio_max"]["value"] == top["moment_ratio_max"]
    assert block["moment_ratio_max"]["f1_Hz"] == top["f1_Hz"]
    assert block["first_limit_by"].startswith(orbits.ALONG)  # the run's order, not the lowest f1
    reached = [p for p in first.branch if p["first_limit"] is not None]
    assert (block["first_limit"] or {}).get("f1_Hz") == (reached[0]["f1_Hz"] if reached else None)
    assert set(first.summary["limits_first_by_kind"]) == set(CRITERIA)


def test_the_spline_maps_orbit_block_says_not_available():
    """The spline reference's period map has no section fields along s: its
    orbits' blocks say so, with no number (and no period run for them)."""
    from types import SimpleNamespace

    from rawehelix.studies import schemes
    params = scene.load("mobile_end", scheme="spline", elements=2)
    limits = branch_limits.OrbitLimits(schemes.of(params).period_map(params), params)
    orbit = SimpleNamespace(f1_Hz=9.0, X=None, steps=None, entry=lambda: {"f1_Hz": 9.0})
    entry = limits.entry(orbit)
    assert entry["limits"]["status"] == branch_limits.NOT_AVAILABLE
    assert entry["moment_ratio_max"] is None and entry["slack_fraction_max"] is None
