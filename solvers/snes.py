"""A Newton solver (PETSc SNES) for a nonlinear form with Dirichlet conditions."""

from __future__ import annotations

import dolfinx.fem
import dolfinx.fem.petsc
import ufl
from petsc4py import PETSc

from rawehelix import compat
from rawehelix.errors import SolverError  # noqa: F401  (raised here, re-exported)

SNES_DEFAULTS = {
    "snes_type": "newtonls",
    # Full Newton steps: near convergence the residual of the fourth-order
    # bending term reaches a round-off floor that grows like N^3 (its Jacobian
    # entries grow like mu p^4 / h^3), where a backtracking line search gives
    # up.  FloorConvergence then declares convergence on the step.
    "snes_linesearch_type": "basic",
    "snes_rtol": 1.0e-10,
    "snes_atol": 1.0e-12,
    "snes_stol": 1.0e-12,
    "snes_max_it": 50,
    "ksp_type": "preonly",
    "pc_type": "lu",  # with lu_options(comm)
}


def lu_options(comm) -> dict:
    """The direct solver of every Newton step: PETSc's own LU in serial, MUMPS in parallel.

    On one process PETSc's LU with the natural ordering (the 1D dofmap is
    already banded) costs a third of MUMPS's per factorisation at N = 8 and
    stays linear in N.  PETSc 3.18's default nested-dissection ordering fails
    there with MPI_ERR_COMM (in ISInvertPermutation), hence "natural"."""
    if comm.size == 1:
        return {"pc_factor_mat_solver_type": "petsc", "pc_factor_mat_ordering_type": "natural"}
    return {"pc_factor_mat_solver_type": "mumps"}


def direct_solver(comm, A=None):
    """A KSP that is one LU solve with :func:`lu_options` (operators ``A`` if given)."""
    ksp = PETSc.KSP().create(comm)
    if A is not None:
        ksp.setOperators(A)
    ksp.setType("preonly")
    pc = ksp.getPC()
    pc.setType("lu")
    options = lu_options(comm)
    pc.setFactorSolverType(options["pc_factor_mat_solver_type"])
    if "pc_factor_mat_ordering_type" in options:
        pc.setFactorOrdering(options["pc_factor_mat_ordering_type"])
    return ksp


class temporary_options:
    """Put options into the PETSc database for one set-up; take them out afterwards.

    ``defaults=True``: only the keys the user has not set (on the command line,
    ``-rawehelix_snes_max_it 100`` etc.), so the user's options win.  Without
    it the given options win and the user's value comes back on exit.  Either
    way nothing leaks into the next solver's set-up (its defaults can differ:
    the Newton tolerance depends on N, the LU on the communicator)."""

    def __init__(self, prefix: str, options: dict | None, defaults: bool = False):
        self.prefix, self.options, self.defaults = prefix, options or {}, defaults

    def __enter__(self):
        opts = PETSc.Options()
        self.added = []
        for key, value in self.options.items():
            name = self.prefix + key
            old = opts.getString(name) if opts.hasName(name) else None
            if self.defaults and opts.hasName(name):
                continue
            self.added.append((name, old))
            opts[name] = value
        return self

    def __exit__(self, *exc):
        opts = PETSc.Options()
        for name, old in reversed(self.added):
            opts.delValue(name)
            if old is not None:
                opts[name] = old


def default_options(prefix: str, defaults: dict) -> temporary_options:
    """``with default_options(prefix, {...}):`` set up a solver with these defaults."""
    return temporary_options(prefix, defaults, defaults=True)


class FloorConvergence:
    """SNES convergence test: PETSc's default (rtol, atol, stol) plus the round-off floor.

    The residual of the fourth-order bending term cannot fall below
    ~eps |J| |x|, which grows like N^3 (and like 1/dt^2 in a time step); there
    Newton's steps shrink to noise while the residual stagnates.  A step below
    ``floor_step`` (relative to the state) that no longer lowers the residual,
    after at least three iterations, is convergence, not failure."""

    def __init__(self, floor_step: float = 1.0e-6):
        self.floor_step = floor_step

    def __call__(self, snes, it, norms):
        xnorm, ynorm, fnorm = norms
        rtol, atol, stol, _ = snes.getTolerances()
        R = PETSc.SNES.ConvergedReason
        if it == 0:
            self.f0 = self.fmin = fnorm
            self.on_floor = False  # True: the last solve was accepted by the floor test
            return R.CONVERGED_ITERATING
        if fnorm != fnorm:
            return R.DIVERGED_FNORM_NAN
        if fnorm <= atol:
            return R.CONVERGED_FNORM_ABS
        if fnorm <= rtol * self.f0:
            return R.CONVERGED_FNORM_RELATIVE
        if ynorm <= stol * xnorm:
            return R.CONVERGED_SNORM_RELATIVE
        floor = it >= 3 and ynorm <= self.floor_step * (1.0 + xnorm) and fnorm > 0.5 * self.fmin
        self.fmin = min(self.fmin, fnorm)
        self.on_floor = floor
        return R.CONVERGED_SNORM_RELATIVE if floor else R.CONVERGED_ITERATING


