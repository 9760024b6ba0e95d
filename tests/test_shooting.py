"""The shooting reference for the stationary state, Sec. 5.1, Eqs. (66)-(68)."""

import dataclasses

import numpy as np
import pytest

from rawehelix.references import shooting
from rawehelix.studies import scene

S = np.linspace(0.0, 1.0, 101)


@pytest.fixture(scope="module")
def params():
    return scene.load("stationary_table2")


@pytest.fixture(scope="module")
def table2(params):
    return shooting.solve(params.normalised())


def _gauss(f, pieces=20, order=12):
    """Integral over [0, 1] of f(s) -> (n, 3) by composite Gauss-Legendre."""
    xg, wg = np.polynomial.legendre.leggauss(order)
    edges = np.linspace(0.0, 1.0, pieces + 1)
    total = 0.0
    for a, b in zip(edges[:-1], edges[1:]):
        s = 0.5 * (a + b) + 0.5 * (b - a) * xg
        total = total + 0.5 * (b - a) * (wg[:, None] * f(s)).sum(axis=0)
    return total


def test_boundary_conditions(table2):
    q = table2.normalised
    assert table2.boundary_residual < 1e-10
    np.testing.assert_allclose(table2.initial_state[[0, 1, 4, 5]], 0.0, atol=0)
    np.testing.assert_allclose(table2.centre_line(0.0)[0], 0.0, atol=1e-12)  # (35)
    np.testing.assert_allclose(table2.centre_line(1.0)[0], q.top_position(), atol=1e-10)  # (66)
    np.testing.assert_allclose(table2.derivatives([0.0, 1.0], 2), 0.0, atol=1e-10)  # (37)
    assert np.all(table2.centre_line(S)[:, 1] == 0.0)  # planar ansatz


def test_table2_tension_is_about_200N(table2):
    T0_N = float(table2.normalised.tension_N(table2.tension(0.0))[0])
    assert T0_N == pytest.approx(3.64e4 * 0.0055, rel=0.03)  # EA eps0 = 200.2 N
    # the sag is visible but small: a few mm on 16 m
    chord = table2.normalised.top_position()
    sag = table2.centre_line(S) - np.outer(S, chord)
    assert 1e-4 < np.abs(sag).max() < 1e-2


def test_without_loads_the_chord_is_straight(params):
    q = params.replace(model={"gravity": False, "drag": False}).normalised()
    sol = shooting.solve(q)
    np.testing.assert_allclose(sol.centre_line(S), np.outer(S, q.top_position()), atol=1e-9)
    np.testing.assert_allclose(sol.tension(S), q.chord_tension(), rtol=1e-9)
    assert q.chord_tension() == pytest.approx(q.sigma * q.eps0)


