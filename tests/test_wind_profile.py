"""The wind's profile in the helix's drag (forms/wind.py, issue 43): the uniform wind is
today's drag, the same UFL expression (so the same compiled forms, bit for bit); a
power or log profile's drag at a point is the closed form -nu |v_A| v_A with
v_A = v_w0 f(z) i_E at that point's height."""

from __future__ import annotations

import math

import numpy as np
import pytest
import ufl
from mpi4py import MPI

import dolfinx
import dolfinx.fem
import dolfinx.mesh

from rawehelix import compat
from rawehelix.forms import rod
from rawehelix.forms.coefficients import Coefficients
from rawehelix.forms.kinematics import I_E
from rawehelix.studies import scene

UNIFORM = {"environment.wind_speed_m_s": 0.0, "wind.speed_m_s": 10.0}


def chord(q, n=4):
    """The straight chord r(s) = (1 + eps0) s (-cos G0, 0, -sin G0) (Eq. 66; k_E points
    down) on P1: its nodes s = 0, 1/n, ..., 1."""
    mesh = dolfinx.mesh.create_interval(MPI.COMM_SELF, n, [0.0, 1.0])
    V = compat.vector_space(mesh, "Lagrange", 1)
    r = dolfinx.fem.Function(V)
    a, g = 1.0 + q.eps0, q.Gamma0
    r.interpolate(lambda x: np.vstack([-a * math.cos(g) * x[0], 0.0 * x[0],
                                       -a * math.sin(g) * x[0]]))
    return V, r


def drag_at_nodes(p):
    """F~_A of the scene at rest on its chord, at the chord's nodes: (s, F (n x 3))."""
    q = p.normalised()
    c = Coefficients.from_normalised(q, p.model)
    V, r = chord(q)
    F = dolfinx.fem.Function(V)
    F.interpolate(compat.expression(rod.aerodynamic_force(ufl.as_vector((0.0, 0.0, 0.0)), c, r), V))
    s = V.tabulate_dof_coordinates()[:, 0]
    return q, s, F.x.array.reshape(-1, 3)


def test_the_uniform_wind_is_todays_drag_expression():
    """The null object gives the drag of Eq. (14) as it was written before the wind
    component, the same UFL tree: the paper's scenes compile the same forms."""
    p = scene.load("stationary_table2")
    q = p.normalised()
    c = Coefficients.from_normalised(q, p.model)
    V, r = chord(q)
    r_t = ufl.as_vector((0.1, 0.0, 0.2))
    v_a = r_t + c.v_w0 * I_E  # today's: forms/rod.py before issue 43
    today = -c.nu * ufl.sqrt(ufl.dot(v_a, v_a) + 1e-14) * v_a
    v = ufl.TestFunction(V)

    def signature(force):  # the form's signature: what the JIT cache compiles by
        return (ufl.inner(force, v) * ufl.dx).signature()
    assert signature(rod.aerodynamic_force(r_t, c, r)) == signature(today)
    assert signature(rod.aerodynamic_force(r_t, c)) == signature(today)
    windy = scene.load("stationary_table2", overrides={**UNIFORM, "wind.profile": "power"})
    c = Coefficients.from_normalised(windy.normalised(), windy.model)
    assert signature(rod.aerodynamic_force(r_t, c, r)) != signature(today)  # it can differ
    with pytest.raises(ValueError, match="needs the centre line r"):
        rod.aerodynamic_force(r_t, c)  # a profile without the height: said, not a TypeError


def fe_state(p):
    """The FE stationary state of ``p`` (the planar model of its torque-free scene):
    (s, centre line) normalised, without the command's reference check."""
    from rawehelix.solvers.stationary import StationarySolver, reduced
    result = StationarySolver(p, MPI.COMM_SELF, planar=reduced(p)).solve()
    return result.s, result.centre_line


def test_wind_section_uniform_reproduces_the_environment_wind_bit_for_bit():
    """[wind] speed_m_s = 10, uniform, is environment.wind_speed_m_s = 10: the same
    normalised groups and, through a stationary solve (N = 2), the same state."""
    paper = scene.load("stationary_table2", elements=2)
    section = scene.load("stationary_table2", elements=2, overrides=UNIFORM)
    assert paper.normalised() == section.normalised()
    (s_a, a), (s_b, b) = fe_state(paper), fe_state(section)
    assert np.array_equal(s_a, s_b) and np.array_equal(a, b)


@pytest.mark.parametrize("profile, extra", [("power", {"wind.shear_exponent": 0.2}),
                                            ("log", {"wind.roughness_m": 0.1})])
def test_a_profiles_drag_at_a_point_is_the_closed_form(profile, extra):
    """At each node of the chord at rest, F_A = -nu sqrt(v^2 + 1e-14) v i_E with v the
    profile's speed at the node's height z = (1 + eps0) s L0 sin G0 (closed form), to
    1e-12; and the drag grows with height (the chord rises from the ground end)."""
    p = scene.load("stationary_table2", overrides={**UNIFORM, "wind.profile": profile,
                                                   "wind.reference_height_m": 5.0, **extra})
    q, s, F = drag_at_nodes(p)
    w = p.wind
    z = (1 + q.eps0) * s * p.helix.length_m * math.sin(q.Gamma0)  # [m]
    if profile == "power":
        f = (np.maximum(z, 0.01) / w.reference_height_m) ** w.shear_exponent
    else:
        f = np.log(np.maximum(z, w.roughness_m) / w.roughness_m) / math.log(
            w.reference_height_m / w.roughness_m)
    v = w.speed_m_s / math.sqrt(p.environment.g_m_s2 * p.helix.length_m) * f  # normalised
    closed = -q.nu * np.sqrt(v * v + 1e-14) * v
    assert np.allclose(F[:, 0], closed, rtol=1e-12, atol=1e-300)
    assert np.all(F[:, 1:] == 0.0)
    top = np.argmax(s)
    assert z[top] > w.reference_height_m and abs(F[top, 0]) > q.nu * q.v_w0**2  # above z_ref


def test_a_profiles_stationary_state_is_the_shooting_references():
    """A power profile (V = 10 m/s at 5 m, a = 0.2) through the stationary solve (N = 4)
    against the independent shooting of Sys. (67) with the drag -nu v(z)^2 at each
    height (references/shooting.py, operation/wind.py's numpy law): they agree to
    2.5e-5 m (uniform wind: 2.0e-5 m; N = 8: 1.8e-6 and 1.4e-6 m, the FE's own error),
    while the profile moves the FE centre line by 9.5e-4 m from the uniform wind's
    (`rawehelix stationary` compares the same in its summary)."""
    from rawehelix.references import shooting
    over = {**UNIFORM, "wind.profile": "power", "wind.reference_height_m": 5.0,
            "wind.shear_exponent": 0.2}
    p = scene.load("stationary_table2", elements=4, overrides=over)
    q = p.normalised()
    s, fe = fe_state(p)
    _, uniform = fe_state(scene.load("stationary_table2", elements=4))
    diff = q.L0 * np.linalg.norm(fe - shooting.solve(q).centre_line(s), axis=1).max()
    moved = q.L0 * np.linalg.norm(fe - uniform, axis=1).max()
    assert diff < 4e-5 and moved > 5e-4, (diff, moved)
