"""The spline-Galerkin reference (Sec. 3, App. A) against Sec. 5.1, Table 3 and Sec. 5.2."""

from __future__ import annotations

import json
import math

import numpy as np
import re

import pytest

from rawehelix.solvers import analytic
from rawehelix.references.spline_galerkin import dynamics, spectrum, stationary
from rawehelix.references.spline_galerkin.basis import SplineBasis
from rawehelix.references.spline_galerkin.system import SplineGalerkin
from rawehelix.studies import modes as modes_study
from rawehelix.studies.present import paper
from rawehelix.studies import scene, schemes


@pytest.fixture(scope="module")
def table2():
    return scene.load("stationary_table2", scheme="spline")


@pytest.fixture(scope="module")
def nd(table2):
    return table2.normalised()


def _modes(nd, N, n_gauss=6):
    system = SplineGalerkin(nd, N, n_gauss)
    return spectrum.modes(system, stationary.solve(system).x)


# -- basis ---------------------------------------------------------------------
@pytest.mark.parametrize("N", [2, 3, 7])
def test_splines_reproduce_polynomials(N):
    """Natural spline: exact for straight lines; clamped spline: exact for cubics."""
    b = SplineBasis.build(N)
    y, s = np.linspace(0, 1, N + 1), b.s
    assert np.allclose(b.D[0] @ (3 * y - 1), 3 * s - 1, atol=1e-13)
    assert np.allclose(b.D[2] @ (3 * y - 1), 0, atol=1e-10)
    f, fp = (lambda x: x**3 - 2 * x**2 + x), (lambda x: 3 * x**2 - 4 * x + 1)
    for k, exact in ((0, f(s)), (1, fp(s)), (2, 6 * s - 4), (3, 6 + 0 * s)):
        got = b.A[k] @ f(y) + b.b0[k] * fp(0.0) + b.bN[k] * fp(1.0)
        assert np.allclose(got, exact, atol=1e-10), k


def test_complex_step_jacobian_matches_finite_differences(nd):
    """The Jacobian is only right if g is complex-safe: check against central FD
    at a generic (non-stationary, twisted, moving) state with the controller on."""
    import dataclasses
    nd2 = dataclasses.replace(nd, k1=0.5, k2=0.5, mN0=1.0, spin_target=3.0)
    system = SplineGalerkin(nd2, 3)
    rng = np.random.default_rng(1)
    x = system.pack(stationary.chord_nodes(system) + 1e-3 * rng.standard_normal((2, 3)),
                    0.1 * rng.standard_normal(4), 0.01 * rng.standard_normal((2, 3)),
                    rng.standard_normal(4), m0=0.3, w=0.2)
    J = system.jacobian(x, 0.7)
    h = 1e-6
    Jfd = np.stack([(system.f(x + h * e, 0.7) - system.f(x - h * e, 0.7)) / (2 * h)
                    for e in np.eye(system.size)], axis=1)
    assert np.allclose(J, Jfd, rtol=1e-5, atol=1e-4 * np.abs(J).max())


# -- Sec. 5.1: stationary state ----------------------------------------------------
def test_residual_at_shooting_solution_falls_with_N(nd):
    """|g(x_s)| at the shooting solution decreases as N grows (Sec. 5.1), and
    Newton's nodes approach the shooting solution."""
    from rawehelix.references import shooting
    centre_line = shooting.solve(nd).centre_line
    res, gap = [], []
    for N in (2, 4, 8, 16):
        system = SplineGalerkin(nd, N)
        r_int = np.asarray(centre_line(np.arange(1, N) / N)).reshape(-1, 3)
        res.append(stationary.residual_norm(system, r_int))
        newton = stationary.solve(system, start=r_int).x[:system.n_r].reshape(-1, 3)
        gap.append(np.abs(newton - r_int).max())
    assert all(b < a for a, b in zip(res, res[1:])), res
    assert res[-1] < 0.25 * res[0], res
    assert all(b < 0.2 * a for a, b in zip(gap, gap[1:])), gap  # ~h^4
    assert gap[0] < 1e-4  # N = 2 already within 1e-4 L0 of the shooting solution


@pytest.mark.parametrize("N", [2, 3, 5, 16])
def test_newton_converges_for_any_N(nd, N):
    system = SplineGalerkin(nd, N)
    st = stationary.solve(system)
    assert st.residual < 1e-9 * nd.sigma
    r_int = st.x[:system.n_r].reshape(-1, 3)
    assert np.allclose(r_int[:, 1], 0.0)  # planar
    # the helix sags below the chord (z down, gravity +k_E)
    chord = stationary.chord_nodes(system)
    assert np.all(r_int[:, 2] > chord[:, 2])


