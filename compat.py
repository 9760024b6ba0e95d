"""Every call that differs between DOLFINx 0.5 (Debian 12) and 0.9+ (Debian 13).

Nothing else in rawehelix may test the DOLFINx version.
"""

from __future__ import annotations

import ctypes

import numpy as np

import dolfinx
import dolfinx.fem
import dolfinx.fem.petsc
import dolfinx.mesh
import ufl

VERSION = tuple(int(x) for x in dolfinx.__version__.split(".")[:2])
NEW = VERSION >= (0, 7)
# solvers/chord.py and solvers/orbits.py step TSALPHA2's scheme as PETSc 3.18 has it
# (Debian 12); PETSc 3.22's (Debian 13) departs from it by ~1e-7 a step (docs/explanation/speed.md)
ALPHA2_AS_PETSC_318 = not NEW

if NEW:
    import basix.ufl

# How long a process waits for another's JIT compilation of the same form before it
# raises TimeoutError.  DOLFINx's default, 10 s, is shorter than one compilation of
# the rod's forms on a loaded 2-core machine, so two ranks of a study (each on
# COMM_SELF) starting on a cold cache could fail where they only had to wait.
JIT_TIMEOUT_S = 600


def jit_options() -> dict:
    """DOLFINx's JIT options in force (0.5: "parameters", 0.9: "options")."""
    import dolfinx.jit
    return dolfinx.jit.get_options() if NEW else dolfinx.jit.get_parameters()


def _lengthen_jit_timeout(seconds: float):
    import dolfinx.jit
    defaults = (dolfinx.jit.DOLFINX_DEFAULT_JIT_OPTIONS if NEW
                else dolfinx.jit.DOLFINX_DEFAULT_JIT_PARAMETERS)
    if "timeout" in defaults:
        value, doc = defaults["timeout"]
        defaults["timeout"] = (max(value, seconds), doc)


_lengthen_jit_timeout(JIT_TIMEOUT_S)

# FFCx takes a form's C file, created exclusively, as the lock of its compilation,
# and its ".c.cached" as the sign that it is done.  A process killed while it
# compiles (a study stopped with SIGKILL, to be resumed) leaves the lock behind,
# and every later process would wait JIT_TIMEOUT_S for it, then fail.  A lock this
# old with no result is such a leftover (a compilation of the rod's forms takes
# under a minute on a loaded machine).
JIT_STALE_S = 180


def clear_stale_jit_locks(older_than_s: float = JIT_STALE_S) -> list:
    """Set aside (as ``.c.stale``) FFCx's locks without a result older than
    ``older_than_s`` in DOLFINx's JIT cache; returns their paths."""
    import os
    import time
    from pathlib import Path

    cache = Path(jit_options()["cache_dir"])
    now, cleared = time.time(), []
    for lock in cache.glob("libffcx_*.c") if cache.is_dir() else ():
        try:
            stale = (not lock.with_suffix(".c.cached").exists()
                     and now - lock.stat().st_mtime > older_than_s)
            if stale:
                os.replace(lock, lock.with_suffix(".c.stale"))
                cleared.append(lock)
        except FileNotFoundError:  # another process finished or cleared it meanwhile
            pass
    return cleared


clear_stale_jit_locks()


def interval_coordinate_element():
    """The P1 coordinate element of a 1D interval mesh with gdim 1."""
    if NEW:
        return ufl.Mesh(basix.ufl.element("Lagrange", "interval", 1, shape=(1,)))
    return ufl.Mesh(ufl.VectorElement("Lagrange", ufl.interval, 1, dim=1))


def create_mesh_1d(comm, cells: np.ndarray, x: np.ndarray):
    """A dolfinx mesh from vertex coordinates ``x`` (n, 1) and cells (m, 2).

    Only rank 0's arrays are used; the mesh is then partitioned."""
    domain = interval_coordinate_element()
    if comm.rank != 0:
        cells = np.empty((0, 2), dtype=np.int64)
        x = np.empty((0, 1), dtype=np.float64)
    # Interior-facet integrals (the interior-penalty terms) need the facets on
    # process boundaries ghosted: GhostMode.shared_facet (not 0.9's default).
    if NEW:
        partitioner = dolfinx.mesh.create_cell_partitioner(dolfinx.mesh.GhostMode.shared_facet)
        return dolfinx.mesh.create_mesh(comm, cells, x, domain, partitioner=partitioner)
    return dolfinx.mesh.create_mesh(comm, cells, x, domain,
                                    ghost_mode=dolfinx.mesh.GhostMode.shared_facet)


