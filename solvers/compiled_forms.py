"""The FE rod's residual F and Jacobian J assembled in compiled code (issue 46): the
FFCx-generated kernels of the formulation's forms called from numba's nopython
mode through their cffi pointers, on the 1D mesh's cells, end facets and
interior facets (the interior-penalty terms), one rank.

Nothing of the physics is here: the kernels are the ones dolfinx assembles (the
forms of forms/, compiled once by FFCx); this module only gathers their
arguments (the packed coefficients U, V, A of each entity, the constants, the
cell geometry) and scatters their element tensors into a dense vector and
matrix, as dolfinx's assembler does.  The gathering maps are found by probing
dolfinx's own packing once (:func:`_coefficient_map`), so a change of element
or of the forms' coefficients is followed, and :meth:`CompiledForms.check`
compares both assemblies (to 1e-12 relative) before a run uses them.

Dirichlet rows: R's are left to the caller (it zeroes them); J's rows and columns
are zero with a unit diagonal (dolfinx's ``assemble_matrix(A, J, bcs)``).
"""

from __future__ import annotations

import cffi
import numba
import numpy as np
from llvmlite import ir
from numba import types
from numba.extending import intrinsic

import dolfinx.cpp

_FFI = cffi.FFI()
_CELL, _EXTERIOR, _INTERIOR = (dolfinx.cpp.fem.IntegralType.cell,
                               dolfinx.cpp.fem.IntegralType.exterior_facet,
                               dolfinx.cpp.fem.IntegralType.interior_facet)
TYPES = (_CELL, _EXTERIOR, _INTERIOR)


class Entities:
    """The integration entities of one integral type: per entity its dofs (the
    element tensor's rows), cell geometry, local facet indices and the entries of
    X = (U, V, A) its packed coefficients read."""

    def __init__(self, dofs, coords, local, wmap):
        self.dofs = np.ascontiguousarray(dofs, dtype=np.int32)
        self.coords = np.ascontiguousarray(coords, dtype=np.float64)
        self.local = np.ascontiguousarray(local, dtype=np.int32)
        self.wmap = np.ascontiguousarray(wmap, dtype=np.int64)


def _topology(mesh, dofmap):
    """Per integral type: (cells of each entity, local facet index in each cell)."""
    tdim = mesh.topology.dim
    mesh.topology.create_connectivity(tdim - 1, tdim)
    mesh.topology.create_connectivity(tdim, tdim - 1)
    f2c, c2f = mesh.topology.connectivity(tdim - 1, tdim), mesh.topology.connectivity(tdim, tdim - 1)
    ncells = mesh.topology.index_map(tdim).size_local
    nfacets = mesh.topology.index_map(tdim - 1).size_local
    cells = [(np.array([c]), np.array([0])) for c in range(ncells)]
    exterior, interior = [], []
    for f in range(nfacets):
        cs = f2c.links(f)
        local = [int(np.flatnonzero(c2f.links(c) == f)[0]) for c in cs]
        (exterior if len(cs) == 1 else interior).append((np.asarray(cs), np.asarray(local)))
    return {_CELL: cells, _EXTERIOR: exterior, _INTERIOR: interior}


def _coefficient_map(form, functions, n):
    """(entities, columns): the index into X = (f_0, f_1, ...) of each packed
    coefficient column, found by packing with f_k = its dof numbers (+ 1 + k n)
    and the others zero (dolfinx's packing is a gather: each column is one dof)."""
    saved = [f.x.array.copy() for f in functions]
    packs = {}
    try:
        for k, f in enumerate(functions):
            for g in functions:
                g.x.array[:] = 0.0
            f.x.array[:] = np.arange(n) + 1.0 + k * n
            for key, arr in dolfinx.cpp.fem.pack_coefficients(form).items():
                packs[key] = packs.get(key, 0.0) + arr
    finally:
        for f, s in zip(functions, saved):
            f.x.array[:] = s
    maps = {}
    for (typ, _), arr in packs.items():
        if np.any(arr < 1.0) or np.any(arr != np.round(arr)):
            raise RuntimeError("compiled forms: a packed coefficient is not a dof of U, V or A")
        maps[typ] = arr.astype(np.int64) - 1
    return maps


def entities(form, functions, mesh, dofmap):
    """:class:`Entities` of each integral type of ``form`` (a dolfinx Form on one
    rank, coefficients ``functions`` in X's order)."""
    n = functions[0].x.array.size
    topo = _topology(mesh, dofmap)
    maps = _coefficient_map(form, functions, n)
    x, gdofs = mesh.geometry.x, mesh.geometry.dofmap
    cell_dofs = dofmap.list
    out = {}
    for typ in TYPES:
        if typ not in form.integral_types:
            continue
        items = topo[typ]
        dofs = [np.concatenate([cell_dofs.links(c) for c in cs]) for cs, _ in items]
        coords = [np.concatenate([x[gdofs.links(c)].reshape(-1) for c in cs]) for cs, _ in items]
        local = [np.resize(lf, 2) for _, lf in items]
        w = maps[typ].reshape(len(items), -1)  # interior facets: both cells' on one row
        out[typ] = Entities(np.array(dofs), np.array(coords), np.array(local), w)
    return out


