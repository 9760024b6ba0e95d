"""Finite element fields as arrays: gathered to rank 0 over the arc length, or set to a constant."""

from __future__ import annotations

import numpy as np
import dolfinx.fem

from rawehelix import compat


def gather(u: "dolfinx.fem.Function", comm=None):
    """(s, values) of a Lagrange or DG field on rank 0, sorted by s.

    ``s`` holds the dof coordinates (normalised arc length), ``values`` has
    shape (n, bs).  Other ranks get (None, None).  DG fields repeat the nodes
    shared by two cells; a stable sort keeps the left cell's value first."""
    V = u.function_space
    comm = comm or V.mesh.comm
    n_owned = V.dofmap.index_map.size_local
    bs = V.dofmap.index_map_bs
    s = V.tabulate_dof_coordinates()[:n_owned, 0]
    vals = u.x.array[: n_owned * bs].reshape(-1, bs)
    if comm.size > 1:  # (one rank: no gather, 2 x ~20 us of pickling at every output)
        s_all = comm.gather(s, root=0)
        v_all = comm.gather(vals, root=0)
        if comm.rank != 0:
            return None, None
        s = np.concatenate(s_all)
        vals = np.concatenate(v_all)
    order = np.argsort(s, kind="stable")
    return s[order], vals[order]


def interpolate_expression(ufl_expr, V) -> "dolfinx.fem.Function":
    """A Function on V interpolating a UFL expression."""
    u = dolfinx.fem.Function(V)
    u.interpolate(compat.expression(ufl_expr, V))
    return u


def set_constant(u, value):
    """u <- the constant vector ``value`` on a collapsed Lagrange vector space.

    Lagrange dofs are nodal values, so this is exact; it costs microseconds,
    where ``u.interpolate(lambda x: ...)`` costs ~0.2 ms on DOLFINx 0.5 (the
    time-dependent end condition is set at every residual evaluation)."""
    bs = u.function_space.dofmap.index_map_bs
    u.x.array.reshape(-1, bs)[:] = np.asarray(value, dtype=u.x.array.dtype)
