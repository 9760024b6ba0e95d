"""Linear frequency response to the circular motion of the upper end (Sec. 5.3, Eq. 70).

About the stationary state w0 with the upper end at the centre r_N0 of its
circle (:func:`centre`; linearised by :class:`~rawehelix.solvers.modal.ModalSolver`:
the K, C, M of ``rawehelix modes`` of that state), a small end motion
r_N(t) = r_N0 + Re(X_b e^{i w t}) gives the steady harmonic response
w = w0 + Re(X e^{i w t}) with

    (K - w^2 M + i w C) X = 0   on the free dofs,     X = X_b   on the bc dofs.  (*)

The circle of Eq. (70) is, with phi = w t~ + phase0, c = cos Gamma0, s = sin Gamma0,

    r_N(t) - r_N0 = r1 (-s sin phi, cos phi, c sin phi) = Re(X_b e^{i w t~}),
    X_b = r1 e^{i phase0} (i s, 1, -i c)   (normalised, units L0),

on the top-end dofs; the bottom end, and the bc rows of the twist and curvature
fields, are held at 0.  The bc rows of K carry 1 on the diagonal, those of C
and M 0 (:mod:`.linearise`), so the bc rows of (*) read X = X_b; the free rows
get the lifting -(K0 - w^2 M0 + i w C0) X_b with the unconstrained matrices
(assembled without bcs, whose bc columns are not zeroed).

PETSc here is real: (*) is solved as the real 2 x 2 block system

    [ K - w^2 M    -w C     ] [Xr]   [fr]
    [   w C      K - w^2 M  ] [Xi] = [fi],

assembled with the real and imaginary parts of each dof interleaved (rows and
columns 2i, 2i + 1: the band of the 1D dofmap is kept, so the LU with the
natural ordering of :func:`~rawehelix.solvers.snes.lu_options` fills like a
complex LU of K, not like the n-wide band of the [Xr; Xi] ordering) and solved
with one LU (:func:`~rawehelix.solvers.snes.direct_solver`, options prefix
``rawehelix_response_``) whose converged reason is checked.

Outputs (linear functionals of X, assembled once as vectors g with g.X):

* the midpoint's displacement (the vertex nearest s = 1/2,
  :func:`~rawehelix.solvers.probes.middle_vertex`), made lateral by removing its
  component along the stationary tangent t there; its amplitude is the
  semi-major axis of the ellipse Re(U e^{i w t}) it traces;
* the linearised tension at s = 0, dT = sigma t . du' (Eq. 29), and |dT|.

The twist is left free (torque-free ends, as the modes): the rigid rotation
makes K singular, but not K - w^2 M at w > 0.  Nothing here reads or writes files.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
import ufl
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.fem
import dolfinx.fem.petsc

from rawehelix import compat
from rawehelix.forms.kinematics import d
from rawehelix.parameters import Parameters
from rawehelix.solvers import petsc_options
from rawehelix.solvers.fields import set_constant
from rawehelix.solvers.modal import ModalSolver
from rawehelix.solvers.probes import middle_vertex
from rawehelix.solvers.snes import SolverError, direct_solver, reason_name
from rawehelix.solvers.state import RodState


def end_amplitude(q) -> np.ndarray:
    """X_b: the complex amplitude of the upper end's displacement on the circle
    of Eq. (70), normalised (units L0): Re(X_b e^{i omega1 t~}) = r_N(t~) - r_N(0)|_{r1=0}."""
    c, s = math.cos(q.Gamma0), math.sin(q.Gamma0)
    return q.r1 * np.exp(1j * q.phase0) * np.array([1j * s, 1.0, -1j * c])


def centre(params: Parameters) -> Parameters:
    """The scene with its upper end at the centre of the circle (R1 = 0): the
    state the response is linearised about.

    Not the end at phase 0 (where the sweep and ``rawehelix modes`` start):
    every point of the circle is at the distance sqrt(a^2 + r1^2) from the lower
    end (a = (1 + eps0) L0, the circle is normal to the chord), so the chord
    length does not change along it; about a point of the circle the
    linearisation would see it change at first order (by r1^2 / a cos phi),
    and with the axial stiffness sigma ~ 1.5e4 that spurious stretch swamps
    the true tension response (5.8 N against 0.013 N quasi-statically for
    mobile_end, R1 = 0.1 m)."""
    return params.replace(ends={"circle_radius_m": 0.0})


def ellipse_semi_major(u: np.ndarray) -> float:
    """The semi-major axis of the ellipse Re(u e^{i theta}), theta in [0, 2 pi),
    of a complex vector u = a + i b: the largest |a cos theta - b sin theta|."""
    a, b = np.real(u), np.imag(u)
    aa, bb, ab = a @ a, b @ b, a @ b
    return math.sqrt(max(0.5 * (aa + bb) + math.hypot(0.5 * (aa - bb), ab), 0.0))


def _csr(A) -> sp.csr_matrix:
    """This rank's rows of a PETSc AIJ matrix (global columns) as scipy CSR."""
    indptr, indices, values = A.getValuesCSR()
    (r0, r1), n = A.getOwnershipRange(), A.getSize()[1]
    return sp.csr_matrix((values, indices, indptr), shape=(r1 - r0, n))


