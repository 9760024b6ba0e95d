"""The lowest modes of each family without options (issue 26), checked against
a dense eigensolve of the same matrices.

Structural damping (Kelvin-Voigt, forms/damping.py) makes every mode above
omega ~ 2 / tau overdamped; their slow roots crowd at -1 / tau (hundreds of
real eigenvalues within 1e-8 of each other at N = 32), which is what made the
whole-spectrum search of ``mobile_end`` with tau_b = tau_t = 1e-3 s fail.  The
reference here is independent of SLEPc and of the search window: the
companion linearisation

    [0  I] [x ]          [I 0] [x ]
    [-K -C] [lx] = lambda [0 M] [lx]

of the assembled (K, C, M), without the Dirichlet rows (they hold x_i = 0
and add only infinite eigenvalues), solved by LAPACK (scipy.linalg.eig): the
whole finite spectrum.  Its eigenvectors are put into the families by the
solver's classifier (the classification is not what is tested here; which
eigenvalues the search returns is).
"""

import math

import numpy as np
import pytest
import scipy.linalg
from mpi4py import MPI
from petsc4py import PETSc

import rawehelix as rh
from rawehelix.families import OVERDAMPED, VIBRATIONS, is_overdamped
from rawehelix.solvers import modal
from rawehelix.solvers.modal import ModalSolver, Window
from rawehelix.solvers.snes import SolverError
from rawehelix.studies import modes as study
from rawehelix.studies import scene

K_LOWEST = 3
DAMPING = {"damping.bending_s": 1e-3, "damping.torsion_s": 1e-3}  # the case


def mobile_end(N, damped=True):
    return scene.load("mobile_end", elements=N, overrides=DAMPING if damped else None)


def windy_table2(N=8):
    """Table 2 with 40 x the drag: the first lateral modes (omega_1 ~ 37-42) are
    overdamped by the linearised drag c = nu v_w0 (1 + (e.i_E)^2) > 2 omega_1."""
    return scene.load("stationary_table2", elements=N,
                      overrides={"helix.drag_coefficient": 40.0})


_cache = {}


def solved(name, N, damped=True):
    key = (name, N, damped)
    if key not in _cache:
        params = mobile_end(N, damped) if name == "mobile_end" else windy_table2(N)
        solver = ModalSolver.from_stationary(params, MPI.COMM_SELF)
        _cache[key] = (solver, solver.solve(require_families=False))
    return _cache[key]


def dense_spectrum(solver):
    """Every finite eigenvalue of (*) and its eigenvector (full size, zero on
    the Dirichlet dofs), by LAPACK on the companion pencil; serial."""
    K, C, M = (A.convert("dense").getDenseArray().copy() for A in (solver.K, solver.C, solver.M))
    free = np.abs(np.diag(M)) > 0
    K, C, M = (A[np.ix_(free, free)] for A in (K, C, M))
    n = K.shape[0]
    I, Z = np.eye(n), np.zeros((n, n))
    lam, vec = scipy.linalg.eig(np.block([[Z, I], [-K, -C]]), np.block([[I, Z], [Z, M]]))
    assert np.all(np.isfinite(lam)) and lam.size == solver.finite_eigenvalue_count()
    full = np.zeros((free.size, lam.size), dtype=complex)
    full[free] = vec[:n]
    return lam, full


def dense_lowest(solver, lam, vectors):
    """Per family the K_LOWEST oscillating eigenvalues (Im > 0) of least
    frequency, and every real nonzero one (overdamped), of the dense spectrum."""
    xr, xi = solver.K.createVecRight(), solver.K.createVecRight()
    by_family = {f: [] for f in solver.families}
    order = np.argsort(np.abs(lam.imag))
    for i in order:
        l = lam[i]
        if l.imag <= 0 or abs(l) < 1e-3 or is_overdamped(l):
            continue  # conjugates, the real ones and the rigid zero
        xr.array[:], xi.array[:] = vectors[:, i].real, vectors[:, i].imag
        fractions, _ = solver.classifier.energy_fractions(xr, xi)
        family = solver.classifier.family(l, xr, xi, fractions)
        if len(by_family[family]) < K_LOWEST:
            by_family[family].append(l)
        if all(len(v) == K_LOWEST for v in by_family.values()):
            break
    real = np.array([l.real for l in lam if abs(l) > 1e-3 and is_overdamped(l)])
    return by_family, real


def lowest(modes, family, k=K_LOWEST):
    return [m.eigenvalue for m in study.ascending(m for m in modes if m.family == family)][:k]


