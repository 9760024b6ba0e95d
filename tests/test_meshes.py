"""Interval meshes: uniform and gmsh-graded nodes, meshio files, dolfinx meshes."""

import numpy as np
import pytest
import ufl
import dolfinx.fem
from mpi4py import MPI
from petsc4py import PETSc

from rawehelix import compat
from rawehelix.meshes import interval
from rawehelix.studies import scene

pytestmark = pytest.mark.mpi

CASES = [(3, 4.0), (8, 1.0), (8, 4.0), (15, 10.0), (32, 4.0)]


def _nodes(N, grading, comm=MPI.COMM_WORLD):
    return interval.graded_nodes(N, grading, comm)


@pytest.mark.parametrize("N", [1, 2, 7, 16])
def test_uniform_nodes(N):
    x = interval.uniform_nodes(N)
    assert x.shape == (N + 1,)
    np.testing.assert_allclose(np.diff(x), 1.0 / N, rtol=1e-12)
    assert x[0] == 0.0 and x[-1] == 1.0


@pytest.mark.parametrize("N, grading", CASES)
def test_graded_nodes(N, grading):
    x = _nodes(N, grading)
    h = np.diff(x)
    assert x.shape == (N + 1,)
    assert x[0] == 0.0 and x[-1] == 1.0
    assert np.all(h > 0)
    assert h.max() / h.min() == pytest.approx(grading, rel=0.1)
    np.testing.assert_allclose(x + x[::-1], 1.0, atol=1e-10)  # symmetric about 1/2
    if grading > 1:  # refined toward both ends, coarsest in the middle
        assert h[0] == pytest.approx(h.min()) and h[-1] == pytest.approx(h.min())
        assert h[(N - 1) // 2] == pytest.approx(h.max())


def test_graded_nodes_repeatable_and_same_on_all_ranks():
    comm = MPI.COMM_WORLD
    a = interval.graded_nodes(12, 5.0, comm)
    b = interval.graded_nodes(12, 5.0, comm)
    np.testing.assert_array_equal(a, b)
    everyone = comm.allgather(a)
    for other in everyone:
        np.testing.assert_array_equal(other, a)


def test_graded_nodes_bad_input():
    with pytest.raises(ValueError, match="grading"):
        interval.graded_nodes(8, 0.5)
    with pytest.raises(ValueError, match="3 elements"):
        interval.graded_nodes(2, 4.0)
    with pytest.raises(ValueError, match="elements"):
        interval.uniform_nodes(0)


@pytest.mark.parametrize("suffix", [".msh", ".xdmf"])
@pytest.mark.parametrize("N, grading", [(5, 1.0), (16, 6.0)])
def test_meshio_round_trip(tmp_path, suffix, N, grading):
    x = _nodes(N, grading)
    path = tmp_path / f"interval_rank{MPI.COMM_WORLD.rank}{suffix}"
    interval.write_meshio(path, x)
    np.testing.assert_allclose(interval.read_meshio(path), x, rtol=0, atol=1e-15)


def test_meshio_rejects_unknown_format(tmp_path):
    with pytest.raises(ValueError, match="format"):
        interval.write_meshio(tmp_path / "a.txt", interval.uniform_nodes(2))


def _global_cells_and_length(mesh):
    cells = mesh.comm.allreduce(compat.cell_count(mesh), op=MPI.SUM)
    one = dolfinx.fem.Constant(mesh, PETSc.ScalarType(1.0))
    length = mesh.comm.allreduce(
        dolfinx.fem.assemble_scalar(dolfinx.fem.form(one * ufl.dx(domain=mesh))), op=MPI.SUM)
    return cells, length


@pytest.mark.parametrize("N, grading", CASES)
def test_dolfinx_mesh(N, grading):
    mesh = interval.create(MPI.COMM_WORLD, _nodes(N, grading))
    cells, length = _global_cells_and_length(mesh)
    assert cells == N
    assert length == pytest.approx(1.0, abs=1e-12)


def test_dolfinx_mesh_keeps_the_nodes():
    """The smallest cell of the dolfinx mesh is the graded end cell."""
    x = _nodes(10, 8.0)
    mesh = interval.create(MPI.COMM_WORLD, x)
    geom = mesh.geometry.x[:, 0]
    comm = mesh.comm
    lo = comm.allreduce(geom.min() if geom.size else np.inf, op=MPI.MIN)
    hi = comm.allreduce(geom.max() if geom.size else -np.inf, op=MPI.MAX)
    assert lo == 0.0 and hi == 1.0
    # every mesh vertex is one of the nodes
    assert np.all(np.min(np.abs(geom[:, None] - x[None, :]), axis=1) < 1e-14)


@pytest.mark.parametrize("mesh_kind, N", [("uniform", 6), ("graded", 12)])
def test_mesh_from_parameters(mesh_kind, N):
    p = scene.load("stationary_table2").replace(
        discretisation={"mesh": mesh_kind, "elements": N, "grading": 3.0})
    mesh = interval.mesh_from_parameters(MPI.COMM_WORLD, p)
    cells, length = _global_cells_and_length(mesh)
    assert cells == N
    assert length == pytest.approx(1.0, abs=1e-12)
    x = interval.mesh_nodes(p, MPI.COMM_WORLD)
    h = np.diff(x)
    assert h.max() / h.min() == pytest.approx(1.0 if mesh_kind == "uniform" else 3.0, rel=1e-6)


def test_bending_length():
    q = scene.load("stationary_table2").normalised()
    l = interval.bending_length(q)
    assert l == pytest.approx(np.sqrt(q.mu / (q.sigma * q.eps0)))
    assert 0.4 < l < 0.6  # Table 2: EI = 1.28e4 N m^2, T = 200 N, L0 = 16.12 m
    assert interval.suggest_grading(q, 16) == 1.0  # elements already finer than l / 4
    stiff = q.__class__(**{**q.__dict__, "mu": q.mu * 1e-4})  # a thin boundary layer
    g = interval.suggest_grading(stiff, 16)
    assert g > 1.0
