"""The section laws in the FE rod (forms/section_law.py, issue 29) against members.py
(numpy, no UFL), the solid section and a numpy reference of the saturating cone.

* the UFL member energy and resultants equal members.py's at the same strains;
* all taut, small amplitude: the tensegrity's stationary state and spectrum are the
  solid's with the members' taut EA and EI, to the slack regularisation's error;
* a sagging state with slack members converges as the slack width w -> 0, and its
  slack onset does not move with w;
* the saturating law: convex, its moment tends to c N R, the solid where all taut.
"""

import functools
import math

import dolfinx
import numpy as np
import pytest
import ufl
from mpi4py import MPI

from rawehelix.forms import section_law
from rawehelix.members import Members, ramp_energy
from rawehelix.parameters import ParameterError
from rawehelix.parameters.eilaw import PAPER_EI_LAW
from rawehelix.solvers import fields
from rawehelix.solvers.modal import ModalSolver
from rawehelix.solvers.stationary import StationarySolver
from rawehelix.studies import scene

N, P = 8, 3


def table2(**changes):
    return scene.load("stationary_table2", elements=N, degree=P).replace(
        model={"kinematics": "extensible"}, **changes)


# -- the UFL law at a point: a one-element mesh and constant strains ------------------
class PointLaw:
    """W, N = dW/d eps, M = dW/d kappa and the Hessian of a section law at constant
    (eps, kappa), assembled over the unit interval (so each equals the integrand)."""

    def __init__(self, section):
        mesh = dolfinx.mesh.create_unit_interval(MPI.COMM_SELF, 1)
        self.eps_c = dolfinx.fem.Constant(mesh, 0.0)
        self.kap_c = dolfinx.fem.Constant(mesh, 0.0)
        e, k = ufl.variable(self.eps_c), ufl.variable(self.kap_c)
        W = section.W(e, k)
        N, M = section.dW(self.eps_c, self.kap_c)
        dx = ufl.dx(mesh)
        exprs = {"W": W, "N": N, "M": M, "N_auto": ufl.diff(W, e), "M_auto": ufl.diff(W, k),
                 "Wee": ufl.diff(ufl.diff(W, e), e), "Wek": ufl.diff(ufl.diff(W, e), k),
                 "Wkk": ufl.diff(ufl.diff(W, k), k)}
        self.forms = {name: dolfinx.fem.form(x * dx) for name, x in exprs.items()}

    def __call__(self, eps, kappa):
        self.eps_c.value, self.kap_c.value = eps, kappa
        return {name: dolfinx.fem.assemble_scalar(f) for name, f in self.forms.items()}


@functools.lru_cache
def normalised_tensegrity(width=1e-4, lay=0.0, P0=0.0, EA_b=0.0):
    p = table2(section={"law": "tensegrity", "slack_width": width, "lay_angle_deg": lay,
                        "self_stress_N": P0, "bar_EA_N": EA_b})
    return p, p.normalised()


@pytest.mark.parametrize("lay, P0, EA_b", [(0.0, 0.0, 0.0), (20.0, 150.0, 2e4)])
def test_ufl_member_energy_is_members_py(lay, P0, EA_b):
    """W, N and M of the UFL law equal Members.energy / resultants (numpy) at the same
    strains, taut and slack, to round-off (in SI: W~ M g, kappa = kappa~ / L0);
    the hand-written dW equals UFL's derivative of W."""
    p, q = normalised_tensegrity(1e-4, lay, P0, EA_b)
    members = p.model.section.members(p.helix)
    law = PointLaw(section_law.from_normalised(q))
    Mg, L0 = p.helix.mass_kg * p.environment.g_m_s2, p.helix.length_m
    seen_slack = 0
    for eps in (-2e-3, 0.0, 1e-3, 5.5e-3):
        for kappa in (0.0, 0.05, 0.3, 2.0, 8.0):  # normalised
            got = law(eps, kappa)
            want = members.resultants(eps, kappa / L0)
            seen_slack += bool((members.strains(eps, kappa / L0) <= 0).any())
            assert got["W"] * Mg == pytest.approx(float(members.energy(eps, kappa / L0)),
                                                  rel=1e-10, abs=1e-9 * Mg)
            assert got["N"] * Mg == pytest.approx(float(want["N"]), rel=1e-10, abs=1e-8)
            assert got["M"] * Mg * L0 == pytest.approx(float(want["M"]), rel=1e-10, abs=1e-8)
            assert got["N_auto"] == pytest.approx(got["N"], rel=1e-8, abs=1e-9)
            assert got["M_auto"] == pytest.approx(got["M"], rel=1e-8, abs=1e-9)
    assert seen_slack >= 3  # the samples cross the slack onset


# -- all taut: the tensegrity is the solid with its taut constants ---------------------
def equivalent_pair(width=1e-4):
    """(tensegrity, solid) scenes of Table 2 with the solid's EI the members' taut EI
    (their taut EA is helix.EA_N by construction, parameters/section.py)."""
    p, _ = normalised_tensegrity(width)
    taut = p.model.section.members(p.helix).taut_moduli()
    assert taut["EA"] == pytest.approx(p.helix.EA_N, rel=1e-12)
    solid = table2(helix={"EI_Nm2": taut["EI"]})
    return p.replace(helix={"EI_Nm2": taut["EI"]}), solid