_RE = sp.csr_matrix(np.eye(2))  # the real part of a complex entry: [[a, 0], [0, a]]
_IM = sp.csr_matrix(np.array([[0.0, -1.0], [1.0, 0.0]]))  # i b: [[0, -b], [b, 0]]


@dataclass
class ResponsePoint:
    """The steady response at one f1, SI but for ``X`` (normalised)."""

    f1_Hz: float
    lateral_mid_amplitude_m: float  # semi-major axis of the midpoint's lateral ellipse [m]
    tension_amplitude_N: float  # |dT(0)| [N]
    in_plane_m: float  # |u.n|, n = j_E x t: the midpoint's in-plane amplitude [m]
    out_of_plane_m: float  # |u.b|, b = t x n (j_E for a planar state) [m]
    midpoint_m: np.ndarray  # complex lateral displacement of the midpoint, (3,) [m]
    tension_N: complex  # complex dT at s = 0 [N]
    X: tuple = field(default=None, repr=False)  # (Re X, Im X): PETSc vectors of W (normalised)

    def entry(self) -> dict:
        return {"f1_Hz": self.f1_Hz, "lateral_mid_amplitude_m": self.lateral_mid_amplitude_m,
                "tension_amplitude_N": self.tension_amplitude_N,
                "lateral_mid_in_plane_m": self.in_plane_m,
                "lateral_mid_out_of_plane_m": self.out_of_plane_m}