def _mixed(cell, degree: int, copies: int, curvature: bool = False, internal: bool = False):
    """``copies`` x (vector P_p with 3 components, scalar P_p) as one mixed element,
    with a third vector P_p (the curvature) after the first pair if ``curvature``,
    or a scalar DG_(p-1) (an internal variable, the space of alpha') if ``internal``."""
    if NEW:
        vec = basix.ufl.element("Lagrange", "interval", degree, shape=(3,))
        sca = basix.ufl.element("Lagrange", "interval", degree)
        dg = [basix.ufl.element("DG", "interval", degree - 1)] * internal
        return basix.ufl.mixed_element([vec, sca] + [vec] * curvature + dg
                                       + [vec, sca] * (copies - 1))
    vec = ufl.VectorElement("Lagrange", cell, degree, dim=3)
    sca = ufl.FiniteElement("Lagrange", cell, degree)
    dg = [ufl.FiniteElement("DG", cell, degree - 1)] * internal
    return ufl.MixedElement([vec, sca] + [vec] * curvature + dg + [vec, sca] * (copies - 1))


def rod_element(cell, degree: int, curvature: bool = False, internal: bool = False):
    """The mixed (r, alpha) element: vector P_p with 3 components and scalar P_p;
    (r, alpha, kappa) with a second vector P_p if ``curvature`` (forms/mixed.py);
    (r, alpha, z) with a scalar DG_(p-1) if ``internal`` (forms/hysteresis.py)."""
    return _mixed(cell, degree, 1, curvature, internal)


def function_space(mesh, element):
    if NEW:
        return dolfinx.fem.functionspace(mesh, element)
    return dolfinx.fem.FunctionSpace(mesh, element)


def scalar_space(mesh, family: str, degree: int):
    if NEW:
        return dolfinx.fem.functionspace(mesh, (family, degree))
    return dolfinx.fem.FunctionSpace(mesh, (family, degree))


def atan2(y, x):
    """UFL's two-argument arctangent (atan_2 in UFL 2022; atan2 from UFL 2023.2)."""
    # dispatch-ok: a library version probe, compat.py's one job
    return (ufl.atan2 if hasattr(ufl, "atan2") else ufl.atan_2)(y, x)


def space_degree(V) -> int:
    """The polynomial degree of a function space's element: a method of UFL's element
    (0.5), a property of basix.ufl's (0.9)."""
    degree = V.ufl_element().degree
    return degree() if callable(degree) else int(degree)


def vector_space(mesh, family: str, degree: int, dim: int = 3):
    if NEW:
        return dolfinx.fem.functionspace(mesh, (family, degree, (dim,)))
    return dolfinx.fem.VectorFunctionSpace(mesh, (family, degree), dim=dim)


def petsc_vec(u):
    """The PETSc vector behind a Function."""
    return u.x.petsc_vec if NEW else u.vector


def interpolation_points(V):
    ip = V.element.interpolation_points
    return ip() if callable(ip) else ip


def expression(ufl_expr, V):
    """A dolfinx Expression evaluated at the interpolation points of ``V``."""
    return dolfinx.fem.Expression(ufl_expr, interpolation_points(V))


def interpolate_expression(u, expr, cells):
    """u <- an Expression made at u's interpolation points, on ``cells`` (int32): the
    C++ call of Function.interpolate (0.5's Python wrapper registers four
    singledispatch functions a call: ~15 us of an output's 30)."""
    if NEW:
        u.interpolate(expr, cells)
    else:
        u._cpp_object.interpolate(expr._cpp_object, cells)


def eval_expression(expr, mesh, cells, values=None):
    """An Expression's values at its points on ``cells`` (into ``values`` if given)."""
    if NEW:
        out = expr.eval(mesh, cells)
        if values is not None:
            values[...] = out.reshape(values.shape)
            return values
        return out
    return expr.eval(cells, values)


def create_vector(form):
    if NEW:
        try:
            return dolfinx.fem.petsc.create_vector(form)
        except TypeError:  # 0.10 takes a list of spaces
            return dolfinx.fem.petsc.create_vector(form.function_spaces)
    return dolfinx.fem.petsc.create_vector(form)


def create_matrix(form):
    return dolfinx.fem.petsc.create_matrix(form)


def locate_boundary_vertices(mesh, marker):
    return dolfinx.mesh.locate_entities_boundary(mesh, 0, marker)