# -- Table 3 ---------------------------------------------------------------------
TABLE3 = [(r.eigenvalue.real, r.eigenvalue.imag, r.family) for r in paper.TABLE3]  # normalised


@pytest.fixture(scope="module")
def modes_n2(nd):
    return _modes(nd, 2)


@pytest.mark.parametrize("re, im, family", TABLE3)
def test_table3_at_N2(modes_n2, re, im, family):
    match = [m for m in modes_n2 if m.family == family
             and abs(m.eigenvalue.imag - im) <= 0.01 * im
             and abs(m.eigenvalue.real - re) <= 0.05]
    assert len(match) == 1, [(m.eigenvalue, m.family) for m in modes_n2]


def test_table3_at_N2_nothing_else(modes_n2):
    """Exactly the five oscillatory pairs of Table 3; the rest is rigid (lambda ~ 0)."""
    oscillatory = [m for m in modes_n2 if m.family != "rigid"]
    assert len(oscillatory) == len(TABLE3)
    rigid = [m for m in modes_n2 if m.family == "rigid"]
    assert rigid and all(abs(m.eigenvalue) < 1e-6 for m in rigid)
    assert all(set(m.dominant) <= {"alpha_0", "alpha_1", "alpha_2"} for m in rigid)
    # stable: the oscillatory pairs decay or are undamped (torsion); the rigid
    # zeros are numerically zero (|lambda| < 1e-6 above), whatever their sign
    assert all(m.eigenvalue.real < 1e-9 for m in oscillatory)


def test_quadrature_is_converged(nd):
    """Refining the Gauss rule changes nothing in the fifth digit."""
    a = np.array([m.eigenvalue for m in _modes(nd, 4, 6) if m.family != "rigid"])
    b = np.array([m.eigenvalue for m in _modes(nd, 4, 12) if m.family != "rigid"])
    assert np.allclose(a, b, rtol=1e-6)


# -- Sec. 5.1 estimates at N = 8 -----------------------------------------------------
def _family(modes, family):
    return sorted((m.eigenvalue for m in modes if m.family == family), key=abs)


def test_spectrum_N8_against_analytic_estimates(nd):
    """|lambda| against the classical estimates; Re against linearised drag.

    Tolerances: torsion 1 % (Eq. 31 is exactly the free-free wave equation:
    only discretisation error); lateral and longitudinal 2 % (the tension
    varies along the rod by ~ +-sin(Gamma0)/2 ~ 0.35 around sigma eps0 = 40,
    about 1 %, and the sagged, stretched rod is not exactly the straight
    pinned beam or bar); drag Re within 2 % of -c/2 with
    c = nu v_w0 (1 + (e.i_E)^2) (Eq. 28 linearised about v = 0).
    """
    modes = _modes(nd, 8)
    T = nd.sigma * nd.eps0
    tors = _family(modes, "torsional")
    for n in (1, 2, 3):
        assert abs(tors[n - 1]) == pytest.approx(analytic.shaft(nd, n), rel=0.01)
        assert abs(tors[n - 1].real) < 1e-6
    c_in = nd.nu * nd.v_w0 * (1 + math.cos(nd.Gamma0) ** 2)
    c_out = nd.nu * nd.v_w0
    for family, c in (("lateral_in_plane", c_in), ("lateral_out_of_plane", c_out)):
        lat = _family(modes, family)
        for n in (1, 2):
            assert abs(lat[n - 1]) == pytest.approx(analytic.beam(nd, n, T), rel=0.02)
            assert -lat[n - 1].real == pytest.approx(c / 2, rel=0.02)
    lon = _family(modes, "longitudinal")
    # the model's own bar: d(T r')/d|r'| = sigma (1 + 2 eps0), and the bending term
    # mu r^(4) acts on the axial component too (Eqs. 30, 33): within 0.2 %
    assert abs(lon[0]) == pytest.approx(analytic.bar(nd, 1, T), rel=0.002)
    assert -lon[0].real == pytest.approx(c_in / 2, rel=0.02)


