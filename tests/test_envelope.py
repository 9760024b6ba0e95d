"""The operating envelope (issue 31): fold curves continued in a scene key end on the
next value's own one-parameter folds, the first-limit boundary is where fixed-f1 orbits
change their limit, ranks agree, a killed run resumes."""

import json
import types

import numpy as np
import pytest
from mpi4py import MPI

import rawehelix as rh
from rawehelix.errors import SceneError
from rawehelix.studies import envelope
from rawehelix.studies.analysis import envelope_curves

VARY, F1 = "helix.EI_Nm2=4381:4600:2", (11.9, 13.0)  # N = 2: folds near 12.01 and 12.74 Hz


def _scene():
    return rh.load_scene("mobile_end", elements=2, degree=3)


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    out = tmp_path_factory.mktemp("envelope")
    result = rh.envelope(_scene(), VARY, *F1, outdir=out, comm=MPI.COMM_SELF)
    result.write(out)
    return result, out


@pytest.mark.long  # the envelope of the small fixture, 25 s: make test-long (test_output_faults and
# test_first_limits run envelopes in make test)
def test_fold_curves_end_on_the_next_values_own_folds(small):
    """Each fold of EI = 4381 continued to 4600 by the minimally augmented system lands
    on the fold that the one-parameter branch at 4600 finds within 1e-3 Hz, and starts on
    its own branch's fold within that fold's error estimate."""
    result, _ = small
    s = result.summary
    assert [len(t["folds"]) for t in s["ticks"]] == [2, 2]
    curves = s["fold_curves"]
    assert len(curves) == 2
    for c in curves:
        assert c["fold_check_Hz"] is not None and abs(c["fold_check_Hz"]) <= 1e-3, c
        assert c["points"][-1]["value"] == 4600.0
        own = next(f for f in s["ticks"][0]["folds"] if f["f1_Hz"] == c["tick_fold_Hz"])
        assert abs(c["points"][0]["f1_Hz"] - own["f1_Hz"]) <= own["f1_error_Hz"] + 1e-4
    assert s["fold_check_max_Hz"] <= envelope_curves.CHECK_HZ


@pytest.mark.long  # the envelope of the small fixture, 25 s: make test-long (test_output_faults and
# test_first_limits run envelopes in make test)
def test_the_summary_is_documented_and_the_map_drawn(small):
    from tests.test_docs import undocumented
    result, out = small
    assert undocumented(json.loads((out / "summary.json").read_text())) == []
    assert (out / "envelope.png").stat().st_size > 0
    assert "fold curve from 4381 to 4600" in envelope.report(result)


@pytest.mark.long  # ~15 s: make test-long (the orbits' own resume is in make test)
@pytest.mark.long  # the envelope of the small fixture, 25 s: make test-long (test_output_faults and
# test_first_limits run envelopes in make test)
def test_a_killed_run_resumes(small, tmp_path):
    """The last three stored points of the second value's branch removed (a run killed
    there): a rerun computes just those again and ends with the same envelope."""
    import shutil
    result, out = small
    again = tmp_path / "again"
    shutil.copytree(out, again)
    window = again / "tick1" / "window0"
    stored = sorted(window.glob("p*.json"))
    for p in stored[-3:]:
        p.unlink()
        p.with_suffix(".npz").unlink()
    resumed = rh.envelope(_scene(), VARY, *F1, outdir=again, comm=MPI.COMM_SELF)
    strip = lambda ticks: [{k: v for k, v in t.items() if k != "wall_s"} for t in ticks]  # noqa: E731
    assert strip(resumed.summary["ticks"]) == strip(result.summary["ticks"])
    assert resumed.summary["fold_curves"] == result.summary["fold_curves"]
    log = (window / "computed.log").read_text().split("\n")[:-1]
    assert len(log) == len(stored) + 3  # the first run's points, then the three again


def test_the_limit_boundary_is_where_fixed_f1_orbits_change():
    """The bisection of envelope._crossing on a stand-in problem whose limit is reached
    above 12.3456 Hz: the boundary is located within its bracket, and the bracket is
    below 1/256 of the points' spacing."""
    orbit = lambda f1: types.SimpleNamespace(f1_Hz=f1, X=np.zeros(1), steps=3)  # noqa: E731
    m = types.SimpleNamespace(orbit=lambda X, f1, steps=None: orbit(f1))
    limits = types.SimpleNamespace(block=lambda o: {"first_limit": (
        {"kind": "slack"} if o.f1_Hz > 12.3456 else None)})
    c = envelope._crossing(m, limits, orbit(12.0), orbit(12.5), None, "slack", 1.0)
    assert abs(c["f1_Hz"] - 12.3456) <= c["f1_error_Hz"] <= 0.5 / 256
    assert c["kind"] == "slack" and c["entering"]


def test_the_key_and_window_are_checked():
    with pytest.raises(SceneError, match="not a scene key"):
        rh.envelope(_scene(), "helix.no_such_key=1:2:2", *F1)
    with pytest.raises(SceneError, match="COUNT >= 2"):
        rh.envelope(_scene(), "helix.EI_Nm2=4000:5000:1", *F1)
    with pytest.raises(SceneError, match="LO:HI"):
        rh.envelope(_scene(), VARY, 13.0, 11.0)
    with pytest.raises(SceneError):  # a value the scene's own checks refuse
        rh.envelope(_scene(), "helix.EI_Nm2=-1:5000:2", *F1)


