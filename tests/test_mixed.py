"""The mixed bending form (discretisation.bending = "mixed", forms/mixed.py):
observed orders against shooting, agreement with the IP form, large N, the
massless curvature field in the modal and dynamic solvers, and the refusals."""

import math

import numpy as np
import pytest
from mpi4py import MPI

import dolfinx.fem

from rawehelix.errors import SceneError
from rawehelix.references import shooting
from rawehelix.solvers import analytic
from rawehelix.solvers.dynamics import DynamicsSolver
from rawehelix.solvers.modal import ModalSolver
from rawehelix.solvers.stationary import StationarySolver
from rawehelix.cli import main as cli
from rawehelix.studies import scene

ELEMENTS = (2, 4, 8, 16)


def table2(N, p=3, bending="mixed"):
    return scene.load("stationary_table2", elements=N, degree=p,
                      overrides={"discretisation.bending": bending})


@pytest.fixture(scope="module")
def reference():
    return shooting.solve(table2(2).normalised())


def errors(N, p, reference, bending="mixed"):
    """(max |r - r_shooting| at the nodes, |T(0) / T_shooting(0) - 1|, result), normalised."""
    res = StationarySolver(table2(N, p, bending), MPI.COMM_SELF).solve()
    dr = np.max(np.linalg.norm(res.centre_line - reference.centre_line(res.s), axis=1))
    T0 = float(np.ravel(reference.tension(0.0))[0])
    return dr, abs(res.tension[0] / T0 - 1), res


@pytest.mark.parametrize("p,rate", [(2, 3.5), (3, 3.5)])
def test_mixed_centre_line_order(reference, p, rate):
    """max |r_FE - r_shooting| at the nodes falls like h^rate, N = 2 ... 16
    (observed log2 ratios: p = 2: 4.06, 3.81, 3.79; p = 3: 4.55, 3.82, 4.00;
    the IP form's are ~p + 1 with 100x larger errors at p = 3)."""
    e = np.array([errors(N, p, reference)[0] for N in ELEMENTS])
    rates = np.log2(e[:-1] / e[1:])
    assert np.all(rates > rate), (e, rates)


def test_mixed_tension_order(reference):
    """T(0) (the end value of sigma (|r'| - 1)) converges like h^p: observed
    log2 ratios 2.12, 2.52 for N = 8, 16, 32 at p = 3, tending to 3.0 (N = 2000,
    docs/explanation/large_n.md)."""
    e = np.array([errors(N, 3, reference)[1] for N in (8, 16, 32)])
    rates = np.log2(e[:-1] / e[1:])
    assert np.all(rates > 2.0) and e[-1] < 5e-6, (e, rates)


def test_ip_and_mixed_agree(reference):
    """N = 32, p = 3: centre lines within 1e-9 (normalised; IP error 4e-10,
    mixed 2e-12), T(0) within 1e-5, and the lowest eigenvalue of each family
    within 1e-6 (measured 4e-8 for the lateral ones)."""
    dr_ip, dT_ip, ip = errors(32, 3, reference, "ip")
    dr_m, dT_m, mixed = errors(32, 3, reference, "mixed")
    assert dr_m < dr_ip
    assert np.max(np.abs(ip.centre_line - mixed.centre_line)) < 1e-9
    assert abs(ip.tension[0] / mixed.tension[0] - 1) < 1e-5
    low = {}
    for bending in ("ip", "mixed"):
        params = table2(32, 3, bending)
        modes = ModalSolver.from_stationary(params, MPI.COMM_SELF).solve(
            per_family=1, keep_vectors=False)
        low[bending] = {}
        for m in modes:
            low[bending].setdefault(m.family, abs(m.eigenvalue))
    for family, lam in low["ip"].items():
        if family != "rigid":
            assert low["mixed"][family] == pytest.approx(lam, rel=1e-6), family


def test_mixed_large_n_in_seconds(reference):
    """N = 2000, p = 3 (where the IP form's lateral eigenvalue is 16 % off):
    centre line within 1e-12 of shooting (measured 5.6e-14, normalised; 9e-13 m),
    T(0) within 1e-10 (measured 1.6e-11)."""
    dr, dT, res = errors(2000, 3, reference)
    assert dr < 1e-12 and dT < 1e-10, (dr, dT)
    assert res.newton_iterations <= 5


def test_curvature_field_is_r_second_derivative():
    """kappa of a state set from a centre line is r'' (kappa equation, kappa = 0
    at the ends): exact for r_z = s^3/6 - s^4/12 at p = 4, r'' = s (1 - s)."""
    rod = StationarySolver(table2(4, 4), MPI.COMM_SELF).rod
    rod.set_centre_line(lambda s: np.stack([s, 0 * s, s**3 / 6 - s**4 / 12], axis=1))
    kappa = rod.w.sub(2).collapse()
    kappa = kappa[0] if isinstance(kappa, tuple) else kappa
    s = kappa.function_space.tabulate_dof_coordinates()[:, 0]
    k = kappa.x.array.reshape(-1, 3)
    assert np.max(np.abs(k[:, 2] - s * (1 - s))) < 1e-10  # round-off of the mass solve: 2e-12
    assert np.max(np.abs(k[:, :2])) < 1e-10