class ReusedJacobian(FloorConvergence):
    """Modified Newton for a time integrator: the Jacobian and its LU stay from
    one iteration and one step to the next until an iteration contracts |F|
    by less than ``rate``, or the shifts of the Jacobian (the 1/dt and 1/dt^2
    factors: a new step size) change; then the next Jacobian call rebuilds
    them.  A fixed step keeps the shifts fixed and the state moves little per
    step, so one LU serves many steps.  Convergence is judged as by
    :class:`FloorConvergence`, on the true residual: only the rate changes.

    The Jacobian callback asks :meth:`rebuild_for`; when it skips the assembly
    the matrix keeps its PETSc state and PCSetUp keeps the LU factors."""

    def __init__(self, rate: float = 0.1, floor_step: float = 1.0e-6):
        super().__init__(floor_step)
        self.rate = rate
        self.stale = True
        self.shifts = None
        self.rebuilds = 0

    def rebuild_for(self, shifts) -> bool:
        """True (and the Jacobian counts as fresh) if it must be rebuilt for these shifts."""
        if self.stale or shifts != self.shifts:
            self.stale, self.shifts = False, shifts
            self.rebuilds += 1
            return True
        return False

    def __call__(self, snes, it, norms):
        reason = super().__call__(snes, it, norms)
        fnorm = norms[2]
        if it > 0 and reason == PETSc.SNES.ConvergedReason.CONVERGED_ITERATING \
                and not fnorm <= self.rate * self.fprev:
            self.stale = True  # slow (or growing): a fresh Jacobian for the next iteration
        self.fprev = fnorm
        return reason


class NewtonSolver:
    """SNES on F(u; v) = 0 with bcs; the Jacobian is the UFL derivative of F."""

    def __init__(self, F: ufl.Form, u: dolfinx.fem.Function, bcs, prefix="rawehelix_",
                 J: ufl.Form | None = None, options: dict | None = None):
        self.u, self.bcs = u, bcs
        self.F = dolfinx.fem.form(F)
        self.J = dolfinx.fem.form(J if J is not None else ufl.derivative(F, u))
        self.b = compat.create_vector(self.F)
        self.A = compat.create_matrix(self.J)
        self.x = compat.petsc_vec(u).copy()
        comm = u.function_space.mesh.comm
        self.snes = PETSc.SNES().create(comm)
        self.snes.setOptionsPrefix(prefix)
        self.convergence = FloorConvergence()
        self.snes.setConvergenceTest(self.convergence)
        self.snes.setFunction(self._residual, self.b)
        self.snes.setJacobian(self._jacobian, self.A)
        with default_options(prefix, {**SNES_DEFAULTS, **lu_options(comm), **(options or {})}):
            self.snes.setFromOptions()
            self.snes.getKSP().setFromOptions()
            self.snes.getKSP().getPC().setFromOptions()
        self.prefix = prefix

    def _update(self, x):
        x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        x.copy(compat.petsc_vec(self.u))
        self.u.x.scatter_forward()

    def _residual(self, snes, x, b):
        self._update(x)
        with b.localForm() as b_local:
            b_local.set(0.0)
        dolfinx.fem.petsc.assemble_vector(b, self.F)
        compat.apply_lifting_and_bc(b, self.J, self.bcs, x, -1.0)

    def _jacobian(self, snes, x, A, P):
        A.zeroEntries()
        dolfinx.fem.petsc.assemble_matrix(A, self.J, self.bcs)
        A.assemble()

    def residual_norm(self) -> float:
        """|F(u)| at the current u with the bc rows (u - g)."""
        x = compat.petsc_vec(self.u).copy()
        self._residual(self.snes, x, self.b)
        return self.b.norm()

    def solve(self, what: str = "Newton solve") -> int:
        """Solve from the current u; return the iteration count or raise SolverError."""
        compat.petsc_vec(self.u).copy(self.x)
        self.snes.solve(None, self.x)
        reason = self.snes.getConvergedReason()
        its = self.snes.getIterationNumber()
        if reason <= 0:
            fnorm = self.snes.getFunctionNorm()
            raise SolverError(
                f"{what}: SNES did not converge (reason {reason_name(reason)}) after {its} "
                f"iterations, last residual norm {fnorm:.3e}. Try more elements (--elements), "
                f"a better first guess, or PETSc options such as -{self.prefix}snes_max_it 200 "
                f"-{self.prefix}snes_linesearch_type l2.")
        self._update(self.x)
        return its


def reason_name(reason: int, kind=None) -> str:
    """The name of a converged reason of ``kind`` (default PETSc.SNES.ConvergedReason)."""
    kind = PETSc.SNES.ConvergedReason if kind is None else kind
    names = {v: k for k, v in vars(kind).items() if isinstance(v, int)}
    return f"{names.get(reason, '?')} ({reason})"
