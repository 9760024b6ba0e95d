"""What a dynamic run records: point values at s = 0, ~1/2, 1 and fields along s.

Point values are scalar forms on the end points (ds, weighted by 1 - s or s)
and on the vertex nearest the middle (dS), so they are exact point
evaluations and need no search for the owning rank: assemble, then sum over
ranks.
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
        self._u.interpolate(self._expr)
        s, vals = fe_fields.gather(self._u)
        if s is None:
            return None
        return {"s": s, **{name: vals[:, k] for k, name in enumerate(self.names)}}


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
        forms = {
            "spin0": at0(alpha_t), "spin_mid": atm(alpha_t), "spin1": at1(alpha_t),
            "alpha0": at0(alpha), "m0": at0(formulation.m0),
            "tension0": at0(T), "tension1": at1(T),
            "x_mid": atm(r[0]), "y_mid": atm(r[1]), "z_mid": atm(r[2]),
        }
        self.forms = {k: dolfinx.fem.form(v) for k, v in forms.items()}
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

    def values(self) -> dict:
        """Normalised point values (collective; every rank gets them)."""
        local = np.array([dolfinx.fem.assemble_scalar(f) for f in self.forms.values()])
        total = self.comm.allreduce(local, op=MPI.SUM)
        return dict(zip(self.forms, total))

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
            u.interpolate(expr)
            s, vals = fe_fields.gather(u)
            if s is not None:
                out["s"] = s
                out[name] = vals if vals.shape[1] > 1 else vals[:, 0]
        return out if self.comm.rank == 0 else None
