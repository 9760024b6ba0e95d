"""Runs that say why they stopped, and one way out from each refusal (issue 41):
a sweep point that is not periodic says what its periodicity test measured, what
still moves and what to try; an unforced scene and out-of-range orbit options are
refused before any work; a scene without the controller's integral action is
refused by every orbit method with the command-line way out; no refusal names an
internal identifier; harmonic balance never returns a point above its tolerance."""

import ast
import json
import math
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import rawehelix as rh
from rawehelix.studies import scene

RAWEHELIX = [sys.executable, "-m", "rawehelix.cli.main"]
ROOT = Path(__file__).resolve().parents[1]


def _run(tmp_path, *argv, timeout=300):
    out = tmp_path / "OUT"
    return subprocess.run([*RAWEHELIX, *argv, "-o", str(out)], cwd=tmp_path,
                          capture_output=True, text=True, timeout=timeout)


def _refused(run, tmp_path, *needles):
    """Exit 2, one line on stderr holding each needle, nothing written."""
    lines = run.stderr.splitlines()
    assert run.returncode == 2, run.stderr
    assert len(lines) == 1 and "Traceback" not in run.stderr, run.stderr
    for needle in needles:
        assert needle in lines[0], lines[0]
    assert list(tmp_path.iterdir()) == []


# -- a forcing of zero amplitude --------------------------------------------------------
UNFORCED = [
    ["sweep", "mobile_end", "--f1", "9:10:1"],
    ["response", "mobile_end", "--f1", "9:10:1"],
    ["orbits", "mobile_end", "--f1", "10:9"],
    ["orbits", "mobile_end", "--f1", "10:9", "--method", "hb"],
    ["envelope", "mobile_end", "--f1", "9:10", "--vary", "helix.EI_Nm2=4000:5000:2"],
]


@pytest.mark.parametrize("argv", UNFORCED, ids=lambda a: "-".join(a[:1] + a[4:5]))
def test_an_unforced_scene_is_refused(tmp_path, argv):
    run = _run(tmp_path, *argv, "--elements", "4", "--set", "ends.circle_radius_m=0")
    _refused(run, tmp_path, "ends.circle_radius_m", f"'{argv[0]}' needs the upper end's circle",
             "--set ends.circle_radius_m=0.1")


def test_an_envelope_through_zero_radius_is_refused(tmp_path):
    run = _run(tmp_path, "envelope", "mobile_end", "--elements", "4", "--f1", "9:10",
               "--vary", "ends.circle_radius_m=0:0.1:2")
    _refused(run, tmp_path, "--vary ends.circle_radius_m=0", "start the --vary range above 0")


def test_the_forcing_check_is_the_scene_not_the_command():
    """The API refuses it too (sweep.compute, orbits.compute, response.check), and a
    radius below the round-off of the positions is no forcing either."""
    from rawehelix.studies import forcing, orbits, response, sweep
    params = scene.load("mobile_end", elements=2, overrides={"ends.circle_radius_m": 0.0})
    for call in (lambda: sweep.compute(params, [10.0]),
                 lambda: orbits.compute(params, 10.0, 9.0),
                 lambda: response.check(params)):
        with pytest.raises(rh.SceneError, match="circle_radius_m"):
            call()
    for radius, refused in ((1e-320, True), (1e-14, True), (1e-9, False), (0.1, False)):
        at = scene.load("mobile_end", elements=2, overrides={"ends.circle_radius_m": radius})
        if refused:  # below round-off of the positions (L0 = 7.9 m)
            with pytest.raises(rh.SceneError, match="forces nothing"):
                forcing.require(at, "sweep")
        else:
            forcing.require(at, "sweep")


# -- the orbits' own options ------------------------------------------------------------
@pytest.mark.parametrize("option,value", [("--max-points", "0"), ("--max-points", "-2"),
                                          ("--tension-step", "0"), ("--tension-step", "1.5"),
                                          ("--tension-step", "nan"),
                                          ("--tension-step", "-0.1")])
def test_orbit_options_out_of_range_are_bad_input(tmp_path, option, value):
    run = _run(tmp_path, "orbits", "mobile_end", "--elements", "4", "--f1", "10:9",
               option, value)
    _refused(run, tmp_path, option)


