"""Rung 4 of the verification ladder: FE spectra (SLEPc) against classical results.

The FE modes about the stationary state (``solvers.modal``) are compared with
the classical continuous systems, written in the normalised variables of
Eqs. (25)-(29) (unit mass per unit length, s in [0, 1]):

* longitudinal: fixed-fixed elastic bar (Rao, *Vibration of Continuous
  Systems*, 2nd ed. 2019, Sec. 9.3; Graff, *Wave Motion in Elastic Solids*,
  1975, Sec. 2.2), with the axial stiffness of this model.  About a straight
  state r' = (1 + eps) e the tension law T = sigma (|r'| - 1) (29) gives
  d(T r') = sigma (1 + eps) (e.u') e + T u' = sigma (1 + 2 eps) (e.u') e + T u'_perp:
  the axial stiffness is sigma (1 + 2 eps), eps = T / sigma.  The bending
  term mu r'''' of Eq. (33) acts on every component of r, axial ones included,
  and with u = u'' = 0 at the ends (35)-(37) the modes stay sin(n pi s):

      omega_n^2 = sigma (1 + 2 eps) (n pi)^2 + mu (n pi)^4.

  (The bending part is 1.3 % of omega_1^2 for Table 2.)
* lateral, in and out of plane: pinned (simply supported) beam under tension
  (Rao, Sec. 11.5, beam under axial force; Graff, Sec. 3.4): with the lateral
  stiffness T from the expansion above,

      omega_n^2 = (n pi)^2 T + mu (n pi)^4.

  The tension varies along the helix by the weight component along the chord,
  linearly to first order; sin^2 and cos^2 (n pi s) are symmetric about
  s = 1/2, so the first-order Rayleigh quotient sees exactly the mean tension
  T = int_0^1 T ds, taken here from the independent shooting solution of
  Sys. (67).  The sag adds the Irvine stiffening to the symmetric in-plane
  modes (Irvine, *Cable Structures*, 1981): +0.07 % for n = 1 of Table 2.
* torsional: free-free shaft (Rao, Sec. 8.3; Graff, Sec. 2.4): alpha_tt =
  delta alpha'' with alpha' = 0 at both ends (38)-(39), omega_n = n pi sqrt(delta).

The drag (28) only damps: a mode lambda = -c/2 +- i sqrt(omega_0^2 - c^2/4)
has |lambda| = omega_0, which is what is compared.  The linearised drag of
F = -nu |v_A| v_A, v_A = v + v_w0 i_E, at v = 0 is dF = -nu v_w0 (dv + (i_E.dv) i_E),
so a motion along the unit vector e is damped by c = nu v_w0 (1 + (e.i_E)^2)
and Re lambda = -c/2.

The 0.5 % agreement for the first three modes of every family holds from
N = 8 elements of degree p = 3 (the convergence table is in
docs/explanation/modal_convergence.md); these tests run at N = 8, p = 3 with the gamma
coupling off (the classical models have none).  Its effect is measured in
:func:`test_gamma_coupling`.
"""

import functools
import math

import numpy as np
import pytest
from mpi4py import MPI

from rawehelix.families import VIBRATIONS
from rawehelix.parameters import (Discretisation, Ends, Environment, Helix, Model, ParameterError,
                                  Parameters)
from rawehelix.references import shooting
from rawehelix.solvers import analytic
from rawehelix.solvers.modal import ModalSolver
from rawehelix.solvers.pep import create_pep
from rawehelix.solvers.stationary import StationarySolver
from rawehelix.studies import modes as study
from rawehelix.studies import scene
from rawehelix.studies.scene import SceneError

N, P = 8, 3


def table2(N=N, p=P, gamma="off"):
    return scene.load("stationary_table2", elements=N, degree=p).replace(model={"gamma": gamma})