def test_modal_massless_curvature():
    """M and C vanish on the kappa rows; the finite count leaves kappa out; the
    lowest mode of each family is within 0.5 % of the classical one."""
    solver = ModalSolver.from_stationary(table2(8), MPI.COMM_SELF)
    rod = solver.rod
    kappa_dofs = np.asarray(rod._kappa_dofs)
    for A in (solver.M, solver.C):
        rows = A.getValues(kappa_dofs.astype(np.int32), np.arange(A.getSize()[1], dtype=np.int32))
        assert np.all(rows == 0.0)
        assert np.max(np.abs(A.getDiagonal().array[kappa_dofs])) == 0.0
    n_r_alpha = 4 * (3 * 8 + 1)
    assert solver.finite_eigenvalue_count() == 2 * (n_r_alpha - 6)
    modes = solver.solve(per_family=1, keep_vectors=False)
    q, T = solver.q, solver.mean_tension_value
    classical = {"longitudinal": analytic.bar(q, 1, T), "lateral_in_plane": analytic.beam(q, 1, T),
                 "lateral_out_of_plane": analytic.beam(q, 1, T), "torsional": analytic.shaft(q, 1)}
    for family, omega in classical.items():
        lam = min(abs(m.eigenvalue) for m in modes if m.family == family)
        assert lam == pytest.approx(float(omega), rel=5e-3), family


def free_vibration(bending, until=0.2):
    """Sec. 5.2's helix without torque, controller and drag, N = 8, dt = 10 ms
    fixed, alpha2, from the stationary state + a 1.6 cm lateral bump and a twist;
    returns the final r, alpha at the nodes."""
    p = scene.load("nominal_operation", elements=8, degree=3).replace(
        torque={"top_Nm": 0.0}, controller={"k1": 0.0, "k2": 0.0, "target_rpm": 0.0},
        model={"drag": False, "gamma": "off"}, time={"dt_s": 0.01},
        discretisation={"bending": bending})
    solver = DynamicsSolver.from_stationary(p, options={"ts_adapt_type": "none"})
    state, rod = solver.state(), solver.rod
    w = dolfinx.fem.Function(rod.W)
    rod.set_state(state, w=w)
    r = w.sub(0).collapse()
    r = r[0] if isinstance(r, tuple) else r
    bump = dolfinx.fem.Function(rod.V_r)
    bump.interpolate(lambda x: np.stack([0 * x[0], 1e-3 * np.sin(np.pi * x[0]), 0 * x[0]]))
    r.x.array[:] += bump.x.array
    w.sub(0).interpolate(r)
    w.sub(1).interpolate(lambda x: 1e-2 * np.cos(np.pi * x[0]))
    w.x.scatter_forward()
    rod.update_curvature(w)  # a consistent start for the index-1 DAE
    state.w, state.offset = w.x.array.copy(), None
    solver.set_state(state)
    solver.advance(until / solver.q.t_scale)
    f = solver.probes.fields()
    return np.concatenate([f["r"].ravel(), f["alpha"]]), solver


def test_dynamics_mixed_follows_ip():
    """alpha2 on the (r, alpha, kappa) DAE: the free vibration follows the IP
    form's to the discretisation difference (measured 1.6e-7 of max |r| after 0.5 s)
    with the same Newton iterations."""
    ip, s_ip = free_vibration("ip")
    mixed, s_m = free_vibration("mixed")
    assert np.max(np.abs(ip - mixed)) < 1e-6 * np.max(np.abs(ip))
    assert s_m.newton_iterations <= s_ip.newton_iterations + 2


def test_first_order_ts_refused_with_mixed():
    p = scene.load("nominal_operation", elements=4, degree=3,
                   overrides={"discretisation.bending": "mixed"})
    with pytest.raises(ValueError, match="alpha2"):
        DynamicsSolver(p, MPI.COMM_SELF, options={"ts_type": "cn"})


def test_bending_is_validated():
    with pytest.raises(SceneError, match="discretisation.bending"):
        table2(4, 3, "hermite")


@pytest.mark.parametrize("p,limit", [(3, 512), (2, 879)])
def test_ip_limit(p, limit):
    assert table2(4, p, "ip").discretisation.ip_limit() == limit


def test_cli_refuses_ip_past_its_limit(tmp_path, capsys):
    """The commands refuse the IP form past N = ip_limit and name the limit and the remedy."""
    out = tmp_path / "out"
    assert cli.main(["modes", "stationary_table2", "--elements", "1000", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "N <= 512" in err and "discretisation.bending=mixed" in err
    assert not out.exists()
    assert math.isfinite(table2(1000, 3, "ip").discretisation.ip_limit())


@pytest.mark.parametrize("command", ["modes", "simulate", "sweep"])
def test_library_refuses_ip_past_its_limit(command):
    """The refusal lives in the library: Python callers get it too (the
    stationary state is not refused: it reports its distance to shooting)."""
    import rawehelix as rh
    scene_ = rh.load_scene("mobile_end", elements=1000)
    with pytest.raises(rh.SceneError, match="N <= 512"):
        getattr(rh, command)(scene_)