# -- one way out from each refusal ------------------------------------------------------
@pytest.mark.parametrize("method", ["hb", "shooting", "auto"])
def test_without_the_integral_action_every_method_names_the_controller(tmp_path, method):
    """k1 = 0: neither method can continue a family of orbits; the one line says what
    to paste into the scene and the --set that does it, for every --method."""
    run = _run(tmp_path, "orbits", "mobile_end", "--elements", "4", "--f1", "10:9",
               "--method", method, "--set", "controller.k1=0")
    _refused(run, tmp_path, "'[controller]' with 'k1 = 0.5'", "--set controller.k1=0.5")


def test_the_envelope_names_the_controller_before_any_work(tmp_path):
    run = _run(tmp_path, "envelope", "mobile_end", "--elements", "4", "--f1", "9:10",
               "--vary", "helix.EI_Nm2=4000:5000:2", "--set", "controller.k1=0")
    _refused(run, tmp_path, "--set controller.k1=0.5")


def test_the_way_out_works(tmp_path):
    """What the refusal says to add makes the same scene run (one orbit, HB)."""
    run = _run(tmp_path, "orbits", "mobile_end", "--elements", "4", "--f1", "10:9.9",
               "--method", "hb", "--max-points", "1", "--superharmonics", "none",
               "--set", "controller.k1=0", "--set", "controller.k1=0.5")
    assert run.returncode == 0, run.stderr


def _raised_messages(path: Path) -> list[tuple[int, str]]:
    """The literal text of every SolverError / SceneError / ValueError raised in a
    module, and every module-level string constant named in capitals (the refusal
    texts defined once)."""
    tree = ast.parse(path.read_text())
    found = []

    def text(node):
        return " ".join(c.value for c in ast.walk(node)
                        if isinstance(c, ast.Constant) and isinstance(c.value, str))

    for node in ast.walk(tree):
        if isinstance(node, ast.Raise) and isinstance(node.exc, ast.Call):
            name = getattr(node.exc.func, "id", getattr(node.exc.func, "attr", ""))
            if name.endswith("Error") or name == "Diverged":
                found.append((node.lineno, text(node.exc)))
        elif isinstance(node, ast.Assign) and isinstance(node.value, (ast.Constant, ast.JoinedStr,
                                                                      ast.BinOp)):
            targets = [t.id for t in node.targets if isinstance(t, ast.Name)]
            if targets and targets[0].isupper():
                found.append((node.lineno, text(node.value)))
        elif isinstance(node, ast.Return) and node.value is not None and \
                isinstance(node.value, (ast.Constant, ast.JoinedStr, ast.BinOp)):
            found.append((node.lineno, text(node.value)))  # cannot(): the reasons
    return found


#: an internal identifier in a message: a CamelCase class name (AlphaMap, PeriodMap),
#: or a method call or attribute of one (m.orbit(, AlphaMap.orbit)
CAMEL = re.compile(r"\b[A-Z][a-z0-9]+(?:[A-Z][a-z0-9]+)+\b")
ATTRIBUTE = re.compile(r"\b[A-Za-z_]\w*\.[a-z_]\w*\(|\b[A-Z]\w+\.[a-z_]\w+\b")
REFUSERS = ["studies/orbit_method.py", "studies/orbits.py", "studies/envelope.py",
            "studies/forcing.py", "studies/sweep.py", "studies/sweep_advice.py",
            "solvers/harmonic_balance/problem.py", "solvers/harmonic_balance/newton.py",
            "solvers/harmonic_balance/scope.py", "solvers/periodic.py",
            "references/spline_galerkin/orbits.py", *sorted(
                str(p.relative_to(ROOT)) for p in (ROOT / "periodic_orbits").glob("*.py"))]


@pytest.mark.parametrize("module", REFUSERS)
def test_no_refusal_names_an_internal_identifier(module):
    bad = [(line, m) for line, m in _raised_messages(ROOT / module)
           if CAMEL.search(m) or ATTRIBUTE.search(m)]
    assert not bad, bad


def test_the_identifier_scan_can_fail():
    assert CAMEL.search("continue it at fixed f1 steps (AlphaMap.orbit) instead")
    assert ATTRIBUTE.search("call m.orbit(X, f1)")
    assert not CAMEL.search("Hill's method, Newton, SLEPc, Floquet, --method hb")