def second_helix(N=N, p=P, gamma="off"):
    """A 100 m, 20 kg helix at 20 deg elevation, no wind, stiffer in bending and
    softer in torsion (sigma = 3000, mu = 0.5, beta = 0.01, delta = 30,
    T / weight ~ 60): nothing of Table 2 but the model."""
    M, g, L0 = 20.0, 9.81, 100.0
    Mg = M * g
    return Parameters(
        helix=Helix(length_m=L0, mass_kg=M, EA_N=3000.0 * Mg, EI_Nm2=0.5 * Mg * L0**2,
                    GJ_Nm2=0.01 * Mg * L0**2, radius_m=0.5),
        ends=Ends(elongation=0.02, elevation_deg=20.0),
        environment=Environment(g_m_s2=g, wind_speed_m_s=0.0),
        model=Model(gamma=gamma),
        discretisation=Discretisation(elements=N, degree=p))


SCENES = {"table2": table2, "second": second_helix}


def classical(q, T, family, n):
    """omega_n of the classical model of ``family`` (module docstring, solvers.analytic)."""
    if family == "longitudinal":
        return float(analytic.bar(q, n, T))
    if family.startswith("lateral"):
        return float(analytic.beam(q, n, T))
    return float(analytic.shaft(q, n))


@functools.lru_cache
def mean_tension(q):
    """int_0^1 T ds of the shooting solution of Sys. (67) (independent of the FE)."""
    s = np.linspace(0.0, 1.0, 2001)
    T = shooting.solve(q).tension(s)
    return float(np.sum(0.5 * (T[1:] + T[:-1]) * np.diff(s)))


_cache = {}


def spectrum(name, comm=MPI.COMM_SELF, gamma="off", N=N, p=P):
    key = (name, comm.size, gamma, N, p)
    if key not in _cache:
        solver = ModalSolver.from_stationary(SCENES[name](N, p, gamma), comm)
        _cache[key] = (solver, solver.solve())
    return _cache[key]


def first(modes, family, count=3):
    return [m.eigenvalue for m in modes if m.family == family][:count]


@pytest.mark.parametrize("name", SCENES)
@pytest.mark.parametrize("family", VIBRATIONS)
def test_classical_frequencies(name, family):
    """|lambda_n| of the first three modes of each family within 0.5 % of the
    classical omega_n (bar, tensioned pinned beam, free-free shaft)."""
    solver, modes = spectrum(name)
    q = solver.q
    T = mean_tension(q)
    assert T == pytest.approx(solver.mean_tension_value, rel=1e-4)
    lam = first(modes, family)
    assert len(lam) == 3, [(m.eigenvalue, m.family) for m in modes]
    errors = [abs(l) / classical(q, T, family, n + 1) - 1 for n, l in enumerate(lam)]
    assert max(abs(e) for e in errors) < 5e-3, errors


@pytest.mark.parametrize("family", VIBRATIONS)
def test_damping_table2(family):
    """Re lambda = -c/2, c = nu v_w0 (1 + (e.i_E)^2), within 2 %: e along the
    chord (longitudinal), normal to it in the x-z plane, and along y; the twist
    is not damped by the drag of the centre line."""
    solver, modes = spectrum("table2")
    q = solver.q
    chord = q.top_position() / np.linalg.norm(q.top_position())
    e = {"longitudinal": chord, "lateral_in_plane": np.cross([0.0, 1.0, 0.0], chord),
         "lateral_out_of_plane": np.array([0.0, 1.0, 0.0])}
    lam = first(modes, family)
    if family == "torsional":
        assert max(abs(l.real) for l in lam) < 1e-6 * abs(lam[0])
        return
    c = q.nu * q.v_w0 * (1 + e[family][0] ** 2)
    for l in lam:
        assert l.real == pytest.approx(-c / 2, rel=0.02)


def test_no_damping_without_wind():
    """Second helix: no wind, so the linearised drag vanishes and every mode is
    undamped (Re lambda = 0 to rounding).  The rigid rotation is a Jordan pair
    at zero, which round-off splits by O(sqrt(eps)) (measured 2.4e-6 with the
    3p quadrature, 1e-9 with UFL's): test_rigid_rotation bounds it."""
    _, modes = spectrum("second")
    vibrations = [m for m in modes if m.family != "rigid"]
    assert all(abs(m.eigenvalue.real) < 1e-8 * max(abs(m.eigenvalue), 1.0) for m in vibrations)