def member_strain_range(solver):
    """(s, e_min over the members, e on the inner member phi = 0) along the rod."""
    r, c = solver.rod.centre_line(), solver.rod.c
    sec = c.section
    eps, _, kappa = sec.strains(r, c)
    strains = sec.member_strains(eps, kappa)
    s, e0 = fields.gather(fields.interpolate_expression(strains[0], solver.V_T))
    lowest = [fields.gather(fields.interpolate_expression(e, solver.V_T))[1][:, 0] for e in strains]
    return s, np.min(lowest, axis=0), e0[:, 0]


@functools.lru_cache
def taut_states():
    tens, solid = equivalent_pair()
    out = {}
    for name, p in (("tensegrity", tens), ("solid", solid)):
        S = StationarySolver(p, MPI.COMM_SELF)
        out[name] = (S.solve(), S)
    _, e_min, _ = member_strain_range(out["tensegrity"][1])
    return out, float(e_min.min())


def regularisation_bound(e_min, w=1e-4):
    """A member's force error k (<e>_w - e) = k (sqrt(e^2 + w^2) - e) / 2 <= k w^2 / (4 e):
    relative to its force k e at most w^2 / (4 e_min^2); the state's and the spectrum's
    relative change is bounded by that of the section's stiffness."""
    return w * w / (4 * e_min * e_min)


@pytest.mark.slow
def test_taut_stationary_state_is_the_solids():
    """Table 2, every member taut (e_min > 10 w): T(0) and the centre line of the
    tensegrity equal the solid's with EA, EI = the members' taut moduli within
    w^2 / (4 e_min^2) (8e-5 here; measured 1e-6)."""
    states, e_min = taut_states()
    assert e_min > 10 * 1e-4
    bound = regularisation_bound(e_min)
    tens, solid = states["tensegrity"][0], states["solid"][0]
    assert tens.tension[0] == pytest.approx(solid.tension[0], rel=bound)
    scale = np.max(np.linalg.norm(solid.centre_line, axis=1))
    assert np.max(np.abs(tens.centre_line - solid.centre_line)) < bound * scale


@pytest.mark.long
def test_taut_spectrum_is_the_solids():
    """Table 3's lowest modes (three per family) of the tensegrity equal the solid's
    with the taut constants within the same bound (the regularisation's error)."""
    _, e_min = taut_states()
    bound = regularisation_bound(e_min)
    tens, solid = equivalent_pair()
    spectra = {}
    for name, p in (("tensegrity", tens), ("solid", solid)):
        modes = ModalSolver.from_stationary(p, MPI.COMM_SELF).solve()
        spectra[name] = {}
        for m in modes:
            spectra[name].setdefault(m.family, []).append(abs(m.eigenvalue))
    for family in ("lateral_in_plane", "lateral_out_of_plane", "longitudinal", "torsional"):
        a = np.sort(spectra["tensegrity"][family])[:3]
        b = np.sort(spectra["solid"][family])[:3]
        assert np.allclose(a, b, rtol=bound, atol=0), (family, a, b)


# -- slack members: convergence in the slack width ----------------------------------------
WIDTHS = (1e-3, 1e-4, 1e-5, 1e-6)


@functools.lru_cache
def slack_states():
    """Table 2 at a fifth of its elongation (T ~ 66 N): the sag's curvature slackens
    the inner members over part of the rod (R kappa > eps there)."""
    out, guess = [], None
    for w in WIDTHS:
        p = table2(ends={"elongation": 0.001}, section={"law": "tensegrity", "slack_width": w})
        S = StationarySolver(p, MPI.COMM_SELF)
        res = S.solve(first_guess=guess)
        s, _, e_inner = member_strain_range(S)
        out.append((res, s, e_inner))
    return out


def onsets(s, e):
    """The s where e changes sign (linear between the nodes of the DG field)."""
    k = np.nonzero(np.sign(e[:-1]) * np.sign(e[1:]) < 0)[0]
    return s[k] - e[k] * (s[k + 1] - s[k]) / (e[k + 1] - e[k])


