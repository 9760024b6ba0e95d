"""The f1 sweep of Sec. 5.3: periodicity, continuation, resuming, refusal, MPI chunks.

These run the spline reference at N = 2 (the paper's method, seconds per
point); the FE backend shares the driver, and its resume is tested at N = 2."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI

from rawehelix.cli import main as cli
from rawehelix.studies import scene, sweep
from tests_util import world_folder, write_scene

# periodic to 0.1 of the oscillation: about 2e-3 of T max at 8-10 Hz
FAST = {"sweep": {"lead_in_s": 1.0, "min_periods": 3, "periodic_tolerance": 0.1}}


@pytest.fixture
def fast_scene(tmp_path):
    return write_scene(tmp_path / "mobile_fast.toml", {**FAST, "discretisation": {
        "scheme": "spline", "elements": 2}}, name="mobile_end")


def entries(path):
    data = json.loads(Path(path).read_text())
    return {p["f1_Hz"]: p for p in data["points"]}


def run_cli(scene_path, outdir, f1="8:10:0.5", extra=()):
    return subprocess.Popen([sys.executable, "-m", "rawehelix.cli.main", "sweep",
                             str(scene_path), "--f1", f1, "-o", str(outdir), *extra],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)


@pytest.mark.long  # make test's 12-minute budget (2026-12-04); make test-long runs it; test_faults.py's Ctrl-C resume stays
def test_kill_and_resume_equals_uninterrupted(tmp_path, fast_scene):
    """SIGKILL mid-sweep leaves a readable results file; re-running finishes
    without recomputing finished points, and the file equals an uninterrupted run's."""
    whole, resumed = tmp_path / "whole", tmp_path / "resumed"
    assert run_cli(fast_scene, whole).wait() == 0
    proc = run_cli(fast_scene, resumed)
    log = resumed / "computed.log"
    deadline = time.time() + 120
    while time.time() < deadline and proc.poll() is None:
        if log.exists() and len(log.read_text().splitlines()) >= 2:
            break
        time.sleep(0.05)
    assert proc.poll() is None, "the sweep finished before it could be killed"
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    done_before = [float(line.split()[0]) for line in log.read_text().splitlines()]
    partial = entries(resumed / "sweep.json")  # readable after SIGKILL
    assert 2 <= len(partial) < 5 and set(partial) == set(done_before)
    assert run_cli(fast_scene, resumed).wait() == 0
    computed = [float(line.split()[0]) for line in log.read_text().splitlines()]
    assert sorted(computed) == sorted(set(computed)), "a finished point was recomputed"
    a, b = entries(whole / "sweep.json"), entries(resumed / "sweep.json")
    assert set(a) == set(b) == {8.0, 8.5, 9.0, 9.5, 10.0}
    for f1 in a:
        for key in ("tension_max_N", "tension_min_N", "tension_mean_N", "periods", "periodic"):
            assert a[f1][key] == b[f1][key], (f1, key)
    # and a third run computes nothing
    assert run_cli(fast_scene, resumed).wait() == 0
    assert len(log.read_text().splitlines()) == len(computed)