@pytest.mark.parametrize("damped", [True, False])
@pytest.mark.parametrize("N", [8, 16])
def test_lowest_modes_equal_those_of_a_dense_solve(N, damped):
    """Without options the search returns, for every family, the same lowest 3
    oscillating eigenvalues as LAPACK on the whole spectrum (1e-6 relative:
    measured 3e-8 at N = 16, round-off of the fourth-order operator; the
    modes of a family are 30 % or more apart),
    and its overdamped entries are real eigenvalues of that spectrum."""
    solver, modes = solved("mobile_end", N, damped)
    assert solver.missing == {}
    lam, vectors = dense_spectrum(solver)
    reference, real = dense_lowest(solver, lam, vectors)
    if damped:  # the hard case: the cluster of slow overdamped roots at -1/tau_b
        tau = solver.q.tau_bending
        assert np.sum(np.abs(real + 1 / tau) < 1e-3 / tau) > N
    else:
        assert real.size == 0
    for family in solver.families:
        got, ref = np.array(lowest(modes, family)), np.array(reference[family])
        assert len(got) == K_LOWEST and len(ref) == K_LOWEST, (family, got, ref)
        assert np.max(np.abs(got - ref) / np.abs(ref)) < 1e-6, (family, got, ref)
    for m in modes:
        if m.family == OVERDAMPED:
            assert m.eigenvalue.imag == 0
            assert np.min(np.abs(real - m.eigenvalue.real)) < 1e-6 * abs(m.eigenvalue)


def test_damped_mobile_end_decay_rates_at_N32():
    """The issue's case at N = 32, no options: the lowest torsional and lateral
    decay rates found before with hand-set options (1.453 and 1.731 1/s) to
    1 %, every family complete (3 longitudinal modes, the third beyond the
    overdamped cluster), one solve of the window, no error."""
    solver, modes = solved("mobile_end", 32)
    assert solver.missing == {} and solver.search["solves"] == 1
    t_scale = solver.q.t_scale
    decay = {f: -lowest(modes, f, 1)[0].real / t_scale for f in VIBRATIONS}
    assert decay["torsional"] == pytest.approx(1.453, rel=1e-2)
    assert decay["lateral_in_plane"] == pytest.approx(1.731, rel=1e-2)
    assert decay["lateral_out_of_plane"] == pytest.approx(1.731, rel=1e-2)
    assert len(lowest(modes, "longitudinal")) == K_LOWEST
    assert abs(lowest(modes, "longitudinal")[-1]) > 1 / solver.q.tau_bending


def test_rh_modes_in_ascending_frequency():
    """rh.modes, its summary and the printed table list the modes in ascending
    frequency (the rigid rotation first), the overdamped ones last by decay."""
    result = rh.modes(windy_table2(), comm=MPI.COMM_SELF)
    kinds = [m.family == OVERDAMPED for m in result]
    assert kinds == sorted(kinds) and any(kinds)  # the overdamped ones last
    f = [m.frequency_Hz for m in result if m.family != OVERDAMPED]
    assert f == sorted(f) and result[0].family == "rigid"
    decay = [m.decay_per_s for m in result if m.family == OVERDAMPED]
    assert decay == sorted(decay)
    assert [e["family"] for e in result.summary["modes"]] == [m.family for m in result]
    rows = study.format_table(result).splitlines()[2:]
    assert [float(r.split()[-2]) for r in rows if "Overdamped" not in r] == pytest.approx(f,
                                                                                      abs=1e-3)


def test_an_overdamped_pair_is_reported_as_overdamped():
    """40 x the drag of Table 2 overdamps the first out-of-plane mode: two real
    roots of lambda^2 + c lambda + omega_1^2 = 0 with c = nu v_w0 (no wind
    component along j_E) and omega_1^2 = T pi^2 + mu pi^4 (the pinned beam of
    tests/test_modal.py, T the mean tension).  They are listed as
    'overdamped' (decay rates, no period, no frequency), and the out-of-plane
    family's lowest 3 oscillating modes are the next three."""
    solver, modes = solved("windy_table2", 8)
    q = solver.q
    c = q.nu * q.v_w0
    omega1 = math.sqrt(solver.mean_tension_value * math.pi**2 + q.mu * math.pi**4)
    assert c > 2 * omega1  # overdamped indeed
    roots = sorted((m.eigenvalue.real for m in modes
                    if m.family == OVERDAMPED and m.dominant == ["y"]), reverse=True)
    assert len(roots) == 2
    assert sum(roots) == pytest.approx(-c, rel=1e-3)  # the sum of the roots
    assert roots[0] * roots[1] == pytest.approx(omega1**2, rel=0.05)  # their product
    assert all(is_overdamped(m.eigenvalue) == (m.family == OVERDAMPED) for m in modes
               if m.family != "rigid")
    out = lowest(modes, "lateral_out_of_plane")
    assert len(out) == 3 and min(l.imag for l in out) > omega1
    result = study.compute(windy_table2(), comm=MPI.COMM_SELF)
    listed = [m for m in result if m.family == OVERDAMPED]
    assert len(listed) >= 2 and all(m.period_s is None for m in listed)
    assert all(m.decay_per_s == pytest.approx(-m.eigenvalue.real / q.t_scale) for m in listed)
    assert result.info["missing_families"] == {}
    table = study.report(result)
    assert "Overdamped" in table and "note: 'Overdamped' rows are real eigenvalues" in table
    keys = {"family", "eigenvalue", "eigenvalue_per_s", "frequency_Hz", "decay_per_s",
            "period_s", "dominant"}
    assert all(set(e) == keys for e in result.summary["modes"])