@intrinsic
def _tabulate(typingctx, kernel, A, w, c, x, e, p):
    """FFCx's tabulate_tensor(A, w, c, coordinate_dofs, entity_local_index,
    quadrature_permutation) at the address ``kernel``, the arrays by their addresses
    (integers: so the nopython functions cache to disk, where a cffi pointer
    cannot, and cost nothing to pass)."""
    sig = types.void(kernel, A, w, c, x, e, p)

    def codegen(context, builder, signature, args):
        dbl, i32, u8 = (ir.DoubleType().as_pointer(), ir.IntType(32).as_pointer(),
                        ir.IntType(8).as_pointer())
        kinds = (dbl, dbl, dbl, dbl, i32, u8)
        fn = builder.inttoptr(args[0], ir.FunctionType(ir.VoidType(), kinds).as_pointer())
        builder.call(fn, [builder.inttoptr(v, t) for v, t in zip(args[1:], kinds)])
        return context.get_dummy_value()
    return sig, codegen


@numba.njit(cache=True)
def _element(Ae, w, kern, X, consts, coords, local, wmap, perm, e):
    """Ae <- entity e's element tensor, its coefficients gathered from X into w."""
    for j in range(wmap.shape[1]):
        w[j] = X[wmap[e, j]]
    Ae[:] = 0.0
    _tabulate(kern, Ae.ctypes.data, w.ctypes.data, consts.ctypes.data, coords[e].ctypes.data,
              local[e].ctypes.data, perm.ctypes.data)


@numba.njit(cache=True)
def _assemble_vector(b, kern, X, consts, dofs, coords, local, wmap, perm):
    Ae, w = np.empty(dofs.shape[1]), np.empty(wmap.shape[1])
    for e in range(dofs.shape[0]):
        _element(Ae, w, kern, X, consts, coords, local, wmap, perm, e)
        for i in range(dofs.shape[1]):
            b[dofs[e, i]] += Ae[i]


@numba.njit(cache=True)
def _assemble_matrix(A, kern, X, consts, dofs, coords, local, wmap, perm):
    m = dofs.shape[1]
    Ae, w = np.empty(m * m), np.empty(wmap.shape[1])
    for e in range(dofs.shape[0]):
        _element(Ae, w, kern, X, consts, coords, local, wmap, perm, e)
        for i in range(m):
            for j in range(m):
                A[dofs[e, i], dofs[e, j]] += Ae[i * m + j]


@numba.njit(cache=True)
def residual(b, X, consts, P):
    """b = F(X) by the kernels of P (:meth:`CompiledForms.pieces`'s first)."""
    b[:] = 0.0
    _assemble_vector(b, P[0][0], X, consts, P[1], P[2], P[3], P[4], P[13])
    _assemble_vector(b, P[0][1], X, consts, P[5], P[6], P[7], P[8], P[13])
    _assemble_vector(b, P[0][2], X, consts, P[9], P[10], P[11], P[12], P[13])


@numba.njit(cache=True)
def jacobian(A, X, consts, P, bc):
    """A = J(X) by the kernels of P (:meth:`CompiledForms.pieces`'s second), its
    Dirichlet rows and columns ``bc`` zero with a unit diagonal."""
    A[:, :] = 0.0
    _assemble_matrix(A, P[0][0], X, consts, P[1], P[2], P[3], P[4], P[13])
    _assemble_matrix(A, P[0][1], X, consts, P[5], P[6], P[7], P[8], P[13])
    _assemble_matrix(A, P[0][2], X, consts, P[9], P[10], P[11], P[12], P[13])
    for i in bc:
        A[i, :] = 0.0
        A[:, i] = 0.0
        A[i, i] = 1.0


