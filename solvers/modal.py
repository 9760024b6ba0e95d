"""Natural modes of a stationary state: the linearised Eqs. (30)-(31) with SLEPc.

:class:`ModalSolver` composes the pieces, each in its own module:

* :mod:`.linearise`: K, C, M of (lambda^2 M + lambda C + K) x = 0 (*) about a
  given state (:class:`~rawehelix.solvers.state.RodState`), fixed ends, free twist;
* :mod:`.pep`: the SLEPc PEP (TOAR, shift-and-invert about a real target);
* :mod:`.classify`: the family of each mode (block residuals, energy fractions);
* :mod:`.analytic`: the classical spectra that place the target and size the
  Krylov space.

The solver takes a state and does not solve for one:
``ModalSolver(params, rod=...).linearise(state)``; the usual path is
:meth:`ModalSolver.from_stationary`, which solves the stationary state of
Sec. 5.1 with :class:`StationarySolver` (alpha(0) = 0 pinned, where the Newton
matrix is regular) and linearises about it on the same rod (the modal bcs
leave the twist free).

Target and size (the search window): :mod:`.modal_window`.  After the solve
every family is checked; a missing one widens the search (nev x WIDEN_FACTOR,
WIDENINGS times, never past the window's ``cap``, the estimated count before the
nearest real root), then raises an error naming the option to raise
(``-rawehelix_pep_nev``).  A real eigenvalue is reported as ``overdamped``
(families.is_overdamped), not as a mode of its family.

The rigid rotation alpha = const is the zero eigenvalue of torque-free ends
(a Jordan pair: alpha = const and alpha = t), reported once as ``rigid``.

Accuracy: the fourth-order operator limits the attainable accuracy of the
lateral modes on fine meshes (round-off ~ eps N^4, 1e-3 at N = 512, p = 3);
see docs/explanation/modal_convergence.md.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.fem

from rawehelix import compat
from rawehelix.families import OVERDAMPED, VIBRATIONS, is_overdamped
from rawehelix.parameters import Parameters
from rawehelix.solvers import analytic, fields, pep as pep_solve
from rawehelix.solvers.classify import Classifier
from rawehelix.solvers.discrete import RodDiscretisation
from rawehelix.solvers.linearise import COMPONENTS, Linearisation
from rawehelix.solvers.modal_window import (  # noqa: F401  (re-exported: the window's names)
    TARGET_SPAN, TARGET_STEPS, WINDOW_EXTRA, WINDOW_MARGIN, Window, estimates, search_window)
from rawehelix.solvers.snes import SolverError
from rawehelix.solvers.state import RodState
from rawehelix.solvers.stationary import StationarySolver

#: widenings of the search (nev x WIDEN_FACTOR) when a family has fewer modes than asked
WIDENINGS = 3
WIDEN_FACTOR = 2.0


@dataclass
class Mode:
    """One mode: an eigenvalue with Im >= 0 stands for its conjugate pair."""

    eigenvalue: complex  # normalised (1 / t_scale units)
    family: str
    fractions: dict  # energy fraction per family (without "rigid")
    dominant: list  # components x, y, z, alpha with energy >= 0.5 of the largest
    error: float  # relative backward error |P(lambda) x| / (...) from SLEPc
    vectors: tuple = field(repr=False, default=None)  # (Re x, Im x) PETSc vectors


class ModalSolver:
    """The linearisation (K, C, M) of one scene about a state and its PEP (*).

    Parameters
    ----------
    params : validated scene parameters (scheme ``fe``).
    comm : MPI communicator; the spectrum does not depend on its size.
    scene : name used in error messages.
    rod : the discretisation to share (e.g. a StationarySolver's); a new one
        by default.
    ends : the end components' lumped terms (forms/end_loads.py), or None.
    """

    def __init__(self, params: Parameters, comm=MPI.COMM_WORLD, scene: str = "scene",
                 rod: RodDiscretisation | None = None, ends=None):
        self.params, self.comm, self.scene = params, comm, scene
        self.rod = rod if rod is not None else RodDiscretisation(params, comm)
        self.q = self.rod.q
        self.lin = Linearisation(self.rod, ends)
        self.classifier = None
        self.stationary_result = None
        self.mean_tension_value = None
        self.missing = {}

    @classmethod
    def from_stationary(cls, params: Parameters, comm=MPI.COMM_WORLD, scene: str = "scene",
                        end_torques: tuple | None = None) -> "ModalSolver":
        """Solve the stationary state (Sec. 5.1; ``end_torques`` = (ground, top),
        normalised by GJ / L0, Eqs. 38-39), linearise about it on the same rod
        and return the solver, with the state's result in ``stationary_result``."""
        stationary = StationarySolver(params, comm, scene=scene)
        if end_torques is not None:
            stationary.set_end_torques(*end_torques)
        result = stationary.solve()
        solver = cls(params, comm, scene=scene, rod=stationary.rod)
        solver.stationary_result = result
        solver.linearise(result.state)
        return solver

    # -- linearisation ------------------------------------------------------------------
    def linearise(self, state: RodState, spin: float = 0.0):
        """Assemble K, C, M (and the energy matrices) about ``state`` (with the
        uniform twist rate ``spin``, normalised, of a relative equilibrium); the
        rod holds the state afterwards.  Returns (K, C, M)."""
        K, C, M = self.lin.assemble(state, spin)
        if self.classifier is None:
            self.classifier = Classifier(self.lin)
        self.mean_tension_value = self.lin.mean_tension
        return K, C, M

    @property
    def K(self):
        return self.lin.K

    @property
    def C(self):
        return self.lin.C

    @property
    def M(self):
        return self.lin.M

    @property
    def bcs(self):
        return self.lin.bcs

    @property
    def twist(self) -> bool:
        return self.params.model.twist

    @property
    def families(self) -> tuple:
        """The families this model has: no torsional ones without the twist field."""
        return tuple(f for f in VIBRATIONS if self.twist or f != "torsional")

    def finite_eigenvalue_count(self) -> int:
        return self.lin.finite_eigenvalue_count()

    # -- target and size from the analytic spectra --------------------------------------
    def default_nev(self, per_family: int = 3, margin: float = 1.2) -> int:
        """Eigenvalues (both of each pair) to hold the lowest ``per_family``
        modes of every family."""
        T = max(self.mean_tension_value, 0.0)
        est = analytic.frequencies(self.q, T, per_family, self.twist)
        omega = margin * max(v[-1] for v in est.values())
        return 2 * analytic.count_below(self.q, T, omega, self.twist) + 2 + 4

    def default_target(self) -> float:
        """omega_min / 4: off the rigid zero, below every mode."""
        T = max(self.mean_tension_value, 0.0)
        est = analytic.frequencies(self.q, T, 1, self.twist)
        return 0.25 * min(v[0] for v in est.values())

    def window(self, per_family: int = 3) -> Window:
        """The target and nev that hold the lowest ``per_family`` oscillating
        modes of each family with the fewest others (:mod:`.modal_window`)."""
        finite = self.finite_eigenvalue_count()
        per_component = finite // (2 * len(COMPONENTS)) + 1  # modes of one family
        est = estimates(self.q, max(self.mean_tension_value, 0.0), per_component, self.twist,
                        self.params.model.kinematics)
        return search_window(est, finite, self.default_target(), per_family)

    # -- the eigenproblem ---------------------------------------------------------------
    def solve(self, nev: int | None = None, per_family: int = 3, target: float | None = None,
              keep_vectors: bool = True, zero_tol: float = 1e-3,
              require_families: bool = True) -> list[Mode]:
        """The lowest ``per_family`` oscillating modes of each family and
        what else the search window holds (nev None: :meth:`window`), or the
        ``nev`` eigenvalues nearest the target (default omega_min / 4: the
        slowest); sorted by |lambda|.

        Raises SolverError if fewer than nev eigenpairs converge, or (when nev
        is not given and ``require_families``) if a family has fewer than
        ``per_family`` oscillating modes after WIDENINGS widenings;
        ``self.missing`` lists such families either way.  ``zero_tol``
        (relative to the lowest estimated omega) separates the rigid zero.  The user's
        -rawehelix_pep_nev and -rawehelix_pep_target (options) win over both."""
        if self.lin.K is None:
            raise RuntimeError(f"{self.scene}: linearise(state) before solve(), or use "
                               "ModalSolver.from_stationary")
        start = time.perf_counter()
        check_families = nev is None
        finite = self.finite_eigenvalue_count()
        if check_families:
            window = self.window(per_family)
        else:
            nev = min(nev, finite - 2)
            window = Window(target=self.default_target(), nev=nev, cap=nev)
        tau = window.target if target is None else target
        nev = window.nev
        zero_abs = zero_tol * 4 * self.default_target()  # zero_tol x omega_min
        for widening in range(WIDENINGS + 1):
            pep = pep_solve.solve(self.comm, [self.K, self.C, self.M], nev, tau, finite,
                                  self.scene)
            modes = self._collect(pep, keep_vectors, zero_abs)
            nconv, used = pep.getConverged(), pep.getDimensions()[0]
            self.search = {"target": pep.getTarget(), "nev": used, "solves": widening + 1}
            pep.destroy()
            found = {f: sum(m.family == f for m in modes) for f in self.families}
            self.missing = ({f: k for f, k in found.items() if k < per_family}
                            if check_families else {})
            if not self.missing or used != nev or nev >= window.cap:
                break  # complete; or the user's -rawehelix_pep_nev; or nothing left to widen
            nev = min(window.cap, math.ceil(WIDEN_FACTOR * nev))
        if self.missing and require_families:
            raise SolverError(
                f"{self.scene}: the lowest {per_family} oscillating modes of each family were "
                f"asked for, but only {self.missing} were found among {nconv} eigenpairs "
                f"(target {self.search['target']:.4g}, nev {self.search['nev']}; the "
                f"discretisation may be too coarse: --elements, --degree; the family may have "
                f"fewer oscillating modes (overdamped); or raise -rawehelix_pep_nev).")
        self.wall_s = time.perf_counter() - start
        return modes

    def _collect(self, pep, keep_vectors: bool, zero_abs: float) -> list[Mode]:
        xr, xi = self.K.createVecRight(), self.K.createVecRight()
        modes, rigid = [], None
        for i in range(pep.getConverged()):
            lam = complex(pep.getEigenpair(i, xr, xi))
            if lam.imag < -1e-12 * max(abs(lam), 1.0) and abs(lam) >= zero_abs:
                continue  # the conjugate of a mode kept
            fractions, comps = self.classifier.energy_fractions(xr, xi)
            if abs(lam) < zero_abs:
                if not self.is_rigid_rotation(fractions):
                    raise SolverError(f"{self.scene}: a zero eigenvalue {lam:.3e} that is not a "
                                      f"rigid rotation (fractions {fractions})")
                if rigid is not None:
                    continue  # the Jordan partner of the rigid rotation
                family = "rigid"
                lam = complex(lam.real, abs(lam.imag))
            elif is_overdamped(lam):
                family = OVERDAMPED  # a real root: no oscillation, no family's mode
                lam = complex(lam.real, 0.0)  # reported as the real root it is
            else:
                family = self.classifier.family(lam, xr, xi, fractions)
            mode = Mode(eigenvalue=lam, family=family, fractions=fractions,
                        dominant=self.classifier.dominant(comps), error=pep.computeError(i),
                        vectors=(xr.copy(), xi.copy()) if keep_vectors else None)
            if family == "rigid":
                rigid = mode
            modes.append(mode)
        modes.sort(key=lambda m: (abs(m.eigenvalue), -m.eigenvalue.imag))
        return modes

    # -- classification and checks ------------------------------------------------------
    def is_rigid_rotation(self, fractions: dict) -> bool:
        """A zero eigenvalue is the rigid rotation alpha = const: its vector's kinetic
        energy is the twist's."""
        return fractions["torsional"] >= 0.99

    def block_residuals(self, lam: complex, xr, xi) -> dict:
        return self.classifier.block_residuals(lam, xr, xi)

    def energy_fractions(self, xr, xi):
        return self.classifier.energy_fractions(xr, xi)

    def bc_amplitude(self, mode: Mode) -> float:
        """max |x_i| over the Dirichlet dofs relative to max |x|: 0 for every mode."""
        xr, xi = mode.vectors
        dofs = np.concatenate([bc.dof_indices()[0][:bc.dof_indices()[1]] for bc in self.bcs])
        with xr.localForm() as a, xi.localForm() as b:
            amp = np.hypot(a.array, b.array)
            local_bc = float(amp[dofs].max()) if dofs.size else 0.0
        return self.comm.allreduce(local_bc, op=MPI.MAX) / max(xr.norm(PETSc.NormType.INFINITY),
                                                               xi.norm(PETSc.NormType.INFINITY))

    # -- on rank 0 ----------------------------------------------------------------------
    def centre_line(self):
        """(s, r (n, 3)) of the state linearised about, on rank 0 ((None, None) elsewhere)."""
        return self.rod.gather_centre_line()

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
            ur = f.sub(self.rod.model.index("centre_line")).collapse()
            ua = f.sub(self.rod.model.index("twist")).collapse()
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