@pytest.mark.long  # make test's budget (make test-long runs it)
def test_other_discretisation_is_refused(tmp_path, fast_scene, capsys):
    out = tmp_path / "out"
    assert cli.main(["sweep", str(fast_scene), "--f1", "9:9:1", "-o", str(out)]) == 0
    before = (out / "sweep.json").read_text()
    assert cli.main(["sweep", str(fast_scene), "--f1", "9:9:1", "--elements", "3",
                     "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "sweep.json" in err and "another scene or discretisation" in err
    assert (out / "sweep.json").read_text() == before


@pytest.mark.parametrize("spec", ["9:8:1", "a:b:c", "0:5:1", "1:5:0"])
def test_bad_f1_range(tmp_path, fast_scene, capsys, spec):
    assert cli.main(["sweep", str(fast_scene), "--f1", spec, "-o", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "--f1" in err or "sweep.f1_" in err  # the option, or the scene key it sets
    assert not (tmp_path / "o").exists()


def test_cap_is_flagged(tmp_path, caplog):
    """A point that hits max_periods before it is periodic is flagged, not accepted;
    a max_periods below the test's 3 x record_periods + 1 is said before the work."""
    path = write_scene(tmp_path / "s.toml", {"sweep": {
        "lead_in_s": 0.0, "min_periods": 2, "max_periods": 2, "record_periods": 1,
        "periodic_tolerance": 1e-9}, "discretisation": {"scheme": "spline", "elements": 2}},
        name="mobile_end")
    params = scene.load(path)
    with caplog.at_level("WARNING", logger="rawehelix"):
        summary = sweep.compute(params, [10.0], comm=MPI.COMM_SELF).summary
    assert "sweep.max_periods = 2 is below the 4 periods" in caplog.text
    assert "--set sweep.max_periods=4" in caplog.text
    (point,) = summary["points"]
    assert point["periodic"] is False and point["periods"] == 2
    assert summary["not_periodic_Hz"] == [10.0]


@pytest.mark.parametrize("k", [1, 2, 3, 40])
def test_chunks_are_contiguous_and_balanced(k):
    """The f1 list of Fig. 8 cut for k ranks: every point once, in order; with
    the cost model ((min_periods + SETTLE_PERIODS) / f1 per point, lead_in_s per chunk)
    the low-frequency chunk gets fewer points, and no chunk costs more than the
    equal-count split's dearest one."""
    params = scene.load("mobile_end")
    f = params.sweep.frequencies()  # Fig. 8: 0.5-15 Hz every 0.5 Hz
    parts = sweep.chunks(f, k, params.sweep)
    assert len(parts) == k
    assert [x for c in parts for x in c] == f
    if k >= len(f):
        assert all(len(c) <= 1 for c in parts)
        return

    def cost(c):
        return params.sweep.lead_in_s + sum(sweep.point_cost(x, params.sweep) for x in c)
    even = sweep.chunks(f, k)
    assert max(map(cost, parts)) <= max(map(cost, even)) + 1e-12
    if k == 2:
        assert len(parts[0]) < len(parts[1])  # the periods are long at low f1
        assert max(map(cost, parts)) < 0.9 * max(map(cost, even))


#: periods each Fig. 8 point took to become periodic, FE N = 8, one rank, f1 =
#: 0.5:15:0.5 Hz (`make bench` section 1, 2026-12-03): the measured cost
MEASURED_PERIODS = [240, 264, 249, 224, 214, 202, 175, 155, 130, 123, 129, 113, 112, 100, 85,
                    73, 56, 48, 41, 34, 31, 36, 38, 37, 37, 184, 180, 185, 249, 279]


def test_chunks_balance_the_measured_cost_of_two_ranks():
    """Two ranks' chunks, cut by the cost model, against the measured simulated
    time of each point (periods / f1): the dearer chunk is within 1.4x of the
    best contiguous cut's (1.31; the former model, 3 s a point, gave 1.74)."""
    params = scene.load("mobile_end")
    f = params.sweep.frequencies()  # Fig. 8: 0.5-15 Hz every 0.5 Hz
    measured = {x: n / x for x, n in zip(f, MEASURED_PERIODS, strict=True)}

    def dearer(parts):
        return max(params.sweep.lead_in_s + sum(measured[x] for x in c) for c in parts)
    best = min(dearer([f[:i], f[i:]]) for i in range(1, len(f)))
    assert dearer(sweep.chunks(f, 2, params.sweep)) < 1.4 * best


@pytest.mark.slow
@pytest.mark.long  # 177 s on a fresh clone (make test-long)
def test_resonance_of_the_paper_at_n2(tmp_path):
    """Fig. 8 at N = 2: flat up to ~8 Hz, a rise above about 9 Hz, peak (> 900 N)
    near 13 Hz, collapse above."""
    params = scene.load("mobile_end", scheme="spline", elements=2)
    result = sweep.compute(params, [2.0, 6.0, 9.0, 11.0, 12.0, 13.0, 13.5, 14.5],
                           comm=MPI.COMM_SELF)
    result.write(tmp_path / "out")
    summary = result.summary
    T = {p["f1_Hz"]: p["tension_max_N"] for p in summary["points"]}
    assert T[2.0] == pytest.approx(T[6.0], rel=0.1)  # flat
    assert T[9.0] > 1.5 * T[2.0]
    assert 12.0 <= summary["resonance_Hz"] <= 14.0
    assert summary["peak_tension_N"] > 800
    assert T[14.5] < 0.5 * summary["peak_tension_N"]
    assert (tmp_path / "out" / "sweep.png").stat().st_size > 10_000


@pytest.mark.mpi
@pytest.mark.slow
@pytest.mark.long  # 170-300 s under mpirun since the periodicity test judges the oscillation
def test_two_ranks_match_one(tmp_path_factory):
    """Chunks on 2 ranks give the points of 1 rank to the periodicity tolerance
    (the second chunk starts from the stationary state with a lead-in instead of
    continuing).  Low f1, where the response is single-valued."""
    comm, base = world_folder(tmp_path_factory, "sweep")
    # the default lead-in (10 s) covers the spin-up under the torque ramp (t0 = 1.8 s)
    params = scene.load("mobile_end", scheme="spline", elements=2)
    freqs = [3.0, 4.0, 5.0, 6.0]
    world = sweep.compute(params, freqs, comm=comm, checkpoint=Path(base) / "world").summary
    memory = sweep.compute(params, freqs, comm=comm).summary  # no checkpoint: gathered in memory
    assert ([p["tension_max_N"] for p in memory["points"]]
            == [p["tension_max_N"] for p in world["points"]])
    if comm.rank == 0:
        serial = sweep.compute(params, freqs, comm=MPI.COMM_SELF,
                               checkpoint=Path(base) / "serial").summary
        assert world["ranks"] == comm.size
        for a, b in zip(serial["points"], world["points"]):
            assert a["f1_Hz"] == b["f1_Hz"]
            assert a["tension_max_N"] == pytest.approx(b["tension_max_N"], rel=3e-3)
            assert a["tension_mean_N"] == pytest.approx(b["tension_mean_N"], rel=3e-3)


# The FE backend's resume: N = 2, p = 2, a short lead-in and few periods.
FE_TINY = {"lead_in_s": 0.2, "min_periods": 2, "max_periods": 3, "record_periods": 1,
           "periodic_tolerance": 5e-2}
FE_F1 = [6.0, 8.0]
EXACT, CLOSE = ("periods", "periodic", "start"), ("tension_max_N", "tension_min_N", "tension_mean_N")


def computed_f1(outdir):
    return [float(line.split()[0]) for line in (outdir / "computed.log").read_text().splitlines()]


def test_fe_sweep_resumes(tmp_path):
    """The FE backend (DynamicsSolver): a second run computes nothing and gives
    the same points; after the second point's files are lost, a run recomputes
    that point alone, continued from the first point's state file, and equals
    the uninterrupted run (the backend restarts the integrator at every f1, so
    continuing in memory and from the file take the same steps, to round-off:
    measured 1.4e-12 relative in T max, as the fresh solver's first Newton
    iterations differ from the warm one's; the sweep's modified Newton (rtol 1e-6, a
    Jacobian rebuilt when convergence slows) turns that into ~1e-9; asserted to 1e-7)."""
    params = scene.load("mobile_end", scheme="fe", elements=2, degree=2).replace(
        sweep=FE_TINY, time={"dt_s": 2e-3})
    whole = tmp_path / "whole"

    def run(outdir):
        return sweep.compute(params, FE_F1, comm=MPI.COMM_SELF, checkpoint=outdir).summary

    first = run(whole)
    assert computed_f1(whole) == FE_F1 and first["computed_now"] == 2
    assert [p["start"] for p in first["points"]] == ["stationary", "continuation"]
    again = run(whole)
    assert computed_f1(whole) == FE_F1 and again["computed_now"] == 0
    assert again["points"] == first["points"]

    # interrupted after the first point: its files stay, the second's are gone
    resumed = tmp_path / "resumed"
    resumed.mkdir()
    (resumed / "points").mkdir()
    for suffix in (".json", ".npz"):
        name = f"f1_{FE_F1[0]:010.5f}{suffix}"
        (resumed / "points" / name).write_bytes((whole / "points" / name).read_bytes())
    last = run(resumed)
    assert computed_f1(resumed) == FE_F1[1:] and last["computed_now"] == 1
    for a, b in zip(first["points"], last["points"]):
        assert {k: a[k] for k in EXACT} == {k: b[k] for k in EXACT}
        assert [b[k] for k in CLOSE] == pytest.approx([a[k] for k in CLOSE], rel=1e-7)
    name = f"f1_{FE_F1[1]:010.5f}"
    a, b = (json.loads((d / "points" / f"{name}.json").read_text()) for d in (whole, resumed))
    assert b["series_tension_N"] == pytest.approx(a["series_tension_N"], rel=1e-7)
    with np.load(whole / "points" / f"{name}.npz") as x, \
            np.load(resumed / "points" / f"{name}.npz") as y:
        assert set(x) == set(y)
        for k in x:
            assert np.allclose(y[k], x[k], rtol=1e-7, atol=1e-7 * np.abs(x[k]).max()), k


class DecayingOscillation:
    """A synthetic backend: tension T = mean + a(t) sin(omega1 t) with an
    oscillation a(t) = a (1 + excess exp(-t / tau)) that settles slowly to its
    periodic value a, plus ``noise`` (relative, random) on every sample.  Its
    exact periodic orbit has T max - T min = 2 a."""

    def __init__(self, q, mean=1.0, a=2.5e-3, excess=0.2, tau_periods=3.0, noise=0.0):
        self.q, self.mean, self.a, self.excess, self.noise = q, mean, a, excess, noise
        self.tau_periods, self.rng = tau_periods, np.random.default_rng(0)

    def stationary(self):
        return 0.0

    def set_frequency(self, f1_Hz, t_start):
        self.omega = self.q.at_frequency(f1_Hz, t_start).omega1
        self.t_start = t_start

    def advance(self, state, t0, t1, t_out):
        t = np.asarray(t_out)
        tau = self.tau_periods * 2 * np.pi / self.omega
        a = self.a * (1 + self.excess * np.exp(-(t - self.t_start) / tau))
        T = self.mean + a * np.sin(self.omega * (t - self.t_start))
        return state, T * (1 + self.noise * self.rng.standard_normal(t.size))

    pack = unpack = staticmethod(lambda s: s)
    section_sampler = None  # the backend interface (solvers/periodic.py): no fields along s
    parts = staticmethod(lambda s: None)  # ... and no parts to name


@pytest.mark.parametrize("tau_periods", [3.0, 10.0])
def test_periodicity_is_judged_on_the_oscillation(tau_periods):
    """Issue 13: an oscillation of 0.25 % of T still changing by 20 % is not
    periodic yet (a tolerance relative to T max accepted it at min_periods);
    the accepted point's T max - T min is the exact orbit's 2 a within 2
    tolerances: the test bounds what remains of each extreme's transient, not
    its last change (which left up to tolerance / (1 - r) of it, r =
    exp(-1 / tau) the decay a period)."""
    from rawehelix.solvers.periodic import periodic_response
    params = scene.load("mobile_end", elements=2)
    q, tol = params.normalised(), 1e-3
    sw = params.sweep.__class__(lead_in_s=0.0, min_periods=4, max_periods=200, record_periods=4,
                                periodic_tolerance=tol)
    backend = DecayingOscillation(q, tau_periods=tau_periods)
    point, _, _ = periodic_response(backend, q, 5.0, 0.0, 0.0, sw, lead_in=False)
    assert point.periodic
    exact = float(q.tension_N(2 * backend.a))
    error = abs(point.tension_max_N - point.tension_min_N - exact) / exact
    assert error <= 2 * tol
    # the old test (T max changing by < tol x T max over 4 periods in a row)
    # accepted periods 2-5, whose T max - T min is still > 10 tol too large
    hi, lo = np.array(point.period_maxima_N), np.array(point.period_minima_N)
    assert np.all(np.abs(np.diff(hi[:5])) <= tol * hi[1:5])
    assert (hi[1:5].max() - lo[1:5].min() - exact) / exact > 10 * tol
    assert point.periods > 5


def test_periodicity_floor_and_cap():
    """No oscillation: judged on 1e-6 of the mean tension (round-off noise of 1e-12
    passes as soon as the test has its three blocks of 4 periods and one); an
    oscillation that never settles hits the cap, flagged."""
    from rawehelix.solvers.periodic import periodic_response
    params = scene.load("mobile_end", elements=2)
    q = params.normalised()
    sw = params.sweep.__class__(lead_in_s=0.0, min_periods=4, max_periods=30, record_periods=4,
                                periodic_tolerance=1e-3)
    flat = DecayingOscillation(q, a=0.0, noise=1e-12)
    point, _, _ = periodic_response(flat, q, 5.0, 0.0, 0.0, sw, lead_in=False)
    assert point.periodic and point.periods == 3 * 4 + 1
    # the extremes change by 2e-2 a a period at the start and 1.5e-2 a at the
    # cap, above the tolerance 1e-3 (T max - T min) = 6e-3 a ... 5e-3 a
    slow = DecayingOscillation(q, excess=2.0, tau_periods=100.0)
    point, _, _ = periodic_response(slow, q, 5.0, 0.0, 0.0, sw, lead_in=False)
    assert not point.periodic and point.periods == 30