@pytest.mark.parametrize("name", SCENES)
def test_rigid_rotation(name):
    """The twist is free: exactly one zero eigenvalue (the Jordan pair of the
    rigid rotation, reported once), a uniform alpha; nothing else near zero."""
    solver, modes = spectrum(name)
    rigid = [m for m in modes if m.family == "rigid"]
    assert len(rigid) == 1
    assert abs(rigid[0].eigenvalue) < 1e-4
    assert rigid[0].fractions["torsional"] > 0.999
    others = min(abs(m.eigenvalue) for m in modes if m.family != "rigid")
    assert others == pytest.approx(float(analytic.shaft(solver.q, 1)), rel=5e-3)


def test_dirichlet_rows_give_no_spurious_eigenvalues():
    """With 1 on the bc diagonal of K and 0 on those of C and M, every
    eigenvector vanishes on the fixed ends and no eigenvalue comes from the bc
    rows.  The naive choice (1 on the bc diagonals of K *and* M) puts a
    spurious pair lambda = +-i on each of the 6 bc dofs: shown here."""
    solver, modes = spectrum("table2")
    slow = [m for m in modes if abs(m.eigenvalue) < 1000]
    assert len(slow) > 30
    assert max(solver.bc_amplitude(m) for m in slow) < 1e-9
    # the fastest modes (|lambda| ~ 5e4 at N = 8) converge to a backward error
    # ~ 1e-8 only; their bc amplitude is of that order, not O(1)
    assert all(solver.bc_amplitude(m) < 100 * m.error + 1e-12 for m in modes)
    assert all(abs(abs(m.eigenvalue) - 1.0) > 0.5 for m in modes)
    import dolfinx.fem.petsc
    M1 = dolfinx.fem.petsc.assemble_matrix(solver.lin.a_M, bcs=solver.bcs, diagonal=1.0)
    M1.assemble()
    pep = create_pep(MPI.COMM_SELF, [solver.K, solver.C, M1], 16, 0.5,
                    solver.finite_eigenvalue_count(), prefix="rawehelix_naive_")
    pep.solve()
    lam = np.array([pep.getEigenpair(i) for i in range(pep.getConverged())])
    spurious = np.sum(np.abs(lam - 1j) < 1e-8) + np.sum(np.abs(lam + 1j) < 1e-8)
    assert spurious == 12


def test_gamma_coupling():
    """The regularised Frenet torsion gamma (Eq. 34, model.gamma_eps = 1e-3)
    couples the out-of-plane motion and the twist: D gamma ~ y_sss / kappa
    drives alpha, and beta tau (r' x r'') of Eq. (32) drives y back.  Measured
    at N = 16, p = 3 for Table 2: the out-of-plane modes keep their frequency
    within 0.5 % and their lateral damping, but carry most of their kinetic
    energy in alpha (so they are found by the block residuals, not by energy);
    the torsional modes move by up to 0.5 % and lose the exact zero damping."""
    solver, modes = spectrum("table2", gamma="regularised", N=16)
    _, reference = spectrum("table2", gamma="off", N=16)
    q, T = solver.q, solver.mean_tension_value
    out = [m for m in modes if m.family == "lateral_out_of_plane"][:3]
    assert len(out) == 3
    for n, m in enumerate(out):
        assert abs(m.eigenvalue) == pytest.approx(classical(q, T, m.family, n + 1), rel=5e-3)
        assert m.eigenvalue.real == pytest.approx(-q.nu * q.v_w0 / 2, rel=0.05)
        assert m.fractions["torsional"] > 0.9  # the twist dominates the kinetic energy
    tors = first(modes, "torsional")
    tors_off = first(reference, "torsional")
    shift = [abs(a) / abs(b) - 1 for a, b in zip(tors, tors_off)]
    assert max(abs(x) for x in shift) < 5e-3
    assert max(abs(x) for x in shift) > 1e-4  # the coupling is visible...
    assert max(abs(l.real) for l in tors_off) < 1e-6  # ... and absent without gamma


