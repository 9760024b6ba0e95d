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


def test_wind_section_uniform_reproduces_the_environment_wind_bit_for_bit():
    """[wind] speed_m_s = 10, uniform, is environment.wind_speed_m_s = 10: the same
    normalised groups and, through a stationary solve (N = 2), the same state."""
    import rawehelix as rh
    paper = rh.load_scene("stationary_table2", elements=2)
    section = rh.load_scene("stationary_table2", elements=2, overrides=UNIFORM)
    assert paper.normalised() == section.normalised()
    a, b = rh.stationary(paper), rh.stationary(section)
    assert np.array_equal(a.centre_line_m, b.centre_line_m)
    assert np.array_equal(a.tension_N, b.tension_N)


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
