"""What a dynamic run records: point values at s = 0, ~1/2, 1 and fields along s.

Point values are scalar forms on the end points (ds, weighted by 1 - s or s)
and on the vertex nearest the middle (dS), so they are exact point
evaluations and need no search for the owning rank: assemble, then sum over
ranks.  All of them at once (:meth:`Probes.values`, every output of simulate)
are one Expression evaluated at the cells' ends (:class:`PointValues`): the same
numbers, 10 forms' assembly (94 us at N = 8) replaced by one evaluation (5 us).
"""

from __future__ import annotations

import numpy as np
import ufl
from mpi4py import MPI

import dolfinx.fem
from petsc4py import PETSc

from rawehelix import compat
from rawehelix.models import rod_model
from rawehelix.solvers import fields as fe_fields


def all_cells(mesh) -> np.ndarray:
    """This rank's cells, ghosts too (what Function.interpolate runs on)."""
    cells = mesh.topology.index_map(mesh.topology.dim)
    return np.arange(cells.size_local + cells.num_ghosts, dtype=np.int32)


def middle_vertex(mesh) -> tuple[float, np.ndarray]:
    """(s, local vertex indices) of the mesh vertex nearest s = 1/2 (normalised)."""
    x = mesh.geometry.x[:, 0]
    local = x[np.argmin(np.abs(x - 0.5))] if len(x) else np.inf
    candidates = mesh.comm.allgather(local)
    s_mid = float(min(candidates, key=lambda v: abs(v - 0.5)))
    vertices = dolfinx.mesh.locate_entities(mesh, 0, lambda y: np.isclose(y[0], s_mid))
    return s_mid, vertices


class SectionProbe:
    """The section's state along s for the limits block (studies/analysis/structure_limits.py):
    the one list of its fields, as UFL of a model's fields by role (models/), at the
    Lagrange nodes of the scalar space ``V_s``; the fields are one vector-valued
    expression (one interpolation and one gather per call: simulate calls it at every
    output step).  A DynamicsSolver's :class:`Probes` and the stationary solver
    (:meth:`of_rod`) both read it."""

    def __init__(self, model, by_role: dict, c, V_s):
        r = by_role["centre_line"]
        mesh = V_s.mesh
        self.comm = mesh.comm
        fields = {
            "strain": model.strain(by_role, c),  # eps = |r'| - 1 (Gamma_3: shearable)
            "curvature": model.curvature(by_role, c),
            "bending_moment": model.bending_moment(by_role, c),
            "torque": model.moment(by_role, c),  # / (GJ / L0)
            "tension": model.tension(by_role, c),  # (29)
            "twist": model.twist(by_role, c),  # (34)
            "ring_phase": model.ring_phase(by_role, c),  # psi (members.py; 0: the worst phase)
        }
        self.names = tuple(fields)
        V = compat.vector_space(mesh, "Lagrange", compat.space_degree(V_s), len(fields))
        self._expr = compat.expression(ufl.as_vector(list(fields.values())), V)
        self._u = dolfinx.fem.Function(V)
        self._cells = all_cells(mesh)

    @classmethod
    def of_rod(cls, rod):
        """The probe of a stationary solver's rod (solvers/stationary.py): the full
        rod's fields, or the planar rod's (x, z) with alpha = 0 (solvers/planar.py)."""
        if not rod.planar:
            return cls(rod.model, rod.model.split(rod.w), rod.c, rod.V_a)
        from rawehelix.solvers.planar import embed
        mesh = rod.mesh
        zero = dolfinx.fem.Constant(mesh, PETSc.ScalarType(0.0))
        by_role = {"centre_line": embed(rod.w), "twist": zero, "curvature": None,
                   "internal_twist": None}
        return cls(rod_model(rod.params), by_role, rod.c,
                   compat.scalar_space(mesh, "Lagrange", rod.degree))

    def section(self) -> dict | None:
        """The section's state along s (normalised, at the Lagrange nodes of ``V_s``,
        sorted by s): s and the fields by name; rank 0 (None elsewhere).  Collective."""
        compat.interpolate_expression(self._u, self._expr, self._cells)
        s, vals = fe_fields.gather(self._u)
        if s is None:
            return None
        return {"s": s, **{name: vals[:, k] for k, name in enumerate(self.names)}}


def _end_cells(mesh, s_point: float) -> list:
    """[(owned cell, reference end 0 or 1)] of the cells meeting at the vertex at
    ``s_point``, each with the weight 1 / (cells meeting there): the dS average
    at an interior vertex, the value at an end."""
    tdim = mesh.topology.dim
    mesh.topology.create_connectivity(0, tdim)
    v2c = mesh.topology.connectivity(0, tdim)
    owned = mesh.topology.index_map(tdim).size_local
    x, gdofs = mesh.geometry.x[:, 0], mesh.geometry.dofmap
    out = []
    for v in dolfinx.mesh.locate_entities(mesh, 0, lambda y: np.isclose(y[0], s_point)):
        cells = v2c.links(v)
        for c in cells[cells < owned]:
            end = int(np.argmin(np.abs(x[gdofs.links(c)[:2]] - s_point)))
            out.append((int(c), end, 1.0 / len(cells)))
    return out