def test_without_twist_field():
    """model.twist = false (a torque-free scene) holds alpha = 0: no torsional
    modes and no rigid rotation.  With gamma off the twist drives the centre
    line (the moment beta alpha' (r' x r'') of Eq. 32) but not the reverse at a
    twist-free stationary state, so the block-triangular spectrum keeps the
    centre-line eigenvalues of the full model: equal to 1e-8 here (N = 8)."""
    _, full = spectrum("table2")
    solver = ModalSolver.from_stationary(table2().replace(model={"twist": False}), MPI.COMM_SELF)
    modes = solver.solve()
    assert solver.families == VIBRATIONS[:3]
    assert not [m for m in modes if m.family in ("torsional", "rigid")]
    for family in VIBRATIONS[:3]:
        a, b = np.array(first(modes, family)), np.array(first(full, family))
        assert len(a) == 3 and np.max(np.abs(a - b) / np.abs(b)) < 1e-8, (family, a, b)
    assert max(solver.bc_amplitude(m) for m in modes[:10]) < 1e-9  # alpha = 0 holds


def test_twist_switch_needs_a_torque_free_fe_scene():
    with pytest.raises(ParameterError, match="model.twist.*torque-free"):
        scene.load("nominal_operation").replace(model={"twist": False})
    with pytest.raises(ParameterError, match="FE scheme only"):
        table2().replace(model={"twist": False}, discretisation={"scheme": "spline"})


@pytest.mark.mpi
def test_same_spectrum_on_all_ranks():
    """The 20 slowest modes on COMM_WORLD agree with a COMM_SELF solve: same
    families, eigenvalues to 1e-9 relative.  The rigid zero is a defective
    (Jordan) eigenvalue, computed only to ~sqrt(machine eps) ~ 1e-6 on either."""
    _, serial = spectrum("table2", comm=MPI.COMM_SELF)
    _, parallel = spectrum("table2", comm=MPI.COMM_WORLD)
    assert [m.family for m in serial[:20]] == [m.family for m in parallel[:20]]
    a = np.array([m.eigenvalue for m in serial[:20] if m.family != "rigid"])
    b = np.array([m.eigenvalue for m in parallel[:20] if m.family != "rigid"])
    assert np.max(np.abs(a - b) / np.abs(a)) < 1e-9
    assert abs(serial[0].eigenvalue) < 1e-4 and abs(parallel[0].eigenvalue) < 1e-4


@pytest.mark.long  # 5.1 s: make test's budget (2026-12-05); make test keeps the modes command
# through test_compute_default_selection_fe and the faults' modes rows
def test_cli_writes_outputs(tmp_path):
    """``rawehelix modes`` with the FE scheme: table, summary.json (the spline
    reference's mode keys plus discretisation and wall time), PNG and XDMF."""
    import json
    lines = []
    result = study.compute(table2(4, 3, gamma="regularised"), count=6, comm=MPI.COMM_SELF)
    lines = study.report(result).splitlines()
    result.write(tmp_path)
    summary = result.summary
    saved = json.loads((tmp_path / "summary.json").read_text())
    assert saved == summary
    assert saved["elements"] == 4 and saved["degree"] == 3 and saved["wall_s"] > 0
    assert len(saved["modes"]) == 6
    for m in saved["modes"]:
        assert set(m) == {"family", "eigenvalue", "eigenvalue_per_s", "frequency_Hz",
                          "decay_per_s", "period_s", "dominant"}
    assert len(saved["kinetic_energy_fractions"]) == 6
    assert saved["modes"][0]["family"] == "rigid"  # ascending frequency: the zero eigenvalue first
    assert (tmp_path / "modes.png").stat().st_size > 1000
    assert "lateral_in_plane_displacement" in (tmp_path / "modes.xdmf").read_text()
    assert any("Torsional" in line for line in lines)