def test_the_refusals_name_a_command_line_way():
    """Each refusal of a method names an option or scene key that works."""
    from rawehelix.periodic_orbits import floquet
    from rawehelix.periodic_orbits.problem import FREE_ROTATION
    from rawehelix.solvers.harmonic_balance import scope
    assert "--set controller.k1=" in FREE_ROTATION and "[controller]" in FREE_ROTATION
    assert "--method hb" in floquet.WAY_OUT
    plain = scene.load("mobile_end", elements=2)
    hysteretic = plain.replace(torsion_hysteresis={"rho": 0.5, "beta_m_n": 1.0})
    assert "--method shooting" in scope.cannot(hysteretic)
    spline = plain.replace(discretisation={"scheme": "spline"})
    assert "--method shooting" in scope.cannot(spline)


# -- harmonic balance: no point above its tolerance ---------------------------------------
@pytest.mark.parametrize("elongation", ["1e9", "1e11"])
def test_harmonic_balance_refuses_a_diverged_branch(tmp_path, elongation):
    """At elongation 1e9 HB once reported a fold and T max 3.6e13 N with the residual
    0.126 at every point, exit 0: now no point, exit 1, one line with advice."""
    run = _run(tmp_path, "orbits", "mobile_end", "--elements", "4", "--set",
               f"ends.elongation={elongation}", "--f1", "10:9", "--method", "hb")
    assert run.returncode == 1, run.stderr
    lines = run.stderr.splitlines()
    assert len(lines) == 1 and "Traceback" not in run.stderr, run.stderr
    assert "no orbit" in lines[0] and "ends.elongation" in lines[0]
    assert not (tmp_path / "OUT" / "summary.json").exists()


class _Problem:
    def continuable(self):
        pass


def test_a_branch_takes_no_point_above_its_tolerance():
    """The class, for every method: a first point above FLOOR_FACTOR x tol is refused
    with its residual; within it, it is a point."""
    from rawehelix.periodic_orbits.continuation import FLOOR_FACTOR, Branch
    from rawehelix.periodic_orbits.problem import Orbit
    from rawehelix.solvers.snes import SolverError
    branch = Branch(_Problem(), tol=1e-7)

    def orbit(residual):
        return Orbit(f1_Hz=10.0, X=np.zeros(3), delta=0.0, tension_max_N=1.0,
                     tension_min_N=0.0, multipliers=np.zeros(1), newton_iterations=1,
                     residual=residual, steps=3, wall_s=0.0)

    assert branch.valid(orbit(FLOOR_FACTOR * 1e-7))
    assert not branch.valid(orbit(0.126)) and not branch.valid(orbit(math.nan))
    with pytest.raises(SolverError, match="0.126 is above its tolerance"):
        branch.start(orbit(0.126))


# -- harmonic balance with the mixed bending -----------------------------------------------
def test_averaged_exponents_of_a_massless_unknown():
    """A singular mass (the mixed bending's moments carry none): the exponents are the
    condensed system's (x2 = x1 / 2: x1'' + 0.1 x1' + 1.5 x1 = 0)."""
    from rawehelix.solvers.harmonic_balance.hill import averaged_exponents
    M, C = np.diag([1.0, 0.0]), np.diag([0.1, 0.0])
    K = np.array([[2.0, -1.0], [-1.0, 2.0]])
    lam = averaged_exponents([M], [C], [K], np.arange(2), 2)
    exact = np.roots([1.0, 0.1, 1.5])
    assert len(lam) == 1 and abs(lam[0] - exact[exact.imag > 0][0]) <= 1e-12


def test_harmonic_balance_runs_with_the_mixed_bending():
    """orbits --method hb with discretisation.bending = "mixed" raised LinAlgError:
    now its orbit at 10 Hz, N = 4, is the interior-penalty bending's to 1e-3 in T max
    and its largest multiplier to 1e-4 (measured 242.40 N vs 242.48 N, 0.96502 both)."""
    from rawehelix.solvers.harmonic_balance.problem import HarmonicBalance
    found = {}
    for bending in ("ip", "mixed"):
        params = scene.load("mobile_end", elements=4, overrides={
            "discretisation.bending": bending})
        hb = HarmonicBalance(params)
        found[bending] = hb.orbit(hb.X_stationary, 10.0)
    ip, mixed = found["ip"], found["mixed"]
    assert mixed.tension_max_N == pytest.approx(ip.tension_max_N, rel=1e-3)
    assert mixed.max_multiplier == pytest.approx(ip.max_multiplier, abs=1e-4)


