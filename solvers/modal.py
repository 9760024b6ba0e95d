"""Natural modes of a stationary state: the linearised Eqs. (30)-(31) with SLEPc.

About a stationary state w0 (Sec. 5.1, solved by Newton with the twist
pinned), a small motion w = w0 + x e^{lambda t} obeys

    (lambda^2 M + lambda C + K) x = 0,                                 (*)

with the three Jacobians of the full residual F(w, w_t, w_tt; v) of
Eqs. (30)-(31) (:func:`rawehelix.forms.rod.residual`):

    K = dF/dw     at (w0, 0, 0)   elastic + geometric stiffness (32)-(34),
    C = dF/dw_t   at (w0, 0, 0)   the linearised drag of Eq. (28),
    M = dF/dw_tt                  the mass, int r_tt.v + alpha_tt psi.

Boundary conditions.  The ends are fixed, so the displacement vanishes at
s = 0 and s = 1 (Eqs. 35-36): homogeneous Dirichlet conditions on r only.
The twist is *not* pinned: with torque-free ends (38)-(39) the rigid rotation
alpha = const is a true mode, the zero eigenvalue reported as family
``rigid`` (a Jordan pair: alpha = const and alpha = t).  The state itself
comes from :class:`StationarySolver` (alpha(0) = 0 pinned, where the Newton
matrix is regular); K, C, M are then assembled on the same space with these
bcs only, i.e. the ``pin_twist=False`` discretisation of the same mesh,
without copying the state between meshes.  The bc rows are
assembled with 1 on the diagonal of K and 0 on those of C and M: a bc dof then
satisfies x_i = 0 exactly and contributes only *infinite* eigenvalues, which
the shift-and-invert transformation maps to 0 and never returns (no spurious
finite eigenvalue; :meth:`ModalSolver.bc_amplitude` shows it).

Solver choice.  SLEPc PEP with TOAR (a Krylov method on the companion
linearisation of (*) stored in compact form) and the shift-and-invert spectral
transformation:

* TOAR works on the general (non-symmetric: drag, and the gamma coupling of
  Eq. 34 which has no potential) quadratic problem without forming the
  2n x 2n pencil; memory is n x (ncv + 2) instead of 2n x ncv;
* shift-and-invert factorises P(tau) = tau^2 M + tau C + K once (PETSc's LU
  in serial, MUMPS in parallel) and makes the eigenvalues nearest the target converge first;
* PETSc here is real, so the target tau is real.  The eigenvalues sit near
  the imaginary axis, |lambda - tau|^2 ~ tau^2 + omega^2, so a real target
  orders them by |lambda|: the slowest modes come first.  tau is put on the
  positive real axis, off the rigid zero (where K is singular) and away from
  every eigenvalue of a stable state (Re lambda <= 0): tau = omega_min / 4,
  omega_min the lowest of the analytic estimates below.
* the number of eigenpairs nev is chosen so that the lowest ``per_family``
  modes of *each* family are inside the computed set: all families' analytic
  estimates below the largest per-family target are counted (both members of
  each conjugate pair, plus the rigid pair), with a margin.  After the solve
  every family is checked; a missing one raises an error naming the option
  to raise (``-rawehelix_pep_nev``).

Options: prefix ``rawehelix_`` (``-rawehelix_pep_nev 40``,
``-rawehelix_pep_target 5``, ``-rawehelix_st_pc_factor_mat_solver_type``...).

Classification of every mode from its eigenvector x, in two steps:

1. centre line or twist: the block (r or alpha) whose own dynamics resonates
   at lambda, i.e. the smaller relative residual of the diagonal block of
   P(lambda) (:meth:`ModalSolver.block_residuals`).  Energy alone cannot
   decide this when the gamma coupling of Eq. (34) is on: a slaved twist then
   dominates the kinetic energy of the out-of-plane lateral modes.
2. for the centre line, the largest kinetic-energy fraction of the
   displacement along the local tangent t of the stationary centre line
   (``longitudinal``, axial stretch), along n = j_E x t (in the x-z plane,
   ``lateral_in_plane``) and along j_E (``lateral_out_of_plane``).

The kinetic-energy fractions (twist with the rotational inertia beta/delta of
Eq. 27, as the spline reference) are reported with every mode; |lambda| below
a small fraction of the target is the ``rigid`` rotation.

Accuracy: the fourth-order operator limits the attainable accuracy of the
lateral modes on fine meshes (round-off ~ eps N^4, 1e-3 at N = 512, p = 3);
see docs/modal_convergence.md.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
import ufl
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.fem
import dolfinx.fem.petsc

from rawehelix import compat
from rawehelix.forms import rod as rod_forms
from rawehelix.forms.kinematics import d
from rawehelix.parameters import Parameters
from rawehelix.solvers import fields
from rawehelix.solvers.snes import SolverError, default_options, lu_options
from rawehelix.solvers.stationary import StationarySolver

FAMILIES = ("longitudinal", "lateral_in_plane", "lateral_out_of_plane", "torsional", "rigid")
COMPONENTS = ("x", "y", "z", "alpha")

PEP_DEFAULTS = {
    "pep_type": "toar",
    "pep_tol": 1.0e-10,
    "pep_max_it": 500,
    "st_type": "sinvert",
    "st_ksp_type": "preonly",
    "st_pc_type": "lu",  # with lu_options(comm)
}


@dataclass
class Mode:
    """One mode: an eigenvalue with Im >= 0 stands for its conjugate pair."""

    eigenvalue: complex  # normalised (1 / t_scale units)
    family: str
    fractions: dict  # energy fraction per family (without "rigid")
    dominant: list  # components x, y, z, alpha with energy >= 0.5 of the largest
    error: float  # relative backward error |P(lambda) x| / (...) from SLEPc
    vectors: tuple = field(repr=False, default=None)  # (Re x, Im x) PETSc vectors


def analytic_frequencies(q, tension: float, count: int, twist: bool = True) -> dict:
    """omega_n, n = 1..count, of the classical models (normalised, Eq. 25).

    Used only to place the target and size the Krylov space; the tests check
    the FE spectrum against the same models with the details of the rod model.

    longitudinal: fixed-fixed bar, omega_n = n pi sqrt(sigma);
    lateral: pinned beam under tension, omega_n^2 = (n pi)^2 T + mu (n pi)^4;
    torsional: free-free shaft, omega_n = n pi sqrt(delta).
    """
    n = np.arange(1, count + 1) * math.pi
    lateral = np.sqrt(n**2 * tension + q.bending * q.mu * n**4)
    return {
        "longitudinal": n * math.sqrt(q.sigma),
        "lateral_in_plane": lateral,
        "lateral_out_of_plane": lateral,
        **({"torsional": n * math.sqrt(q.delta)} if twist else {}),  # model.twist = false: none
    }


def _count_below(q, tension: float, omega: float, twist: bool = True) -> int:
    """How many analytic modes (all families) have omega_n <= omega."""
    total = 0
    for rate in (math.sqrt(q.sigma), math.sqrt(q.delta))[:2 if twist else 1]:  # bar, shaft
        total += int(omega / (math.pi * rate))
    # lateral, twice (in and out of plane): solve mu k^4 + T k^2 = omega^2 for k = n pi
    mu = max(q.bending * q.mu, 1e-300)
    k2 = (-tension + math.sqrt(tension**2 + 4 * mu * omega**2)) / (2 * mu)
    total += 2 * int(math.sqrt(max(k2, 0.0)) / math.pi)
    return total


class ModalSolver:
    """Stationary state, its linearisation (K, C, M) and the PEP (*) for one scene.

    Parameters
    ----------
    params : validated scene parameters (scheme ``fe``).
    comm : MPI communicator; the spectrum does not depend on its size.
    scene : name used in error messages.
    """

    def __init__(self, params: Parameters, comm=MPI.COMM_WORLD, scene: str = "scene"):
        self.params, self.comm, self.scene = params, comm, scene
        self.stationary = StationarySolver(params, comm, scene=scene)
        self.rod = rod = self.stationary.rod
        self.q = rod.q
        # separate fields for w, w_t, w_tt: the three Jacobians of F at (w0, 0, 0)
        self.w_t = dolfinx.fem.Function(rod.W, name="velocity")
        self.w_tt = dolfinx.fem.Function(rod.W, name="acceleration")
        F = rod_forms.residual(rod.w, self.w_t, self.w_tt, rod.test, rod.c, rod.degree,
                               rod.penalty, rod.measures)  # (30)-(31)
        du = rod.trial
        self.a_K = dolfinx.fem.form(ufl.derivative(F, rod.w, du))
        self.a_C = dolfinx.fem.form(ufl.derivative(F, self.w_t, du))
        self.a_M = dolfinx.fem.form(ufl.derivative(F, self.w_tt, du))
        self.bcs = self._fixed_ends()
        self._energy_forms()
        self.stationary_result = None
        self.K = self.C = self.M = None

    # -- set-up --------------------------------------------------------------------
    def _fixed_ends(self):
        """Homogeneous Dirichlet conditions on the displacement at both ends
        (35)-(36); none on the twist (the rigid rotation stays free)."""
        rod = self.rod
        zero = dolfinx.fem.Function(rod.V_r)
        return [dolfinx.fem.dirichletbc(zero, dofs, rod.W.sub(0))
                for dofs in rod.end_dofs.values()] + rod.twist_bcs

    def _energy_forms(self):
        """Kinetic-energy matrices of the families and of the components.

        Displacement u along the local tangent t of the stationary centre line
        (``longitudinal``), along n = j_E x t (``lateral_in_plane``), along j_E
        (``lateral_out_of_plane``); twist alpha with the rotational inertia
        beta/delta = 2 rho I / (rho A L0^2) of Eq. (27) (``torsional``), as in
        the spline reference (``spline_galerkin.spectrum``).
        """
        rod = self.rod
        dx = rod.measures[0]
        c = rod.c
        r0 = ufl.split(rod.w)[0]
        u, a = ufl.split(rod.trial)
        v, b = ufl.split(rod.test)
        t = d(r0) / ufl.sqrt(ufl.dot(d(r0), d(r0)))
        j = ufl.as_vector((0.0, 1.0, 0.0))
        n = ufl.cross(j, t)
        n = n / ufl.sqrt(ufl.dot(n, n) + 1e-300)
        rot = c.beta / c.delta  # (27)
        family = {
            "longitudinal": ufl.dot(u, t) * ufl.dot(v, t) * dx,
            "lateral_in_plane": ufl.dot(u, n) * ufl.dot(v, n) * dx,
            "lateral_out_of_plane": u[1] * v[1] * dx,
            "torsional": rot * a * b * dx,
        }
        comps = {"x": u[0] * v[0] * dx, "y": u[1] * v[1] * dx, "z": u[2] * v[2] * dx,
                 "alpha": rot * a * b * dx}
        self._energy_ufl = {"family": family, "component": comps}
        self._energy = None

    def _assemble_energy(self):
        self._energy = {
            kind: {k: self._assemble(dolfinx.fem.form(a), [], 0.0) for k, a in forms.items()}
            for kind, forms in self._energy_ufl.items()}

    @staticmethod
    def _assemble(a, bcs, diagonal):
        A = dolfinx.fem.petsc.assemble_matrix(a, bcs=bcs, diagonal=diagonal)
        A.assemble()
        return A

    # -- stationary state and linearisation -------------------------------------------
    def linearise(self):
        """Solve for the stationary state (if not done) and assemble K, C, M.

        bc rows: K_ii = 1, C_ii = M_ii = 0 (infinite eigenvalues only)."""
        if self.stationary_result is None:
            self.stationary_result = self.stationary.solve()
        self.w_t.x.array[:] = 0.0
        self.w_tt.x.array[:] = 0.0
        self.K = self._assemble(self.a_K, self.bcs, 1.0)
        self.C = self._assemble(self.a_C, self.bcs, 0.0)
        self.M = self._assemble(self.a_M, self.bcs, 0.0)
        self._assemble_energy()
        self.mean_tension_value = self.mean_tension()
        return self.K, self.C, self.M

    def mean_tension(self) -> float:
        """int_0^1 T ds of the stationary state (normalised, Eq. 29)."""
        T = rod_forms.tension_of(self.rod.w, self.rod.c)
        local = dolfinx.fem.assemble_scalar(dolfinx.fem.form(T * self.rod.measures[0]))
        return self.comm.allreduce(local, op=MPI.SUM)

    # -- the eigenproblem ------------------------------------------------------------
    def default_nev(self, per_family: int = 3, margin: float = 1.2) -> int:
        """Eigenvalues (both of each pair) to hold the lowest ``per_family``
        modes of every family, from :func:`analytic_frequencies`."""
        T = max(self.mean_tension_value, 0.0)
        est = analytic_frequencies(self.q, T, per_family, self.twist)
        omega = margin * max(v[-1] for v in est.values())
        return 2 * _count_below(self.q, T, omega, self.twist) + 2 + 4

    @property
    def twist(self) -> bool:
        return self.params.model.twist

    @property
    def families(self) -> tuple:
        """The families this model has: no torsional ones without the twist field."""
        return tuple(f for f in FAMILIES[:-1] if self.twist or f != "torsional")

    def default_target(self) -> float:
        T = max(self.mean_tension_value, 0.0)
        est = analytic_frequencies(self.q, T, 1, self.twist)
        return 0.25 * min(v[0] for v in est.values())

    def finite_eigenvalue_count(self) -> int:
        """2 (n - n_bc): the number of finite eigenvalues of (*)."""
        n_bc = self.comm.allreduce(
            sum(bc.dof_indices()[1] for bc in self.bcs), op=MPI.SUM)
        return 2 * (self.rod.dof_count() - n_bc)

    def solve(self, nev: int | None = None, per_family: int = 3, target: float | None = None,
              keep_vectors: bool = True, zero_tol: float = 1e-3,
              require_families: bool = True) -> list[Mode]:
        """The modes nearest the target: at least the lowest ``per_family`` of
        each family (unless ``nev`` is given), sorted by |lambda|.

        Raises SolverError if fewer than nev eigenpairs converge, or (when nev
        is not given and ``require_families``) if a family has fewer than
        ``per_family`` modes; ``self.missing`` lists such families either way.
        ``zero_tol`` (relative to the target) separates the rigid zero."""
        start = time.perf_counter()
        if self.K is None:
            self.linearise()
        check_families = nev is None
        finite = self.finite_eigenvalue_count()
        nev = min(nev or self.default_nev(per_family), finite - 2)
        tau = self.default_target() if target is None else target
        for attempt, factor in enumerate((1.0, 1.37, 0.61, 2.3, 0.37)):
            pep = create_pep(self.comm, [self.K, self.C, self.M], nev, tau * factor, finite,
                             ncv_extra=7 * attempt)
            try:
                pep.solve()
                break
            except PETSc.Error as err:
                # LAPACK's Schur reordering (trexc) can fail on nearly equal
                # eigenvalues (the in- and out-of-plane lateral pairs); another
                # target changes the projected problem
                if attempt == 4:
                    raise SolverError(f"{self.scene}: SLEPc PEP failed ({err}) for the targets "
                                      f"tried; try -rawehelix_pep_target or other N") from None
        reason = pep.getConvergedReason()
        nconv = pep.getConverged()
        nev_used = pep.getDimensions()[0]
        if reason < 0 or nconv < nev_used:
            raise SolverError(
                f"{self.scene}: SLEPc PEP found {nconv} of {nev_used} eigenpairs "
                f"(reason {reason}) after {pep.getIterationNumber()} restarts. Try "
                f"-rawehelix_pep_ncv {2 * nev_used + 20}, -rawehelix_pep_max_it 2000 "
                f"or a target nearer the wanted modes (-rawehelix_pep_target).")
        tau = pep.getTarget()
        modes = self._collect(pep, nconv, keep_vectors, zero_tol * abs(tau) * 4)
        pep.destroy()
        found = {f: sum(m.family == f for m in modes) for f in self.families}
        self.missing = {f: k for f, k in found.items() if k < per_family} if check_families else {}
        if self.missing and require_families:
            raise SolverError(
                f"{self.scene}: the lowest {per_family} modes of each family were asked for, "
                f"but only {self.missing} were found among {nconv} eigenpairs (the "
                f"discretisation may be too coarse: --elements, --degree; or raise "
                f"-rawehelix_pep_nev).")
        self.wall_s = time.perf_counter() - start
        return modes

    def _collect(self, pep, nconv: int, keep_vectors: bool, zero_abs: float) -> list[Mode]:
        xr, xi = self.K.createVecRight(), self.K.createVecRight()
        modes, rigid = [], None
        for i in range(nconv):
            lam = complex(pep.getEigenpair(i, xr, xi))
            if lam.imag < -1e-12 * max(abs(lam), 1.0) and abs(lam) >= zero_abs:
                continue  # the conjugate of a mode kept
            fractions, comps = self.energy_fractions(xr, xi)
            error = pep.computeError(i)
            if abs(lam) < zero_abs:
                if fractions["torsional"] < 0.99:
                    raise SolverError(f"{self.scene}: a zero eigenvalue {lam:.3e} that is not a "
                                      f"rigid rotation (fractions {fractions})")
                if rigid is not None:
                    continue  # the Jordan partner of the rigid rotation
                family = "rigid"
                lam = complex(lam.real, abs(lam.imag))
            else:
                family = self.family(lam, xr, xi, fractions)
            top = max(comps.values())
            mode = Mode(eigenvalue=lam, family=family, fractions=fractions,
                        dominant=[c for c in COMPONENTS if comps[c] >= 0.5 * top], error=error,
                        vectors=(xr.copy(), xi.copy()) if keep_vectors else None)
            if family == "rigid":
                rigid = mode
            modes.append(mode)
        modes.sort(key=lambda m: (abs(m.eigenvalue), -m.eigenvalue.imag))
        return modes

    def family(self, lam: complex, xr, xi, fractions: dict) -> str:
        """Torsional if the twist block resonates (:meth:`block_residuals`),
        else the centre-line family with the largest kinetic energy."""
        rho = self.block_residuals(lam, xr, xi)
        if rho["twist"] < rho["centre_line"]:
            return "torsional"
        lateral = {k: v for k, v in fractions.items() if k != "torsional"}
        return max(lateral, key=lateral.get)

    # -- classification ------------------------------------------------------------------
    def _twist_mask(self) -> np.ndarray:
        """Boolean mask of the owned alpha dofs in a PETSc vector of W."""
        if getattr(self, "_mask", None) is None:
            W = self.rod.W
            n_owned = W.dofmap.index_map.size_local * W.dofmap.index_map_bs
            _, parent = compat.collapse(W.sub(1))
            parent = np.asarray(parent)
            mask = np.zeros(n_owned, dtype=bool)
            mask[parent[parent < n_owned]] = True
            self._mask = mask
        return self._mask

    def block_residuals(self, lam: complex, xr, xi) -> dict:
        """Relative residuals of the centre-line and twist blocks of (*).

        For x_b = x restricted to block b (r or alpha), and P_bb the diagonal
        block of P(lambda) = lambda^2 M + lambda C + K:

            rho_b = |P_bb x_b| / (|K_bb x_b| + |lambda|^2 |M_bb x_b|).

        A block whose own dynamics resonates at lambda has rho_b ~ 0; a block
        that is only driven by the other one has rho_b = O(1) (its residual is
        the coupling force).  This decides between centre line and twist when
        the coupling is one-sided: with the gamma coupling of Eq. (34) on, an
        out-of-plane motion y drives alpha through D gamma ~ y_sss / kappa
        (kappa ~ 0.02 for Table 2), while alpha drives the centre line only
        through the weak beta tau (r' x r'') of Eq. (32); the lateral mode then
        has most of its kinetic energy in alpha, but it is the centre line that
        resonates (and its damping is the lateral drag).  A block that does not
        move at all has rho_b = inf."""
        mask = self._twist_mask()
        out = {}
        for name, keep in (("centre_line", ~mask), ("twist", mask)):
            parts = []
            for x in (xr, xi):
                y = x.copy()
                y.array[~keep] = 0.0
                parts.append(y)
            prod = {}
            for key, A in (("K", self.K), ("C", self.C), ("M", self.M)):
                pr, pi = A.createVecLeft(), A.createVecLeft()
                A.mult(parts[0], pr)
                A.mult(parts[1], pi)
                prod[key] = pr.array[keep] + 1j * pi.array[keep]
            residual = lam**2 * prod["M"] + lam * prod["C"] + prod["K"]

            def norm(z):
                return math.sqrt(self.comm.allreduce(float(np.sum(np.abs(z)**2)), op=MPI.SUM))

            scale = norm(prod["K"]) + abs(lam)**2 * norm(prod["M"])
            out[name] = norm(residual) / scale if scale > 0 else math.inf
        return out

    def energy_fractions(self, xr, xi):
        """(family fractions, component energies) of the eigenvector xr + i xi."""
        y = self.K.createVecRight()

        def energy(A):
            A.mult(xr, y)
            e = y.dot(xr)
            A.mult(xi, y)
            return e + y.dot(xi)

        fam = {k: energy(A) for k, A in self._energy["family"].items()}
        total = sum(fam.values()) or 1.0
        comps = {k: energy(A) for k, A in self._energy["component"].items()}
        return {k: e / total for k, e in fam.items()}, comps

    def bc_amplitude(self, mode: Mode) -> float:
        """max |x_i| over the Dirichlet dofs relative to max |x|: 0 for every mode."""
        xr, xi = mode.vectors
        dofs = np.concatenate([bc.dof_indices()[0][:bc.dof_indices()[1]] for bc in self.bcs])
        with xr.localForm() as a, xi.localForm() as b:
            amp = np.hypot(a.array, b.array)
            local_bc = float(amp[dofs].max()) if dofs.size else 0.0
        return self.comm.allreduce(local_bc, op=MPI.MAX) / max(xr.norm(PETSc.NormType.INFINITY),
                                                               xi.norm(PETSc.NormType.INFINITY))

    # -- mode shapes on rank 0 ----------------------------------------------------------
    def mode_shape(self, mode: Mode):
        """(s, u (n, 3), alpha (n,)) on rank 0, None elsewhere: the eigenvector
        rotated in the complex plane to make its largest entry real, real part,
        scaled to max(|u|, |alpha|) = 1 (|u| the length of the displacement of r)."""
        xr, xi = mode.vectors
        parts = []
        for x in (xr, xi):
            f = dolfinx.fem.Function(self.rod.W)
            x.copy(compat.petsc_vec(f))
            f.x.scatter_forward()
            ur = f.sub(0).collapse()
            ua = f.sub(1).collapse()
            ur = ur[0] if isinstance(ur, tuple) else ur
            ua = ua[0] if isinstance(ua, tuple) else ua
            s, u = fields.gather(ur)
            _, a = fields.gather(ua)
            parts.append((s, u, a))
        if self.comm.rank != 0:
            return None
        s = parts[0][0]
        u = parts[0][1] + 1j * parts[1][1]
        a = parts[0][2][:, 0] + 1j * parts[1][2][:, 0]
        flat = np.concatenate([u.ravel(), a])
        phase = flat[np.argmax(np.abs(flat))]
        phase = phase / abs(phase) if abs(phase) > 0 else 1.0
        u, a = (u / phase).real, (a / phase).real
        scale = max(np.linalg.norm(u, axis=1).max(), np.abs(a).max()) or 1.0
        return s, u / scale, a / scale


def create_pep(comm, operators, nev: int, target: float, finite: int, prefix: str = "rawehelix_",
               ncv_extra: int = 0):
    """A TOAR PEP with shift-and-invert about a real target; options from ``prefix``."""
    from slepc4py import SLEPc
    pep = SLEPc.PEP().create(comm)
    pep.setOptionsPrefix(prefix)
    pep.setOperators(operators)
    pep.setProblemType(SLEPc.PEP.ProblemType.GENERAL)
    ncv = min(max(2 * nev, nev + 30) + ncv_extra, finite)
    pep.setDimensions(nev=nev, ncv=ncv)
    pep.setTarget(target)
    pep.setWhichEigenpairs(SLEPc.PEP.Which.TARGET_MAGNITUDE)
    lu = {"st_" + k: v for k, v in lu_options(comm).items()}
    with default_options(prefix, {**PEP_DEFAULTS, **lu}):
        pep.setFromOptions()  # -rawehelix_pep_*, -rawehelix_st_*
        pep.getST().getKSP().setFromOptions()
        pep.getST().getKSP().getPC().setFromOptions()
    return pep
