"""helix.EI_law (EI = a T + b at the local tension, forms/extensible.py) against
the shooting reference and the closed-form modes.

Normalised (Eqs. 25-29): mu(eps) = mu_a sigma eps + mu_b, mu_a = a / L0^2,
mu_b = b / (M g L0^2).  The law of the paper, Eq. (64): a = 52.4 Nm^2/N,
b = 2290 Nm^2.

* The stationary state of Table 2 is checked against the shooting of the
  planar extensible elastica with the same law (solvers/shooting.py::
  solve_extensible, scipy only, no FE code), whose axial force is
  N.t = T + 1/2 mu_a sigma kappa^2.
* The modes are checked against the string-beam of tests/test_extensible.py,
  omega_n^2 = (T/lambda) k^2 + (mu(T)/lambda^2) k^4 with mu at the mean
  tension (docs/physics.md says what that neglects).
"""

import functools
import math

import numpy as np
import pytest
import ufl
import dolfinx.fem
from mpi4py import MPI

from rawehelix.forms import energy, extensible
from rawehelix.forms.kinematics import d
from rawehelix.parameters import EILaw, ParameterError
from rawehelix.solvers import shooting
from rawehelix.solvers.discrete import RodDiscretisation
from rawehelix.solvers.stationary import StationarySolver
from rawehelix.studies import scene

EQ64 = {"a_Nm2_per_N": 52.4, "b_Nm2": 2290.0}  # Eq. (64)
P = 3


def table2(N=8, law=EQ64, **model):
    return scene.load("stationary_table2", elements=N, degree=P).replace(
        model={"kinematics": "extensible", **model}, helix={"EI_law": law})


# -- parameters --------------------------------------------------------------------

def test_law_parameters_and_normalisation():
    """The law becomes mu = mu_a T~ + mu_b at the normalised tension; EI_Nm2 keeps
    the torsional inertia (delta) and mu; the scene file's inline table is read."""
    p = table2()
    q, h = p.normalised(), p.helix
    assert isinstance(h.EI_law, EILaw) and q.bending_law
    T_N = 200.0
    mu_of_T = q.mu_per_tension * T_N / q.force_scale + q.mu_at_zero_tension
    assert mu_of_T == pytest.approx(h.EI_law.EI_Nm2(T_N) / (h.mass_kg * 9.81 * h.length_m**2),
                                    rel=1e-14)
    assert h.EI_law.EI_Nm2(T_N) == pytest.approx(12770.0)
    default = table2(law=None)
    assert q.delta == default.normalised().delta and q.mu == default.normalised().mu
    assert "EI law: EI = 52.4 Nm^2/N x T + 2290 Nm^2" in p.describe_model()


def test_default_is_off_and_fingerprints_unchanged():
    p = scene.load("stationary_table2")
    assert p.helix.EI_law is None and not p.normalised().bending_law
    assert "EI_law" not in p.as_dict()["helix"]
    assert p.describe_model() == p.model.describe()
    assert table2().as_dict()["helix"]["EI_law"] == EQ64


def test_scene_file(tmp_path):
    text = scene.resolve("stationary_table2").read_text()
    text = text.replace("[helix]", "[helix]\nEI_law = {a_Nm2_per_N = 52.4, b_Nm2 = 2290}", 1)
    path = tmp_path / "law.toml"
    path.write_text(text + '\n[model]\nkinematics = "extensible"\n')
    assert scene.load(path).helix.EI_law == EILaw(**EQ64)
    path.write_text(text)  # the paper's kinematics: refused, the key named
    with pytest.raises(scene.SceneError, match="helix.EI_law.*extensible"):
        scene.load(path)
    path.write_text(text.replace("b_Nm2 = 2290", "b_Nm2 = -1") + '\n[model]\nkinematics = "extensible"\n')
    with pytest.raises(scene.SceneError, match="helix.EI_law.b_Nm2"):
        scene.load(path)


@pytest.mark.parametrize("law, key", [
    ({"a_Nm2_per_N": -1.0, "b_Nm2": 2290.0}, "helix.EI_law.a_Nm2_per_N"),
    ({"a_Nm2_per_N": 52.4, "b_Nm2": 0.0}, "helix.EI_law.b_Nm2"),
    ({"a_Nm2_per_N": float("nan"), "b_Nm2": 1.0}, "helix.EI_law.a_Nm2_per_N"),
    ({"a_Nm2_per_N": 52.4}, "helix.EI_law"),
    ({"a_Nm2_per_N": 52.4, "b_Nm2": 1.0, "c": 2.0}, "helix.EI_law"),
    ({"a_Nm2_per_N": "52.4", "b_Nm2": 1.0}, "helix.EI_law.a_Nm2_per_N"),
    (52.4, "helix.EI_law"),
])
def test_bad_values_refused(law, key):
    with pytest.raises(ParameterError) as err:
        table2(law=law)
    assert err.value.key == key