# -- Sec. 5.2: nominal operation -------------------------------------------------------
def test_nominal_operation_settles_at_120_rpm():
    params = scene.load("nominal_operation", scheme="spline", elements=2)
    ts = dynamics.time_series(params, until_s=30.0, output_every_s=0.5)
    assert ts.time_s[-1] == pytest.approx(30.0)
    assert np.allclose(ts.node_s_m, [0.0, params.helix.length_m / 2, params.helix.length_m])
    assert np.all(np.abs(ts.spin_rpm[-1] / 120.0 - 1) < 0.005), ts.spin_rpm[-1]
    assert ts.ground_torque_Nm[-1] == pytest.approx(25.0, rel=0.02)
    assert ts.tension0_N[-1] == pytest.approx(200.0, rel=0.05)
    assert np.all(ts.spin_rpm[0] == 0.0)
    # the ramp takes time: not yet settled at 2 s
    assert ts.spin_rpm[ts.time_s <= 2.0][-1, 0] < 110.0
    # Eq. (40) integrated in time holds along the whole run (exact treatment of m0):
    # m0(t) - m0(0) = mN(t) - mN(0) + k1 (alpha_0 - alpha_0(0) - alpha* t) + k2 (alpha_0' - alpha_0'(0))
    nd = params.normalised()
    names = SplineGalerkin(nd, 2).names()
    X, t = ts.states, ts.time_s / nd.t_scale
    a0, ad0, m0 = (X[:, names.index(k)] for k in ("alpha_0", "alphadot_0", "m_0"))
    mN = np.array([nd.top_torque(tk) for tk in t])
    rhs = mN - mN[0] + nd.k1 * (a0 - a0[0] - nd.spin_target * t) + nd.k2 * (ad0 - ad0[0])
    assert np.abs(m0 - m0[0] - rhs).max() < 1e-4 * nd.mN0


# -- studies/modes.py -------------------------------------------------------------------
def run_modes(params, outdir, count=None, log=lambda *a: None):
    """What `rawehelix modes` does: compute, print, write; returns the summary."""
    result = modes_study.compute(params, count)
    for line in modes_study.report(result).splitlines():
        log(line)
    result.write(outdir)
    return result.summary


def test_modes_run_writes_summary(tmp_path):
    params = scene.load("stationary_table2", scheme="spline", elements=2)
    out = tmp_path / "modes"
    lines = []
    summary = run_modes(params, out, log=lines.append)
    data = json.loads((out / "summary.json").read_text())
    assert data["scheme"] == "spline" and data["elements"] == 2 and data["wall_s"] >= 0
    keys = {"family", "eigenvalue", "eigenvalue_per_s", "frequency_Hz", "decay_per_s", "period_s",
            "dominant"}
    assert all(set(m) == keys for m in data["modes"])
    lon = [m for m in data["modes"] if m["family"] == "longitudinal"][0]
    assert lon["period_s"] == pytest.approx(0.03, abs=0.002)  # Table 3
    assert lon["eigenvalue_per_s"][1] == pytest.approx(lon["eigenvalue"][1] / params.normalised().t_scale)
    assert all(m["period_s"] is None for m in data["modes"] if m["family"] == "rigid")
    assert "Longitudinal" in "\n".join(lines)
    assert summary["modes"] == data["modes"]
    few = run_modes(params, tmp_path / "few", count=3, log=lambda *a: None)
    assert len(few["modes"]) == 3


def test_modes_run_fe_failure_leaves_no_output(tmp_path, monkeypatch):
    """The FE branch (issue 4, tests/test_modal.py) writes nothing when a solve fails."""
    from rawehelix.solvers import modal
    from rawehelix.solvers.snes import SolverError

    def boom(*a, **k):
        raise SolverError("SLEPc PEP found 0 of 20 eigenpairs")
    monkeypatch.setattr(modal.ModalSolver, "solve", boom)
    params = scene.load("stationary_table2", scheme="fe", elements=2)
    with pytest.raises(SolverError):
        run_modes(params, tmp_path / "fe")
    assert not (tmp_path / "fe").exists()


def test_modes_run_failure_leaves_no_output(tmp_path, monkeypatch):
    def boom(*a, **k):
        raise RuntimeError("Newton did not converge")
    monkeypatch.setattr(schemes.Spline, "spectrum", boom)
    params = scene.load("stationary_table2", scheme="spline", elements=2)
    with pytest.raises(RuntimeError):
        run_modes(params, tmp_path / "x")
    assert not (tmp_path / "x").exists()


def test_scheme_registry_refuses_an_unknown_name_as_a_scene_does():
    from rawehelix.parameters import SCHEMES, ParameterError
    assert tuple(schemes.SCHEME_REGISTRY) == SCHEMES
    listed = re.escape(f"must be one of {SCHEMES}")  # the registry's list, every scheme
    with pytest.raises(ParameterError, match=listed):
        schemes.get("fd")
    with pytest.raises(scene.SceneError, match=listed):
        scene.load("stationary_table2", scheme="fd")


def test_both_schemes_of_the_registry_give_the_shooting_tension():
    """T(0) of each scheme, asked of the registry, against the shooting reference."""
    from rawehelix.references import shooting
    for name, N in (("fe", 4), ("spline", 8)):
        params = scene.load("stationary_table2", scheme=name, elements=N)
        assert schemes.of(params).name == name
        q = params.normalised()
        expected = q.tension_N(shooting.solve(q).tension(0.0))
        assert schemes.of(params).stationary_tension_N(params) == pytest.approx(expected, rel=1e-3)
