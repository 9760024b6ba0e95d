"""Interval meshes of the normalised arc length s~ in [0, 1] (Eq. 25).

Uniform nodes as in the paper (s_j = j/N, Sec. 3), or nodes graded toward
both ends with gmsh, where the bending boundary layers of width
sqrt(mu / (sigma eps0)) sit (the ends are pinned with zero curvature,
Eq. 37).  Meshes can be written and read with meshio, and turned into a
dolfinx mesh through :mod:`rawehelix.compat` (no DOLFINx call here).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from rawehelix.parameters import Normalised, Parameters
from rawehelix.errors import SceneError

__all__ = ["uniform_nodes", "graded_nodes", "bending_length", "suggest_grading",
           "write_meshio", "read_meshio", "create", "mesh_nodes", "mesh_from_parameters"]


# -- nodes ------------------------------------------------------------------------

def _check_elements(N) -> int:
    if int(N) != N or N < 1:
        raise ValueError(f"the number of elements must be an integer >= 1, got {N!r}")
    return int(N)


def uniform_nodes(N: int) -> np.ndarray:
    """The N + 1 nodes s~_j = j / N on [0, 1] (Sec. 3)."""
    N = _check_elements(N)
    return np.linspace(0.0, 1.0, N + 1)


def _ratio(x: np.ndarray) -> float:
    """Signed log grading: log(h_max / h_min), > 0 when the ends are finer."""
    h = np.diff(x)
    sign = 1.0 if h[len(h) // 2] >= h[0] else -1.0
    return sign * math.log(h.max() / h.min())


class _Gmsh:
    """One gmsh session (own, or a new model in a caller's session)."""

    def __enter__(self):
        import gmsh  # system gmsh (Debian python3-gmsh); imported on use only
        self.gmsh = gmsh
        is_init = getattr(gmsh, "isInitialized", None)  # not in gmsh 4.8
        self.own = not (is_init is not None and is_init())
        if self.own:
            gmsh.initialize()
        else:
            self.previous = gmsh.model.getCurrent()
        gmsh.option.setNumber("General.Terminal", 0)
        return self

    def nodes(self, N: int, coef: float) -> np.ndarray:
        """Sorted node coordinates of [0, 1] with a transfinite Bump law."""
        gmsh = self.gmsh
        gmsh.model.add("rawehelix_interval")
        try:
            p0 = gmsh.model.geo.addPoint(0.0, 0.0, 0.0)
            p1 = gmsh.model.geo.addPoint(1.0, 0.0, 0.0)
            line = gmsh.model.geo.addLine(p0, p1)
            gmsh.model.geo.mesh.setTransfiniteCurve(line, N + 1, "Bump", coef)
            gmsh.model.geo.synchronize()
            gmsh.model.mesh.generate(1)
            _, coords, _ = gmsh.model.mesh.getNodes()
        finally:
            gmsh.model.remove()
        x = np.sort(np.asarray(coords).reshape(-1, 3)[:, 0])
        if x.size != N + 1:
            raise RuntimeError(f"gmsh made {x.size - 1} elements instead of {N}")
        return x

    def __exit__(self, *exc):
        if self.own:
            self.gmsh.finalize()
        else:
            self.gmsh.model.setCurrent(self.previous)
        return False


class GradingError(ValueError):
    """A grading that gmsh cannot give N elements (its reach depends on N)."""


def _graded_nodes_serial(N: int, grading: float) -> np.ndarray:
    from scipy.optimize import brentq

    target = math.log(grading)
    with _Gmsh() as g:
        # The meaning of the Bump coefficient has changed between gmsh versions,
        # so it is calibrated: find the side of 1 that refines toward the ends,
        # then bracket and solve  log(h_max / h_min) = log(grading).
        def mismatch(log_c):
            return _ratio(g.nodes(N, math.exp(log_c))) - target

        side = -1.0 if _ratio(g.nodes(N, 0.5)) > 0 else 1.0
        far = side * 0.5
        while mismatch(far) < 0:
            far *= 2.0
            if abs(far) > 60:
                raise GradingError(f"gmsh cannot grade {N} elements by {grading:g}: "
                                   "use a smaller grading or more elements")
        lo, hi = sorted((0.0, far))
        log_c = brentq(mismatch, lo, hi, xtol=1e-12, rtol=1e-12)
        x = g.nodes(N, math.exp(log_c))
    x[0], x[-1] = 0.0, 1.0
    return x


def graded_nodes(N: int, grading: float, comm=None) -> np.ndarray:
    """N + 1 nodes on [0, 1], refined symmetrically toward both ends (gmsh).

    Parameters
    ----------
    N : int
        Number of elements (exactly N are made).
    grading : float
        Ratio of the largest (middle) to the smallest (end) element, >= 1;
        1 gives the uniform nodes.  Needs N >= 3 when > 1.
    comm : mpi4py communicator, optional
        gmsh runs on rank 0 only and the nodes are broadcast.

    Returns
    -------
    numpy.ndarray
        The sorted nodes, s~ normalised by L0.
    """
    N = _check_elements(N)
    if not (grading >= 1 and math.isfinite(grading)):
        raise ValueError(f"grading must be a finite number >= 1, got {grading!r}")
    if grading == 1:
        return uniform_nodes(N)
    if N < 3:
        raise ValueError(f"a symmetric grading needs at least 3 elements, got N = {N}")
    if comm is None or comm.size == 1:
        return _graded_nodes_serial(N, grading)
    result = None
    if comm.rank == 0:
        try:
            result = _graded_nodes_serial(N, grading)
        except Exception as err:  # every rank must learn of it, or they hang
            result = err
    result = comm.bcast(result, root=0)
    if isinstance(result, Exception):
        raise result
    return result


# -- the bending boundary layer ---------------------------------------------------

def bending_length(normalised: Normalised) -> float:
    """sqrt(mu / (sigma eps0)): the bending boundary layer over L0.

    Near a pinned end (Eq. 37) the linearised Eq. (30), mu w'''' = T w'' + q,
    has the homogeneous solutions exp(+-s~/l) with l = sqrt(mu / T) and
    T = sigma eps0 the chord tension (Eq. 29)."""
    return math.sqrt(normalised.mu / normalised.chord_tension())


def suggest_grading(normalised: Normalised, N: int, per_layer: int = 4) -> float:
    """A grading that puts about ``per_layer`` end elements across one bending
    length, never coarser than uniform; capped at 100."""
    N = _check_elements(N)
    h_end = bending_length(normalised) / per_layer
    if h_end >= 1.0 / N or N < 3:
        return 1.0
    # geometric grading of one half: h_end (r^(n) - 1)/(r - 1) = 1/2, n = N/2 elements
    from scipy.optimize import brentq
    n = N / 2.0
    if h_end * n >= 0.5:
        return 1.0
    r = brentq(lambda r: h_end * (r**n - 1.0) / (r - 1.0) - 0.5, 1.0 + 1e-12, 10.0)
    return float(min(r ** (n - 1.0), 100.0))


# -- files ------------------------------------------------------------------------

# suffix -> (meshio writer, meshio reader); .msh is written as gmsh 2.2 ASCII
_FORMATS = {".msh": ("gmsh22", "gmsh"), ".xdmf": ("xdmf", "xdmf"),
            ".vtu": ("vtu", "vtu"), ".vtk": ("vtk", "vtk")}


def _format(path: Path, read: bool = False) -> str:
    try:
        return _FORMATS[path.suffix.lower()][int(read)]
    except KeyError:
        raise ValueError(f"{path}: unknown mesh format; use one of {', '.join(_FORMATS)}") from None


def write_meshio(path, nodes: np.ndarray) -> Path:
    """Write the nodes as a line mesh (points padded to 3D, s~ along x)."""
    import meshio

    path = Path(path)
    nodes = np.asarray(nodes, dtype=float)
    points = np.zeros((nodes.size, 3))
    points[:, 0] = nodes
    cells = np.column_stack([np.arange(nodes.size - 1), np.arange(1, nodes.size)])
    fmt = _format(path)
    if fmt == "gmsh22":  # gmsh wants physical and geometrical tags
        tags = np.ones(len(cells), dtype=int)
        mesh = meshio.Mesh(points, [("line", cells)],
                           cell_data={"gmsh:physical": [tags], "gmsh:geometrical": [tags]})
        meshio.write(path, mesh, file_format=fmt, binary=False)
    else:
        meshio.write(path, meshio.Mesh(points, [("line", cells)]), file_format=fmt)
    return path


def read_meshio(path) -> np.ndarray:
    """The sorted nodes of a line mesh written by :func:`write_meshio` (or any
    chain of line cells along x)."""
    import meshio

    path = Path(path)
    mesh = meshio.read(path, file_format=_format(path, read=True))
    x = np.asarray(mesh.points, dtype=float)[:, 0]
    lines = [c.data for c in mesh.cells if c.type == "line"]
    if not lines:
        raise ValueError(f"{path}: no line cells")
    cells = np.concatenate(lines)
    order = np.argsort(x)
    rank = np.empty_like(order)
    rank[order] = np.arange(order.size)  # node index -> position along s
    joined = np.sort(rank[cells], axis=1)
    joined = joined[np.argsort(joined[:, 0])]
    chain = np.column_stack([np.arange(x.size - 1), np.arange(1, x.size)])
    if joined.shape != chain.shape or not np.array_equal(joined, chain):
        raise ValueError(f"{path}: the line cells do not join consecutive nodes")
    return x[order]


# -- dolfinx ----------------------------------------------------------------------

def create(comm, nodes: np.ndarray):
    """A dolfinx interval mesh (gdim 1) through the nodes; rank 0's nodes are
    used and the mesh is partitioned over ``comm``."""
    from rawehelix import compat

    nodes = np.asarray(nodes, dtype=np.float64)
    if nodes.ndim != 1 or nodes.size < 2 or np.any(np.diff(nodes) <= 0):
        raise ValueError("nodes must be a strictly increasing 1D array of >= 2 values")
    n = nodes.size
    cells = np.column_stack([np.arange(n - 1), np.arange(1, n)]).astype(np.int64)
    return compat.create_mesh_1d(comm, cells, nodes.reshape(n, 1))


def mesh_nodes(params: Parameters, comm=None) -> np.ndarray:
    """The nodes asked for by ``params.discretisation`` (mesh, elements, grading)."""
    disc = params.discretisation
    if disc.mesh == "uniform":
        return uniform_nodes(disc.elements)
    if disc.mesh == "graded":
        try:
            return graded_nodes(disc.elements, disc.grading, comm)
        except GradingError as err:  # bad input, known only once N is: exit 2, one line
            raise SceneError(params.name, "discretisation.grading", str(err)) from None
    raise ValueError(f"discretisation.mesh = {disc.mesh!r}: must be 'uniform' or 'graded'")


def mesh_from_parameters(comm, params: Parameters):
    """The dolfinx mesh of ``params.discretisation``."""
    return create(comm, mesh_nodes(params, comm))