class HarmonicResponse:
    """The linear response (*) of one scene about the stationary state of its
    :class:`ModalSolver` (the solver's K, C, M, bcs and rod).

    ``HarmonicResponse.from_stationary(params)`` solves the stationary state
    and linearises; :meth:`at` gives the response at one f1, :meth:`vector`
    the complex dof vector, :meth:`orbit_state` the state on the orbit at a time."""

    def __init__(self, modal: ModalSolver, params: Parameters):
        if modal.K is None:
            raise RuntimeError("HarmonicResponse: the modal solver is not linearised yet")
        if modal.params.ends.circle_radius_m != 0:
            raise ValueError("HarmonicResponse: linearise about the circle's centre (a modal "
                             "solver of the scene with ends.circle_radius_m = 0: centre(params))")
        self.modal = modal
        self.params, self.comm, self.scene = params, modal.comm, modal.scene
        rod = modal.rod
        self.rod, self.q = rod, params.normalised()
        lin = modal.lin
        self._K, self._C, self._M = _csr(modal.K), _csr(modal.C), _csr(modal.M)
        # the unconstrained matrices for the lifting (bc columns kept)
        self._K0, self._C0, self._M0 = (dolfinx.fem.petsc.assemble_matrix(a)
                                        for a in (lin.a_K, lin.a_C, lin.a_M))
        for A in (self._K0, self._C0, self._M0):
            A.assemble()
        self._Xb = self._end_vectors()
        self._bc_rows = self._owned_bc_rows()
        self._outputs()
        self.ksp = None

    @classmethod
    def from_stationary(cls, params: Parameters, comm=MPI.COMM_WORLD,
                        scene: str = "scene") -> "HarmonicResponse":
        """Solve the stationary state with the upper end at the centre of its
        circle (Sec. 5.1 with R1 = 0), linearise about it (as ``rawehelix modes``
        does) and return the response solver for the circle of ``params``."""
        return cls(ModalSolver.from_stationary(centre(params), comm, scene=scene), params)

    # -- set-up -------------------------------------------------------------------------
    def _end_vectors(self):
        """(Re X_b, Im X_b) as PETSc vectors of W: nonzero on the top-end dofs only."""
        rod = self.rod
        Xb = end_amplitude(self.q)
        out = []
        for part in (Xb.real, Xb.imag):
            u = dolfinx.fem.Function(rod.V_r)
            set_constant(u, part)
            bc = dolfinx.fem.dirichletbc(u, rod.end_dofs["top"], rod.sub("centre_line"))
            x = self.modal.K.createVecRight()
            x.set(0.0)
            dolfinx.fem.petsc.set_bc(x, [bc])
            out.append(x)
        return tuple(out)

    def _owned_bc_rows(self) -> np.ndarray:
        """The owned bc rows of (*), local indices."""
        n_owned = self.rod.W.dofmap.index_map.size_local * self.rod.W.dofmap.index_map_bs
        rows = [bc.dof_indices()[0][:bc.dof_indices()[1]] for bc in self.modal.bcs]
        rows = np.unique(np.concatenate(rows)) if rows else np.zeros(0, dtype=np.int32)
        return rows[rows < n_owned]

    def _outputs(self):
        """The functionals g (PETSc vectors, g.X) of the midpoint's x, y, z and of
        dT(0) = sigma t.du'(0), and the stationary unit tangent at the midpoint."""
        rod = self.rod
        mesh = rod.mesh
        self.s_mid, vertices = middle_vertex(mesh)
        dS_mid = ufl.dS(domain=mesh, subdomain_data=compat.vertex_tags(mesh, vertices),
                        subdomain_id=1)
        ds = ufl.ds(domain=mesh)
        s = ufl.SpatialCoordinate(mesh)[0]
        r0 = rod.centre_line()  # the stationary state: the rod holds it after linearise
        v = rod.model.split(rod.test)["centre_line"]
        t0 = d(r0) / ufl.sqrt(ufl.dot(d(r0), d(r0)))
        forms = [ufl.avg(v[k]) * dS_mid for k in range(3)]
        forms.append(rod.c.sigma * ufl.dot(t0, d(v)) * (1 - s) * ds)  # dT at s = 0, (29)
        self._g = []
        for a in forms:
            g = dolfinx.fem.petsc.assemble_vector(dolfinx.fem.form(a))
            g.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
            self._g.append(g)
        tangent = [self.comm.allreduce(dolfinx.fem.assemble_scalar(dolfinx.fem.form(
            ufl.avg(d(r0)[k]) * dS_mid)), op=MPI.SUM) for k in range(3)]
        t = np.array(tangent) / np.linalg.norm(tangent)
        n = np.cross([0.0, 1.0, 0.0], t)  # in plane, as solvers.linearise
        n /= np.linalg.norm(n)
        self.tangent_mid, self.normal_mid, self.binormal_mid = t, n, np.cross(t, n)
        position = [self.comm.allreduce(dolfinx.fem.assemble_scalar(dolfinx.fem.form(
            ufl.avg(r0[k]) * dS_mid)), op=MPI.SUM) for k in range(3)]
        self.position_mid = np.array(position)  # normalised

    # -- the solve ----------------------------------------------------------------------
    def block_matrix(self, omega: float) -> PETSc.Mat:
        """The interleaved real form of K - omega^2 M + i omega C (this rank's rows
        2 r0 .. 2 r1 - 1); its bc rows are the identity."""
        real = self._K - omega**2 * self._M
        A = (sp.kron(real, _RE, format="csr") + sp.kron(omega * self._C, _IM, format="csr")).tocsr()
        A.sort_indices()
        n_local, n = 2 * real.shape[0], 2 * real.shape[1]
        return PETSc.Mat().createAIJ(((n_local, n), (n_local, n)),
                                     csr=(A.indptr.astype(PETSc.IntType),
                                          A.indices.astype(PETSc.IntType), A.data),
                                     comm=self.comm)

    def forcing(self, omega: float):
        """(fr, fi): the lifting -(K0 - w^2 M0 + i w C0) X_b on the free rows and
        X_b on the bc rows of (*)."""
        Xr, Xi = self._Xb
        K0, C0, M0 = self._K0, self._C0, self._M0
        out = []
        for a, b, sign in ((Xr, Xi, 1.0), (Xi, Xr, -1.0)):
            # real part: -(K0 - w^2 M0) Xr + w C0 Xi; imaginary: -(K0 - w^2 M0) Xi - w C0 Xr
            f, tmp = K0.createVecLeft(), K0.createVecLeft()
            K0.mult(a, f)
            M0.mult(a, tmp)
            f.axpy(-omega**2, tmp)
            f.scale(-1.0)
            C0.mult(b, tmp)
            f.axpy(sign * omega, tmp)
            f.array[self._bc_rows] = a.array[self._bc_rows]
            out.append(f)
        return tuple(out)

    def solve(self, omega: float):
        """(Re X, Im X) at the normalised angular frequency omega > 0 (PETSc
        vectors of W).  Raises SolverError if the LU solve fails."""
        if not (omega > 0 and math.isfinite(omega)):
            raise ValueError(f"{self.scene}: the response needs omega > 0, got {omega!r}")
        A = self.block_matrix(omega)
        fr, fi = self.forcing(omega)
        b = A.createVecLeft()
        b.array[0::2], b.array[1::2] = fr.array, fi.array
        x = A.createVecRight()
        if self.ksp is None:
            self.ksp = direct_solver(self.comm)
            self.ksp.setOptionsPrefix(petsc_options.RESPONSE_PREFIX)
            self.ksp.setFromOptions()
        self.ksp.setOperators(A)
        try:
            self.ksp.solve(b, x)
            reason = self.ksp.getConvergedReason()
        except PETSc.Error as err:  # a zero pivot, say
            reason = f"PETSc error {err.ierr}"
        else:
            reason = None if reason > 0 and np.isfinite(x.norm()) else \
                f"KSP reason {reason_name(reason, PETSc.KSP.ConvergedReason)}, |x| = {x.norm():.3g}"
        if reason is not None:
            raise SolverError(
                f"{self.scene}: the linear response at f1 = {self.frequency_Hz(omega):.6g} Hz "
                f"failed ({reason}): K - w^2 M + i w C is singular there (an undamped "
                f"natural frequency, or w = 0 with the free twist); move f1 off it")
        Xr, Xi = fr.duplicate(), fi.duplicate()
        Xr.array[:], Xi.array[:] = x.array[0::2], x.array[1::2]
        return Xr, Xi

    # -- in SI --------------------------------------------------------------------------
    def omega(self, f1_Hz: float) -> float:
        """The normalised angular frequency of f1 [Hz], Eq. (70)."""
        return 2 * math.pi * f1_Hz * self.q.t_scale

    def frequency_Hz(self, omega: float) -> float:
        return omega / (2 * math.pi * self.q.t_scale)

    def outputs(self, Xr, Xi):
        """(complex midpoint displacement (3,), complex dT(0)), normalised (collective)."""
        values = np.array([g.dot(Xr) + 1j * g.dot(Xi) for g in self._g])
        return values[:3], values[3]

    def at(self, f1_Hz: float, keep_vector: bool = False) -> ResponsePoint:
        """The response at f1 [Hz] (collective): the midpoint's lateral amplitude
        [m] and the tension amplitude at s = 0 [N]; ``keep_vector``: with X."""
        Xr, Xi = self.solve(self.omega(f1_Hz))
        u, dT = self.outputs(Xr, Xi)
        t = self.tangent_mid
        lateral = u - t * (t @ u)  # perpendicular to the stationary tangent
        q = self.q
        return ResponsePoint(
            f1_Hz=float(f1_Hz),
            lateral_mid_amplitude_m=float(q.length_m(ellipse_semi_major(lateral))),
            tension_amplitude_N=float(q.tension_N(abs(dT))),
            in_plane_m=float(q.length_m(abs(self.normal_mid @ u))),
            out_of_plane_m=float(q.length_m(abs(self.binormal_mid @ u))),
            midpoint_m=lateral * q.L0, tension_N=complex(dT * q.force_scale),
            X=(Xr, Xi) if keep_vector else None)

    def vector(self, f1_Hz: float) -> np.ndarray:
        """The complex response X at f1 [Hz]: this rank's owned dofs of W (normalised)."""
        Xr, Xi = self.solve(self.omega(f1_Hz))
        return Xr.array + 1j * Xi.array

    def orbit_state(self, f1_Hz: float, t: float = 0.0) -> RodState:
        """The state on the linear orbit at the normalised time t: w = w0 +
        Re(X e^{i w t}), w_t = Re(i w X e^{i w t}) (local arrays with ghosts),
        with the circle at phase ``q.phase0`` at t~ = 0, as :meth:`solve` takes it."""
        omega = self.omega(f1_Hz)
        Xr, Xi = self.solve(omega)
        rot = np.exp(1j * omega * t)
        W = self.rod.W
        w, w_t = dolfinx.fem.Function(W), dolfinx.fem.Function(W)
        X = (Xr.array + 1j * Xi.array) * rot
        n = X.size
        w.x.array[:n] = X.real
        w_t.x.array[:n] = (1j * omega * X).real
        for f in (w, w_t):
            f.x.scatter_forward()
        w0 = self.rod.w.x.array
        return RodState(w0 + w.x.array, w_t.x.array.copy(), t, self.rod.dof_count())