def locate_all_dofs(mesh, spaces):
    """Every dof of ``spaces`` ((W.sub(i), V_collapsed)) on this rank's cells and
    ghosts.  DOLFINx 0.9 needs the cell-to-cell connectivity for this."""
    tdim = mesh.topology.dim
    mesh.topology.create_connectivity(tdim, tdim)
    cells = mesh.topology.index_map(tdim)
    every = np.arange(cells.size_local + cells.num_ghosts, dtype=np.int32)
    return dolfinx.fem.locate_dofs_topological(spaces, tdim, every)


def cell_count(mesh) -> int:
    """Number of cells owned by this rank."""
    return mesh.topology.index_map(mesh.topology.dim).size_local



def apply_lifting_and_bc(b, J_form, bcs, x, scale: float = -1.0):
    """b <- b - scale*A(x - g) lifting, ghost accumulation, then the bc rows of a
    Newton residual: b_bc = scale*(g - x) (positional arguments: 0.5 calls the
    factor ``scale``, 0.9 ``alpha``)."""
    from petsc4py import PETSc
    dolfinx.fem.petsc.apply_lifting(b, [J_form], [bcs], [x], scale)
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    dolfinx.fem.petsc.set_bc(b, bcs, x, scale)


def collapse(V_sub):
    """(collapsed space, map to parent dofs)."""
    out = V_sub.collapse()
    return out if isinstance(out, tuple) else (out, None)



def shearable_element(cell, degree: int):
    """The shearable rod's (r, alpha, n) element: vector P_p, scalar P_p and the
    director n, vector P_(p-1) (forms/shearable.py)."""
    if NEW:
        vec = basix.ufl.element("Lagrange", "interval", degree, shape=(3,))
        sca = basix.ufl.element("Lagrange", "interval", degree)
        low = basix.ufl.element("Lagrange", "interval", degree - 1, shape=(3,))
        return basix.ufl.mixed_element([vec, sca, low])
    return ufl.MixedElement([ufl.VectorElement("Lagrange", cell, degree, dim=3),
                             ufl.FiniteElement("Lagrange", cell, degree),
                             ufl.VectorElement("Lagrange", cell, degree - 1, dim=3)])


def rod_pair_element(cell, degree: int):
    """The first-order (r, alpha, r_t, alpha_t) element: two copies of :func:`rod_element`'s
    fields, flattened into one mixed element of four sub-elements."""
    return _mixed(cell, degree, 2)


def vertex_tags(mesh, vertices, value: int = 1):
    """Meshtags marking the given (sorted) vertices, dim 0, for dS/ds subdomains."""
    vertices = np.asarray(vertices, dtype=np.int32)
    return dolfinx.mesh.meshtags(mesh, 0, vertices, np.full(len(vertices), value, dtype=np.int32))


def assemble_vector_array(b: np.ndarray, form) -> np.ndarray:
    """b <- the form's cell and facet integrals, assembled into a numpy array (this
    rank's owned and ghost entries, no ghost accumulation): the fast path of a
    serial step loop, without a PETSc Vec (0.5 to 0.9 dispatch on np.ndarray)."""
    b[:] = 0.0
    dolfinx.fem.assemble_vector(b, form)
    return b


def petsc_option_used(name: str) -> bool:
    """Whether anything has read the option ``name`` (without '-') of PETSc's
    database: petsc4py 3.18 has no call for it, so PetscOptionsUsed of the
    libpetsc already loaded (ctypes), or ``Options.used`` where petsc4py has it."""
    from petsc4py import PETSc
    if hasattr(PETSc.Options, "used"):  # dispatch-ok: a library version probe (compat.py)
        return bool(PETSc.Options().used(name))
    flag = ctypes.c_int()
    err = _libpetsc().PetscOptionsUsed(None, name.encode(), ctypes.byref(flag))
    if err:
        raise RuntimeError(f"PetscOptionsUsed({name!r}) returned error {err}")
    return bool(flag.value)


def _libpetsc():
    """The libpetsc this process has loaded (petsc4py's), its C calls by ctypes."""
    global _LIBPETSC
    if _LIBPETSC is None:
        with open("/proc/self/maps") as maps:
            paths = {ln.split()[-1] for ln in maps if "/libpetsc" in ln and ".so" in ln}
        if len(paths) != 1:
            raise RuntimeError(f"cannot tell which libpetsc is loaded: {sorted(paths)}")
        _LIBPETSC = ctypes.CDLL(paths.pop())
    return _LIBPETSC


_LIBPETSC = None
