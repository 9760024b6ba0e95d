"""Rung 1 of the verification ladder: FE derivatives of analytic fields converge.

The cellwise k-th derivative of the degree-p Lagrange interpolant of a smooth
field converges in L2 at the rate p + 1 - k (Ciarlet, The Finite Element
Method for Elliptic Problems, Thm. 3.1.6).  Degree 2 has no third derivative.
"""

import numpy as np
import pytest
import ufl
import dolfinx.fem
from mpi4py import MPI

from rawehelix import compat
from rawehelix.forms.kinematics import d
from rawehelix.meshes import interval

ELEMENTS = (8, 16, 32)


def analytic(x):
    """A smooth 3-vector field along s and its UFL form."""
    return ufl.as_vector((ufl.sin(np.pi * x[0]), ufl.cos(2 * x[0]), x[0] ** 3 * ufl.exp(x[0])))


def derivative_errors(N: int, p: int) -> list[float]:
    mesh = interval.create(MPI.COMM_WORLD, interval.uniform_nodes(N))
    V = compat.vector_space(mesh, "Lagrange", p, 3)
    x = ufl.SpatialCoordinate(mesh)
    f = analytic(x)
    u = dolfinx.fem.Function(V)
    u.interpolate(compat.expression(f, V))
    dx = ufl.dx(domain=mesh, metadata={"quadrature_degree": 2 * p + 8})
    errors = []
    for k in (1, 2, 3):
        e = dolfinx.fem.form(ufl.inner(d(u, k) - d(f, k), d(u, k) - d(f, k)) * dx)
        errors.append(np.sqrt(mesh.comm.allreduce(dolfinx.fem.assemble_scalar(e), op=MPI.SUM)))
    return errors


@pytest.mark.parametrize("p", (2, 3, 4))
@pytest.mark.parametrize("k", (1, 2, 3))
def test_derivative_rates(p, k):
    if k > p - 0 and k == 3 and p == 2:
        pytest.skip("degree 2 elements have no third derivative")
    errors = np.array([derivative_errors(N, p)[k - 1] for N in ELEMENTS])
    rates = np.log2(errors[:-1] / errors[1:])
    expected = p + 1 - k
    assert np.all(rates > expected - 0.15), (rates, expected)
    assert np.all(rates < expected + 0.6), (rates, expected)