@pytest.mark.mpi
def test_one_and_two_ranks_agree():
    """Under mpirun -n 2: each rank traces one value's branch; the envelope equals a
    serial one (rank 0 alone)."""
    comm = MPI.COMM_WORLD
    if comm.size != 2:
        pytest.skip("deals two values to two ranks: run under mpirun -n 2")
    window = (12.8, 13.0)  # a few points of each branch
    world = rh.envelope(_scene(), VARY, *window, comm=comm)
    if comm.rank == 0:
        serial = rh.envelope(_scene(), VARY, *window, comm=MPI.COMM_SELF)
        assert world.summary["ticks"] == [dict(t, wall_s=w["wall_s"]) for t, w in
                                          zip(serial.summary["ticks"], world.summary["ticks"])]
        assert world.summary["fold_curves"] == serial.summary["fold_curves"]
    comm.barrier()


@pytest.mark.long  # ~4 min: two tensegrity branches by HB, the curves, 12 shooting orbits
def test_the_tensegritys_unstable_band_is_the_shootings():
    """The Sec. 5.3 helix with the members' law (self-stress 30 N, bars EA 1e4 N, N = 4)
    has a narrow unstable band that moves up in f1 with the tension: 9.34-9.59 Hz at
    elongation 0.002 (a complex pair near -1 leaves the unit circle, turns real, and a real
    multiplier comes back through -1), 10.98-11.03 Hz at 0.005 (complex throughout).  The
    envelope over 0.002-0.005, its branches stepping at most 0.1 Hz, finds both
    boundaries on each branch and traces the two
    from 0.002 to 0.005, where they end on that branch's own within 1e-3 Hz.  At each
    curve's ends and middle the shooting (generalised-alpha, dt = 0.1 ms; the monodromy's
    multipliers) changes stability within 2e-3 Hz of it at that elongation."""
    from rawehelix.periodic_orbits.bifurcations import critical
    from rawehelix.solvers.harmonic_balance.problem import HarmonicBalance
    from rawehelix.solvers.orbits import AlphaMap

    sets = {"model.kinematics": "extensible", "section.law": "tensegrity",
            "section.self_stress_N": 30.0, "section.bar_EA_N": 1e4}
    params = rh.load_scene("mobile_end", elements=4, degree=3, overrides=sets)
    result = rh.envelope(params, "ends.elongation=0.002:0.005:2", 9.0, 11.3,
                         comm=MPI.COMM_SELF, f1_step_Hz=0.1)  # the branches land in the band
    s = result.summary
    curves = s["bifurcation_curves"]
    assert len(curves) == 2, curves
    for c in curves:
        assert (c["from_value"], c["to_value"]) == (0.002, 0.005)
        assert c["end"] == "reached the end of the window" and abs(c["check_Hz"]) <= 1e-3
    assert s["bifurcation_check_max_Hz"] <= envelope_curves.CHECK_HZ
    ends = sorted(c["points"][0]["f1_Hz"] for c in curves)
    assert ends[0] == pytest.approx(9.34, abs=0.01) and ends[1] == pytest.approx(9.585, abs=0.01)
    for c in curves:
        pts = c["points"]
        for point in (pts[0], pts[len(pts) // 2], pts[-1]):
            p = params_at(point["value"], sets)
            hb, shoot = HarmonicBalance(p), AlphaMap(p.replace(time={"dt_s": 1e-4}),
                                                     rho_inf=0.9)
            g = []
            for f in (point["f1_Hz"] - 2e-3, point["f1_Hz"] + 2e-3):
                o = hb.orbit(hb.X_stationary, f)
                mu = shoot.orbit(hb.state(o.X, f), f, tol=1e-5).multipliers
                g.append(critical(mu)[0] - 1.0)
            assert g[0] * g[1] < 0, (point, g)


def params_at(elongation, sets):
    return rh.load_scene("mobile_end", elements=4, degree=3,
                         overrides={**sets, "ends.elongation": elongation})


@pytest.mark.long  # 8.4 s, make test's 12-minute budget (2026-12-05: 733 s); make test keeps
# envelope's other tick and window tests
def test_a_tick_reports_only_its_window():
    """The continuation's last step leaves the window (here to 12.158 and 12.906 Hz for
    --f1 12.2:12.9): the envelope's ticks, their folds and limits hold points in [LO, HI]
    only (the tester's D7), and the branch still reaches both ends.  9 s."""
    lo, hi = 12.2, 12.9
    result = rh.envelope(_scene(), VARY, lo, hi, comm=MPI.COMM_SELF)
    for tick in result.summary["ticks"]:
        f1 = [e["f1_Hz"] for e in tick["branch"]]
        assert lo <= min(f1) <= lo + 0.05 and max(f1) == pytest.approx(hi), tick["value"]
        assert all(lo <= e["f1_Hz"] <= hi for e in tick["folds"] + tick["bifurcations"])
    assert all(lo <= c["f1_Hz"] <= hi for c in result.summary["limit_curve"])