@pytest.mark.parametrize("sections", [
    {"model": {"kinematics": "paper"}},
    {"discretisation": {"scheme": "spline"}},
    {"discretisation": {"bending": "mixed"}},
])
def test_refused_combinations(sections):
    with pytest.raises(ParameterError, match="helix.EI_law|model.kinematics"):
        table2().replace(**sections)


# -- the stationary state ------------------------------------------------------------

@functools.lru_cache
def reference(law=True):
    return shooting.solve_extensible(table2(law=EQ64 if law else None).normalised())


def stationary_errors(N):
    """(max position error, max tension error / T(0)) of the FE state at N elements."""
    ref = reference()
    res = StationarySolver(table2(N), MPI.COMM_SELF).solve()
    position = np.max(np.linalg.norm(res.centre_line - ref.centre_line(res.s), axis=1))
    tension = np.max(np.abs(res.tension - ref.tension(res.s_tension))) / ref.tension(0.0)[0]
    return position, tension


def test_stationary_state_against_shooting():
    """Table 2 with the law of Eq. (64): the FE centre line approaches the
    shooting solution like h^3.8 (measured 1.24e-6, 8.75e-8 at N = 4, 8) and the
    tension T = sigma eps like h^2 (5.8e-4, 1.45e-4 of T(0)): T = N.t - 1/2 mu_a
    sigma kappa^2 carries the error of kappa = |t'|, O(h^2) for cubics.  Both are
    far below the law's own effect on the state (the references with and
    without the law differ by 3.7e-3 of T at mid-span)."""
    (e4, t4), (e8, t8) = stationary_errors(4), stationary_errors(8)
    assert math.log2(e4 / e8) > 3.5, (e4, e8)
    assert math.log2(t4 / t8) > 1.8, (t4, t8)
    assert e8 < 2e-7 and t8 < 3e-4, (e8, t8)
    law, none = reference(True), reference(False)
    s = np.linspace(0.0, 1.0, 21)
    effect = np.max(np.abs(law.tension(s) - none.tension(s))) / law.tension(0.0)[0]
    assert effect > 10 * t8, (effect, t8)
    # the consistent axial force: N.t - T = 1/2 mu_a sigma kappa^2 > 0 where the rod bends
    q = law.normalised
    gap = law.axial_force(0.5)[0] - law.tension(0.5)[0]
    assert gap == pytest.approx(0.5 * q.mu_per_tension * q.sigma * law.curvature(0.5)[0]**2,
                                rel=1e-12)
    assert gap > 20 * t8 * law.tension(0.0)[0]


def test_residual_is_the_variation_of_the_energy():
    """F(w; v) = d/dh U(w + h v) with the law (bent, stretched state, no drag):
    central differences of forms/energy.py's potential agree to 1e-7 relative
    (measured 2e-9).  The consistent axial term int 1/2 mu_a sigma kappa^2 t.v'
    is 6 % of F here, so a residual without it would miss by 3e5 times the
    tolerance; the law-free residual differs by 9 %."""
    values = {}
    for law in (EQ64, None):
        params = table2(N=4, law=law, drag=False)
        rod = RodDiscretisation(params, MPI.COMM_SELF)
        rod.set_centre_line(lambda s: np.column_stack([-0.8 * s + 0.05 * np.sin(3 * s),
                                                       0.03 * s**2 * (1 - s), -0.75 * s]))
        direction = dolfinx.fem.Function(rod.W)
        direction.sub(0).interpolate(lambda x: np.vstack([np.sin(2 * x[0]), x[0]**2,
                                                          np.cos(x[0])]))
        F = dolfinx.fem.form(ufl.replace(rod.stationary_residual(), {rod.test: direction}))
        r, alpha = ufl.split(rod.w)[:2]
        U = dolfinx.fem.form(energy.potential(r, alpha, rod.c, rod.degree, rod.penalty,
                                              rod.measures))
        t = extensible.unit_tangent(r)
        dx = rod.measures[0]
        axial = dolfinx.fem.form(0.5 * rod.c.mu_a * rod.c.sigma * ufl.dot(d(t), d(t))
                                 * ufl.dot(t, d(ufl.split(direction)[0])) * dx)
        w0 = rod.w.x.array.copy()
        h, u = 1e-5, []
        for sign in (1, -1):
            rod.w.x.array[:] = w0 + sign * h * direction.x.array
            u.append(dolfinx.fem.assemble_scalar(U))
        rod.w.x.array[:] = w0
        values[law is None] = (dolfinx.fem.assemble_scalar(F), (u[0] - u[1]) / (2 * h),
                               dolfinx.fem.assemble_scalar(axial))
    F_law, dU_law, axial_term = values[False]
    print(f"\nF {F_law:.10e}, dU {dU_law:.10e}, axial term {axial_term:.3e}, "
          f"law-free F {values[True][0]:.6e}")
    assert F_law == pytest.approx(dU_law, rel=1e-7)
    assert abs(axial_term) > 1e-4 * abs(F_law)
    assert abs(values[True][0] / F_law - 1) > 1e-2