def test_converged_in_rtol(table2, params):
    tight = shooting.solve(params.normalised(), rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(tight.centre_line(S), table2.centre_line(S), atol=1e-8, rtol=0)
    np.testing.assert_allclose(tight.tension(S), table2.tension(S), atol=1e-8, rtol=0)


def test_fourth_derivative_is_the_derivative_of_the_third(table2):
    s, h = np.linspace(0.05, 0.95, 19), 1e-4
    fd = (table2.derivatives(s + h, 3) - table2.derivatives(s - h, 3)) / (2 * h)
    np.testing.assert_allclose(table2.derivatives(s, 4), fd, atol=1e-6)
    fd2 = (table2.derivatives(s + h, 0) - table2.derivatives(s - h, 0)) / (2 * h)
    np.testing.assert_allclose(table2.derivatives(s, 1), fd2, atol=1e-7)


def test_global_force_and_moment_balance(table2):
    """Integrating (30) over [0, 1]: the internal force
    n = (T - mu kappa^2) r' - mu r''' (Eqs. 32-33, tau = 0) satisfies n' = -q with
    q = k_E + F_A, so n(1) - n(0) = -q (unit length).  With m = mu r' x r'' the
    moment balance m' + r' x n = 0 and r(0) = 0, r''(0) = r''(1) = 0 give
    r(1) x n(1) = -(int_0^1 r ds) x q."""
    q = table2.normalised
    mu = q.mu
    load = np.array([-q.nu * q.v_w0**2, 0.0, 1.0])

    def n(s):
        d1, d2, d3 = (table2.derivatives(s, k) for k in (1, 2, 3))
        kappa2 = (d2**2).sum(axis=1)
        return (table2.tension(s) - mu * kappa2)[:, None] * d1 - mu * d3

    n0, n1 = n(0.0)[0], n(1.0)[0]
    np.testing.assert_allclose(n1 - n0, -load, atol=1e-8)
    # the ends carry shear from bending, not only tension along r'
    assert np.abs(mu * table2.derivatives(0.0, 3)[0]).max() > 0.1
    r_mean = _gauss(table2.centre_line)
    np.testing.assert_allclose(np.cross(table2.centre_line(1.0)[0], n1),
                               -np.cross(r_mean, load), atol=1e-8)


def _beam_string(s, load, P, mu):
    """w of mu w'''' - P w'' = load, w = w'' = 0 at s = 0, 1 (pinned beam-string)."""
    k = np.sqrt(P / mu)
    return (load / (2 * P) * s * (1 - s)
            - load / (P * k**2) * (1 - np.cosh(k * (s - 0.5)) / np.cosh(k / 2)))


def _beam_string_slope(s, load, P, mu):
    k = np.sqrt(P / mu)
    return load / (2 * P) * (1 - 2 * s) + load / (P * k) * np.sinh(k * (s - 0.5)) / np.cosh(k / 2)


def test_small_loads_match_the_linear_beam_string(params):
    """Loads scaled by lam = 1e-2: the displacement from the chord, split into
    normal w and axial u parts, solves the linearised (30),
    mu w'''' - T0 w'' = q_n and mu u'''' - (sigma (1 + eps0) + T0) u'' = q_t with
    T0 = sigma eps0.  The nonlinear error in w is O(lam |q| / T0); the tiny axial
    part u ~ q_t / sigma also feels the shortening by the sag, O(w'^2), hence
    the looser tolerance (measured: 3e-6 for w, 1e-3 for u, 2e-3 for T)."""
    lam = 1e-2
    q = dataclasses.replace(params.normalised(), gravity=lam, drag=lam)
    sol = shooting.solve(q)
    a = 1 + q.eps0
    e = q.top_position() / a  # chord direction
    nrm = np.array([-e[2], 0.0, e[0]])  # normal in the x-z plane
    load = np.array([-lam * q.nu * q.v_w0**2, 0.0, lam])
    d = sol.centre_line(S) - a * np.outer(S, e)
    T0 = q.sigma * q.eps0
    w_ref = _beam_string(S, load @ nrm, T0, q.mu)
    u_ref = _beam_string(S, load @ e, q.sigma * a + T0, q.mu)
    assert np.abs(w_ref).max() > 1e-5
    np.testing.assert_allclose(d @ nrm, w_ref, atol=1e-4 * np.abs(w_ref).max())
    np.testing.assert_allclose(d @ e, u_ref, atol=1e-2 * np.abs(u_ref).max())
    # tension: T = T0 + sigma u' to first order (Eq. 29)
    T_ref = T0 + q.sigma * _beam_string_slope(S, load @ e, q.sigma * a + T0, q.mu)
    np.testing.assert_allclose(sol.tension(S) - T0, T_ref - T0,
                               atol=1e-2 * np.abs(T_ref - T0).max())


def test_single_segment_failure_is_reported(params):
    """Plain shooting over [0, 1] meets the exp(sqrt(sigma/mu)) ~ e^27 axial mode
    and fails; the error must say so with the boundary mismatch."""
    with pytest.raises(RuntimeError, match="mismatch"):
        shooting.solve(params.normalised(), segments=1)


def test_bad_input():
    p = scene.load("mobile_end")  # top end on a circle: not planar
    with pytest.raises(ValueError, match="planar"):
        shooting.solve(p.normalised())
    q = scene.load("stationary_table2").replace(model={"bending": False}).normalised()
    with pytest.raises(ValueError, match="bending"):
        shooting.solve(q)


def test_shares_no_code_with_the_fe_path():
    """The reference must stay independent: importing it loads no FE stack."""
    import subprocess
    import sys
    code = ("import sys; import rawehelix.references.shooting; "
            "print(sorted({m.split('.')[0] for m in sys.modules} & "
            "{'dolfinx', 'ufl', 'basix', 'petsc4py', 'ffcx'}))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