class PointValues:
    """Scalars at points of s (the ends, the middle vertex) by one vector Expression
    at both ends of the cells that meet there (its reference points X = 0, 1),
    summed over ranks: ``{name: (UFL scalar, s)}``."""

    def __init__(self, mesh, quantities: dict):
        self.comm, self._mesh = mesh.comm, mesh
        exprs = []
        for e, _ in quantities.values():
            if not any(e is f for f in exprs):
                exprs.append(e)
        self._expr = dolfinx.fem.Expression(ufl.as_vector(exprs), np.array([[0.0], [1.0]]))
        at = {s_point: _end_cells(mesh, s_point) for _, s_point in quantities.values()}
        self._cells = np.unique([c for v in at.values() for c, _, _ in v]).astype(np.int32)
        row = {int(c): k for k, c in enumerate(self._cells)}
        m = len(exprs)
        # value k = sum of weight * E[cell row, end, component] over its entries
        self._index, self._owner, self._weight = [], [], []
        for k, (e, s_point) in enumerate(quantities.values()):
            comp = next(j for j, f in enumerate(exprs) if f is e)
            for c, end, w in at[s_point]:
                self._index.append((row[c] * 2 + end) * m + comp)
                self._owner.append(k)
                self._weight.append(w)
        self._index, self._owner = np.array(self._index, int), np.array(self._owner, int)
        self._weight = np.array(self._weight)
        self.names = tuple(quantities)
        self._values = np.empty((self._cells.size, 2 * m))

    def __call__(self) -> dict:
        """The values by name (collective; every rank gets them)."""
        local = np.zeros(len(self.names))
        if self._cells.size:
            flat = compat.eval_expression(self._expr, self._mesh, self._cells,
                                          self._values).reshape(-1)
            local = np.bincount(self._owner, self._weight * flat[self._index],
                                minlength=len(self.names))
        if self.comm.size > 1:
            local = self.comm.allreduce(local, op=MPI.SUM)
        return dict(zip(self.names, local.tolist()))


class Probes:
    """Scalar forms for the time series and interpolations for the fields."""

    def __init__(self, formulation):
        rod = formulation.rod
        mesh, c, model = rod.mesh, rod.c, rod.model
        by_role, rates = formulation.fields.roles()  # the model's fields and observables by role
        r, alpha = by_role["centre_line"], by_role["twist"]
        r_t, alpha_t = rates["centre_line"], rates["twist"]
        self.comm = mesh.comm
        s = ufl.SpatialCoordinate(mesh)[0]
        ds = ufl.ds(domain=mesh)
        self.s_mid, vertices = middle_vertex(mesh)
        dS_mid = ufl.dS(domain=mesh, subdomain_data=compat.vertex_tags(mesh, vertices), subdomain_id=1)
        T = model.tension(by_role, c)  # (29)
        at0 = lambda e: e * (1 - s) * ds  # noqa: E731  value at s = 0
        at1 = lambda e: e * s * ds  # noqa: E731  value at s = 1
        atm = lambda e: ufl.avg(e) * dS_mid  # noqa: E731  value at the middle vertex
        points = {  # name: (value, where)
            "spin0": (alpha_t, at0), "spin_mid": (alpha_t, atm), "spin1": (alpha_t, at1),
            "alpha0": (alpha, at0), "m0": (formulation.m0, at0),
            "tension0": (T, at0), "tension1": (T, at1),
            "x_mid": (r[0], atm), "y_mid": (r[1], atm), "z_mid": (r[2], atm),
        }
        self.forms = {k: dolfinx.fem.form(where(e)) for k, (e, where) in points.items()}
        s_of = {at0: 0.0, at1: 1.0, atm: self.s_mid}
        self.point_values = PointValues(mesh, {k: (e, s_of[where]) for k, (e, where) in points.items()})
        # fields along s, interpolated at the Lagrange nodes
        V_r, V_s = rod.V_r, rod.V_a
        self.field_exprs = {
            "r": (compat.expression(r, V_r), dolfinx.fem.Function(V_r)),
            "alpha": (compat.expression(alpha, V_s), dolfinx.fem.Function(V_s)),
            "alpha_t": (compat.expression(alpha_t, V_s), dolfinx.fem.Function(V_s)),
            "r_t": (compat.expression(r_t, V_r), dolfinx.fem.Function(V_r)),
            "tension": (compat.expression(T, V_s), dolfinx.fem.Function(V_s)),
            "twist": (compat.expression(model.twist(by_role, c), V_s),  # (34)
                      dolfinx.fem.Function(V_s)),
        }
        # the section's state for the limits block (studies/analysis/structure_limits.py)
        self.section_probe = SectionProbe(model, by_role, c, V_s)
        self._cells = all_cells(mesh)

    def values(self) -> dict:
        """Normalised point values (collective; every rank gets them): the forms'
        values by :class:`PointValues`."""
        return self.point_values()

    def value(self, name: str) -> float:
        """One normalised point value (collective): the sweep reads T(0) every step."""
        return self.comm.allreduce(dolfinx.fem.assemble_scalar(self.forms[name]), op=MPI.SUM)

    def section(self) -> dict | None:
        """The section's state along s (:meth:`SectionProbe.section`).  Collective."""
        return self.section_probe.section()

    def fields(self) -> dict | None:
        """Normalised fields at the Lagrange nodes, sorted by s, on rank 0 (None elsewhere)."""
        out = {}
        for name, (expr, u) in self.field_exprs.items():
            compat.interpolate_expression(u, expr, self._cells)
            s, vals = fe_fields.gather(u)
            if s is not None:
                out["s"] = s
                out[name] = vals if vals.shape[1] > 1 else vals[:, 0]
        return out if self.comm.rank == 0 else None