def test_a_short_window_is_widened(monkeypatch):
    """A window that holds too few eigenvalues is widened (nev x WIDEN_FACTOR) until
    every family has its 3 oscillating modes: the same modes as the default."""
    solver, modes = solved("mobile_end", 8, damped=False)
    default = solver.window()
    monkeypatch.setattr(ModalSolver, "window",
                        lambda self, per_family=3: Window(default.target, 12, default.cap))
    widened = solver.solve(keep_vectors=False)
    assert solver.search["solves"] > 1 and solver.search["nev"] > 12 and solver.missing == {}
    for family in solver.families:
        assert np.allclose(lowest(widened, family), lowest(modes, family), rtol=1e-9)


def test_a_window_that_cannot_widen_gives_a_clear_error(monkeypatch):
    solver, _ = solved("mobile_end", 8, damped=False)
    target = solver.window().target
    monkeypatch.setattr(ModalSolver, "window",
                        lambda self, per_family=3: Window(target, 8, 10))
    with pytest.raises(SolverError, match="oscillating modes of each family.*-rawehelix_pep_nev"):
        solver.solve(keep_vectors=False)
    assert solver.missing and solver.search["nev"] == 10


def test_the_users_pep_options_pass_through():
    """-rawehelix_pep_nev and -rawehelix_pep_target win over the window (and
    then nothing is widened)."""
    solver, _ = solved("mobile_end", 8)
    options = PETSc.Options()
    options["rawehelix_pep_nev"] = 30
    options["rawehelix_pep_target"] = 20.0
    try:
        solver.solve(keep_vectors=False, require_families=False)
    finally:
        options.delValue("rawehelix_pep_nev")
        options.delValue("rawehelix_pep_target")
    assert solver.search == {"target": 20.0, "nev": 30, "solves": 1}


def test_the_window_keeps_the_cluster_out():
    """The estimates put the slow overdamped roots at about -1/tau; the window's
    disk about its target holds every wanted estimate and none of them, while
    without damping the target stays omega_min / 4."""
    solver, _ = solved("mobile_end", 8)
    window = solver.window()
    est = modal.estimates(solver.q, solver.mean_tension_value, 40)
    real = np.concatenate([r.ravel() for r in est.values()])
    real = real[real.imag == 0].real
    assert real.size and np.all(real <= -1 / solver.q.tau_bending * (1 - 1e-6))
    wanted = np.concatenate([r[r[:, 0].imag > 0, 0][:K_LOWEST] for r in est.values()])
    far = np.abs(wanted - window.target).max()
    assert np.all(np.abs(real - window.target) > far)
    undamped, _ = solved("mobile_end", 8, damped=False)
    assert undamped.window().target == pytest.approx(undamped.default_target())


@pytest.mark.mpi
def test_same_lowest_modes_on_all_ranks():
    """The window (estimates from the allreduced mean tension) and the modes
    are those of one rank: the issue's damped case at N = 16."""
    serial, _ = solved("mobile_end", 16)
    parallel = ModalSolver.from_stationary(mobile_end(16), MPI.COMM_WORLD)
    a, b = parallel.window(), serial.window()
    assert (a.nev, a.cap) == (b.nev, b.cap) and a.target == pytest.approx(b.target, rel=1e-12)
    modes = parallel.solve(keep_vectors=False)
    _, reference = solved("mobile_end", 16)
    for family in VIBRATIONS:
        assert np.allclose(lowest(modes, family), lowest(reference, family), rtol=1e-8)