@pytest.mark.long
def test_slack_state_converges_in_the_width():
    """T(0) and the centre line converge as w -> 0 at an observed rate >= 1.2 in
    log10 of successive differences (the expectation w^2; measured 1.7 and 2.0 over
    w = 1e-4, 1e-5, 1e-6), and the slack onsets (where the inner member's strain
    crosses 0) converge to fixed points: their distance to the w = 1e-6 onsets falls
    with w and is below 2e-3 L0 at w = 1e-5 (measured 2.1e-2, 1.1e-2, 7e-4 L0 for
    w = 1e-3, 1e-4, 1e-5: the inner member's strain is shallow here, |e| <= 1.8e-4
    over the slack set, so a width near it moves the onset), and the slack set
    (the nodes with e < 0) is the same for w = 1e-5 and 1e-6."""
    states = slack_states()
    T = np.array([res.tension[0] for res, _, _ in states])
    X = [res.centre_line for res, _, _ in states]
    dT = np.abs(np.diff(T))
    dX = np.array([np.max(np.abs(X[i + 1] - X[i])) for i in range(len(X) - 1)])
    for d in (dT, dX):
        assert math.log10(d[1] / d[2]) > 1.2, d
    assert dX[-1] < 1e-7
    slack = [e < 0 for _, _, e in states]
    assert all(x.any() for x in slack)  # members are slack
    assert np.array_equal(slack[2], slack[3])
    last = onsets(states[-1][1], states[-1][2])
    assert len(last) == 2  # the slack set is an interval of s
    shift = []
    for _, s, e in states[:-1]:
        here = onsets(s, e)
        assert len(here) == len(last)
        shift.append(np.max(np.abs(here - last)))
    assert np.all(np.diff(shift) < 0) and shift[-1] < 2e-3, shift


# -- the saturating law --------------------------------------------------------------------
def cone_numpy(eps, kappa, A, B, rho):
    """The unregularised cone law, piecewise (parameters/section.py's "saturating"):
    W = A eps^2/2 + B kappa^2/2 where B kappa <= rho A eps; (eps + rho kappa)^2 /
    (2 (1/A + rho^2/B)) where not and eps + rho kappa > 0; 0 else."""
    if B * kappa <= rho * A * eps:
        return 0.5 * A * eps**2 + 0.5 * B * kappa**2
    g = eps + rho * kappa
    return g * g / (2 * (1 / A + rho * rho / B)) if g > 0 else 0.0


@functools.lru_cache
def saturating(width=1e-4):
    p = table2(section={"law": "saturating", "slack_width": width})
    q = p.normalised()
    return q, PointLaw(section_law.from_normalised(q))


def test_saturating_law_is_the_cone():
    """At a small width the law is the piecewise conjugate (numpy) within the smoothing's
    offset; where all taut it is the solid's quadratic; M / (N rho) -> 1 at large curvature."""
    q, law = saturating(1e-7)
    A, B, rho = q.sigma, q.mu, q.section_saturation * q.section_radius
    assert q.section_saturation == 1.0  # n = 6, even
    for eps in (-1e-3, 0.0, 1e-3, 5e-3):
        for kappa in (0.0, 0.01, 0.1, 1.0, 10.0):
            want = cone_numpy(eps, kappa, A, B, rho)
            assert law(eps, kappa)["W"] == pytest.approx(want, rel=1e-6, abs=1e-9 * A)
    taut = law(5e-3, 0.01)  # B kappa << rho A eps
    assert taut["N"] == pytest.approx(A * 5e-3, rel=1e-6)
    assert taut["M"] == pytest.approx(B * 0.01, rel=1e-6)
    ratios = [law(2e-3, k)["M"] / (law(2e-3, k)["N"] * rho) for k in (0.1, 1.0, 10.0, 100.0)]
    assert ratios[-1] == pytest.approx(1.0, abs=1e-6)
    assert np.all(np.diff(ratios) >= 0)


def test_saturating_law_is_convex():
    """The Hessian in (eps, kappa) has eigenvalues >= 0 (to round-off) at sampled strains,
    across both kinks, at the default width; and M >= 0 (convex in t' too)."""
    q, law = saturating(1e-4)
    rng = np.random.default_rng(29)
    for eps, kappa in zip(rng.uniform(-5e-3, 1e-2, 200), rng.uniform(0, 2.0, 200)):
        v = law(eps, kappa)
        H = np.array([[v["Wee"], v["Wek"]], [v["Wek"], v["Wkk"]]])
        assert np.linalg.eigvalsh(H).min() >= -1e-9 * q.sigma, (eps, kappa, H)
        assert v["M"] >= 0


def test_solid_is_the_null_object():
    """The default scene's section is the solid: its normalised fields are the null ones."""
    q = table2().normalised()
    assert isinstance(section_law.from_normalised(q), section_law.SolidSection)
    assert q.section_law == "solid" and q.section_stiffness == 0.0


def test_refuses_the_ei_law_with_a_member_law():
    with pytest.raises(ParameterError, match="section.law"):
        table2(helix={"EI_law": PAPER_EI_LAW}, section={"law": "tensegrity"})


def test_members_numpy_ramp_energy_is_the_ufl_one():
    """forms/section_law.py::ramp_energy is members.py::ramp_energy, deep in the slack too."""
    mesh = dolfinx.mesh.create_unit_interval(MPI.COMM_SELF, 1)
    e = dolfinx.fem.Constant(mesh, 0.0)
    form = dolfinx.fem.form(section_law.ramp_energy(e, 1e-4) * ufl.dx(mesh))
    for x in (-1.0, -1e-3, -1e-4, 0.0, 1e-5, 1e-2):
        e.value = x
        assert dolfinx.fem.assemble_scalar(form) == pytest.approx(float(ramp_energy(x, 1e-4)),
                                                                rel=1e-10, abs=1e-22)