class CompiledForms:
    """F and J of a :class:`~rawehelix.solvers.rod_operator.RodOperator`'s
    formulation (TSALPHA2's forms) by their FFCx kernels from numba; one rank.

    ``pieces()`` gives the flat tuple the nopython stepper passes to
    :func:`residual` and :func:`jacobian`."""

    def __init__(self, op):
        form = op.form
        if form.u.function_space.mesh.comm.size > 1:
            raise RuntimeError("compiled forms: one rank only")
        self.op, self.form = op, form
        V = form.u.function_space
        mesh = V.mesh
        functions = (form.u, form.v, form.a)
        self.n = n = op.n
        if form.u.x.array.size != n:
            raise RuntimeError("compiled forms: ghosted dofs")
        self.bc_dofs = np.asarray(op.bc_dofs, dtype=np.int64)
        self._F, self._J = form.F, form.J
        self.F_entities = entities(form.F, functions, mesh, V.dofmap)
        self.J_entities = entities(form.J, functions[:2], mesh, V.dofmap)
        self.F_kernels = self._kernels(form.F)
        self.J_kernels = self._kernels(form.J)
        self._shift_slots = self._jacobian_constants()
        #: J's entries lie within this many places of the diagonal (an entity couples its dofs)
        self.bandwidth = max(int(np.ptp(d)) for e in self.J_entities.values() for d in e.dofs)

    @staticmethod
    def _kernels(f):
        uf = f.ufcx_form
        out = {}
        for typ in TYPES:
            k = int(typ)
            if uf.num_integrals(k) > 1:
                raise RuntimeError("compiled forms: more than one integral of a type (subdomains)")
            if uf.num_integrals(k) == 1:
                if uf.integrals(k)[0].needs_facet_permutations and k != int(_INTERIOR):
                    raise RuntimeError("compiled forms: facet permutations")
                out[typ] = uf.integrals(k)[0].tabulate_tensor_float64
        return out

    def _jacobian_constants(self):
        """Where J's constants differ from F's: the two shifts (found by probing)."""
        form = self.form
        saved = form.shift_v.value, form.shift_a.value
        form.shift_v.value, form.shift_a.value = 1.25e7, 2.5e9
        cf, cj = dolfinx.cpp.fem.pack_constants(self._F), dolfinx.cpp.fem.pack_constants(self._J)
        form.shift_v.value, form.shift_a.value = saved
        sv, sa = int(np.flatnonzero(cj == 1.25e7)[0]), int(np.flatnonzero(cj == 2.5e9)[0])
        rest = np.delete(np.arange(cj.size), [sv, sa])
        if rest.size != cf.size or not np.array_equal(cj[rest], cf):
            raise RuntimeError("compiled forms: J's constants are not F's and the two shifts")
        return sv, sa, rest

    def constants(self) -> np.ndarray:
        """F's constants at the time set (the form's set_time)."""
        return dolfinx.cpp.fem.pack_constants(self._F)

    def jacobian_constants(self, cf, sv, sa) -> np.ndarray:
        i, j, rest = self._shift_slots
        cj = np.empty(cf.size + 2)
        cj[rest], cj[i], cj[j] = cf, sv, sa
        return cj

    def _arguments(self, ents, kernels):
        """(kernel addresses, then dofs, coords, local, wmap of each integral type,
        then the quadrature permutation): a missing type has no entities."""
        any_e = next(iter(ents.values()))
        addresses, arrays = np.zeros(3, np.int64), []
        for k, typ in enumerate(TYPES):
            e = ents.get(typ)
            if e is None:
                arrays += [any_e.dofs[:0], any_e.coords[:0], any_e.local[:0], any_e.wmap[:0]]
            else:
                addresses[k] = int(_FFI.cast("uintptr_t", kernels[typ]))
                arrays += [e.dofs, e.coords, e.local, e.wmap]
        return (addresses, *arrays, np.zeros(2, np.uint8))

    def pieces(self):
        """(F's arguments, J's arguments) of :func:`residual` and :func:`jacobian`."""
        if getattr(self, "_pieces", None) is None:
            self._pieces = (self._arguments(self.F_entities, self.F_kernels),
                            self._arguments(self.J_entities, self.J_kernels))
        return self._pieces

    def residual(self, X, consts):
        b = np.zeros(self.n)
        residual(b, X, consts, self.pieces()[0])
        return b

    def jacobian(self, X, cj):
        A = np.zeros((self.n, self.n))
        jacobian(A, X, cj, self.pieces()[1], self.bc_dofs)
        return A

    def check(self, X, sv, sa, tol=1e-12):
        """Compare both assemblies with dolfinx's at X (loaded into the forms) and the
        time set; raise if they differ by more than ``tol`` (relative, max norm)."""
        op, n = self.op, self.n
        op.load(X[:n], X[n:2 * n], X[2 * n:])
        cf = self.constants()
        R0 = op.residual().copy()
        R1 = self.residual(X, cf)
        J0 = op.assemble_jacobian(op.create_jacobian(), sv, sa)
        J1 = self.jacobian(X, self.jacobian_constants(cf, sv, sa))
        er = np.abs(R1 - R0).max() / max(np.abs(R0).max(), 1e-300)
        ej = np.abs(J1 - J0).max() / max(np.abs(J0).max(), 1e-300)
        if not (er <= tol and ej <= tol):
            raise RuntimeError(f"compiled forms: differ from dolfinx's assembly (residual "
                               f"{er:.2e}, Jacobian {ej:.2e} relative)")
        return er, ej