# -- a sweep point that is not periodic says why ----------------------------------------
class _Backend:
    """T = 1 + a(t) sin(w t): a(t) = a (1 + excess r^k) after k periods, or a sustained
    beat (``beat``); no parts."""

    section_sampler = None  # the backends' interface: no fields along s

    def __init__(self, q, r=0.99, beat=0.0):
        self.q, self.r, self.beat = q, r, beat

    def stationary(self):
        return 0.0

    def set_frequency(self, f1_Hz, t_start):
        self.omega, self.t_start = self.q.at_frequency(f1_Hz, t_start).omega1, t_start

    def advance(self, state, t0, t1, t_out):
        t = np.asarray(t_out) - self.t_start
        k = t * self.omega / (2 * np.pi)
        a = 2.5e-3 * (1 + 0.2 * self.r ** k + self.beat * np.sin(0.3 * k))
        return state, 1.0 + a * np.sin(self.omega * t)

    pack = unpack = staticmethod(lambda s: s)
    parts = staticmethod(lambda s: None)  # no parts (solvers/periodic.py's Backend)


def _sweep_params(max_periods):
    params = scene.load("mobile_end", elements=2)
    return params, params.sweep.__class__(lead_in_s=0.0, min_periods=4,
                                          max_periods=max_periods, record_periods=4)


def test_a_slow_transient_says_how_many_more_periods():
    """r = 0.99 a period: the remainder after 40 periods is known, and so are the
    periods it still needs; the advice gives the --set that allows them."""
    from rawehelix.solvers.periodic import periodic_response
    from rawehelix.studies import sweep_advice
    params, sw = _sweep_params(40)
    q = params.normalised()
    point, _, _ = periodic_response(_Backend(q, r=0.99), q, 5.0, 0.0, 0.0, sw, lead_in=False)
    why = point.unsettled
    assert not point.periodic and why["reason"] == "decaying too slowly"
    assert why["decay_per_period"] == pytest.approx(0.99, abs=2e-3)
    assert why["remainder_N"] > why["allowed_N"]
    # the remainder decays by r a period: it reaches the allowance after n more periods
    n = math.log(why["allowed_N"] / why["remainder_N"]) / math.log(0.99)
    assert why["periods_to_settle"] == pytest.approx(n, abs=1.5)
    advice = sweep_advice.advice(params, why, 5.0)
    more = [a for a in advice if "--set sweep.max_periods=" in a]
    total = int(more[0].rsplit("=", 1)[1])
    assert total >= 40 + why["periods_to_settle"]
    assert point.entry()["not_periodic"] is why


def test_a_beat_that_does_not_decay_is_told_to_damp():
    from rawehelix.solvers.periodic import periodic_response
    from rawehelix.studies import sweep_advice
    params, sw = _sweep_params(60)
    params = params.replace(controller={"k1": 0.0, "k2": 0.0})
    q = params.normalised()
    point, _, _ = periodic_response(_Backend(q, r=1.0, beat=0.1), q, 5.0, 0.0, 0.0, sw,
                                    lead_in=False)
    why = point.unsettled
    assert not point.periodic and why["reason"] == "not decaying"
    assert why["remainder_N"] is None and why["periods_to_settle"] is None
    advice = " | ".join(sweep_advice.advice(params, why, 5.0))
    assert "--set controller.k1=0.5" in advice and "--set damping.torsion_s=" in advice
    assert "max_periods" not in advice
    assert "do not decay" in sweep_advice.reason(why)


def test_a_periodic_point_has_no_reason():
    from rawehelix.solvers.periodic import periodic_response
    params, sw = _sweep_params(200)
    q = params.normalised()
    point, _, _ = periodic_response(_Backend(q, r=0.5), q, 5.0, 0.0, 0.0, sw, lead_in=False)
    assert point.periodic and point.unsettled is None
    assert "not_periodic" not in point.entry()