def test_solver_takes_a_state():
    """ModalSolver runs no Newton: it linearises about the state it is given,
    here a stationary state of another rod of the same discretisation, and
    finds the spectrum of ModalSolver.from_stationary."""
    params = table2(4)
    solver = ModalSolver(params, MPI.COMM_SELF)
    assert solver.stationary_result is None and not np.any(solver.rod.w.x.array)
    with pytest.raises(RuntimeError, match="linearise"):
        solver.solve()
    state = StationarySolver(params, MPI.COMM_SELF).solve().state
    solver.linearise(state)
    assert np.array_equal(solver.rod.w.x.array, state.w)
    shared = ModalSolver.from_stationary(params, MPI.COMM_SELF)
    assert shared.stationary_result.newton_iterations > 0
    a = np.array([m.eigenvalue for m in solver.solve(nev=12)])
    b = np.array([m.eigenvalue for m in shared.solve(nev=12)])
    assert np.allclose(a, b, rtol=1e-9, atol=1e-7)


def _check_default_selection(result, families):
    for family in families:
        assert sum(m.family == family for m in result) == 3, [(m.family, m.eigenvalue)
                                                             for m in result]
    assert result[0].family == "rigid" and all(m.period_s is None for m in result
                                               if m.family == "rigid")
    im = [abs(m.eigenvalue.imag) for m in result]
    assert im == sorted(im)  # ascending frequency, as the table of rawehelix modes
    assert result.summary["missing_families"] == {}


def test_compute_default_selection_fe(tmp_path, monkeypatch):
    """compute(): the lowest 3 modes of each family and the rigid rotation, in
    SI; the shapes at unit amplitude; nothing written until write()."""
    monkeypatch.chdir(tmp_path)
    params = table2(4)
    q = params.normalised()
    result = study.compute(params, comm=MPI.COMM_SELF)
    assert not list(tmp_path.iterdir())
    _check_default_selection(result, VIBRATIONS)
    assert sum(m.family == "rigid" for m in result) == 1
    for m in result:
        assert m.frequency_Hz == pytest.approx(abs(m.eigenvalue.imag) / (2 * math.pi * q.t_scale))
        assert m.decay_per_s == pytest.approx(-m.eigenvalue.real / q.t_scale)
        n = len(m.s_m)
        assert m.displacement.shape == (n, 3) and m.alpha_rad.shape == (n,)
        amp = max(np.linalg.norm(m.displacement, axis=1).max(), np.abs(m.alpha_rad).max())
        assert amp == pytest.approx(1.0)
        assert m.s_m[0] == 0.0 and m.s_m[-1] == pytest.approx(params.helix.length_m)
    lon = next(m for m in result if m.family == "longitudinal")
    assert np.linalg.norm(lon.displacement, axis=1).max() == pytest.approx(1.0)
    assert result.x0_m.shape == (len(lon.s_m), 3)
    assert "Rigid rotation" in study.format_table(result)
    # the animation of studies.present.render, when it is there: one GIF per family's first mode
    from rawehelix.studies.present import render
    calls = []

    def animation(path, s_m, x0_m, displacement, alpha_rad, radius_m, title):
        assert x0_m.shape == displacement.shape and alpha_rad.shape == s_m.shape
        assert radius_m == params.helix.radius_m
        calls.append(title)
        path.write_bytes(b"GIF89a")
        return path

    monkeypatch.setattr(render, "mode_animation", animation, raising=False)
    monkeypatch.setattr(render, "available", lambda: True, raising=False)
    paths = result.write(tmp_path / "out")
    assert {p.name for p in paths} == {"summary.json", "modes.png", "modes.xdmf",
                                       *(f"mode_{f}.gif" for f in VIBRATIONS)}
    assert len(calls) == 4 and calls[0].startswith("Longitudinal")


def test_compute_default_selection_spline():
    result = study.compute(scene.load("stationary_table2", scheme="spline", elements=4))
    _check_default_selection(result, VIBRATIONS)
    assert all(m.displacement is None for m in result)  # no shapes from the reference


@pytest.mark.parametrize("count", [0, -2, 2.5, True, "3"])
def test_compute_refuses_a_bad_count(count):
    with pytest.raises(SceneError, match="modes: count: must be an integer >= 1"):
        study.compute(table2(4), count=count, comm=MPI.COMM_SELF)