def test_progress_is_reported_per_period():
    """periodic_response's progress(k, measure) at every period; the terminal bar shows
    periods done of max_periods and the measure; off a terminal, no bar."""
    from rawehelix.solvers.periodic import periodic_response
    from rawehelix.studies.sweep import PeriodBar
    params, sw = _sweep_params(20)
    q = params.normalised()
    seen = []
    periodic_response(_Backend(q, r=1.0, beat=0.1), q, 5.0, 0.0, 0.0, sw, lead_in=False,
                      progress=lambda k, m: seen.append((k, m)))
    assert [k for k, _ in seen] == list(range(1, 21))
    assert seen[11][1] is None and seen[12][1] is not None  # 3 x 4 + 1 periods to judge
    with PeriodBar(5.0, sw, show=False) as bar:
        assert bar is None


def test_progress_bar_text(capsys):
    from rawehelix.solvers.periodic import Transient
    from rawehelix.studies.sweep import PeriodBar
    _, sw = _sweep_params(500)
    with PeriodBar(5.0, sw, show=True) as bar:
        bar.bar.ncols = 100
        bar(7, Transient(1e-3, 0.9, 9e-3, 1e-3, False))
        bar.bar.refresh()
        bar(8, Transient(1e-3, None, None, 1e-3, False))
        bar.bar.refresh()
    err = capsys.readouterr().err
    assert "7/500 periods, remainder / allowed 9" in err
    assert "8/500 periods, remainder / allowed not decaying" in err


def test_sweep_says_what_still_moves(tmp_path):
    """The tester's case (no controller, the torque ramp sets the spin going), short:
    the point's lines and summary.json say the twist's rotation rate moves most and
    give the controller's --set; on a pipe (not a terminal) no progress bar."""
    run = _run(tmp_path, "sweep", "mobile_end", "--elements", "4", "--f1", "10:10:1",
               "--set", "controller.k1=0", "--set", "controller.k2=0",
               "--set", "sweep.max_periods=16", "--set", "sweep.lead_in_s=0.5")
    assert run.returncode == 0, run.stderr
    assert "\r" not in run.stderr and "periods |" not in run.stderr
    text = run.stdout + run.stderr
    assert "why: T max and T min at s = 0" in text
    assert "try: a controller" in text and "--set controller.k1=0.5" in text
    point = json.loads((tmp_path / "OUT" / "summary.json").read_text())["points"][0]
    why = point["not_periodic"]
    assert why["moving"][0]["part"] == "the twist's rotation rate"
    assert any("--set controller.k1=0.5" in a for a in why["advice"])


# -- memory: what a long branch keeps --------------------------------------------------------
def test_a_dropped_lu_is_destroyed():
    """petsc4py 3.18 leaves a dropped object to PETSc's garbage: an LU (its MUMPS
    factor) dropped by the continuation grew HB's Fig. 8 by ~7 MB a point at N = 4."""
    import scipy.sparse as sparse
    from rawehelix.solvers.harmonic_balance.sparse_lu import LU
    lu = LU(sparse.eye(50, format="csr") * 2.0)
    assert lu.solve(np.ones(50)) == pytest.approx(0.5)
    ksp, A = lu.ksp, lu.A
    del lu
    assert ksp.handle == 0 and A.handle == 0


def test_a_branch_keeps_the_matrices_of_its_newest_point_only():
    from rawehelix.solvers.harmonic_balance.problem import HarmonicBalance
    from rawehelix.studies.orbits import branch
    hb = HarmonicBalance(scene.load("mobile_end", elements=4))
    points = branch(hb).trace(hb.orbit(hb.X_stationary, 10.0), 9.0, direction=-1.0,
                              max_points=3)
    assert len(points) == 3
    assert all(p.jacobian is None and p.G is None for p in points[:-1])
    assert points[-1].jacobian is not None
    # a trace started again from a released point evaluates its Jacobian again and
    # takes the same step
    again = branch(hb).trace(points[0], 9.0, direction=-1.0, max_points=2)
    assert again[1].f1_Hz == pytest.approx(points[1].f1_Hz, abs=1e-9)
    assert again[1].tension_max_N == pytest.approx(points[1].tension_max_N, rel=1e-9)
