"""The quadratic eigenproblem (lambda^2 M + lambda C + K) x = 0 with SLEPc PEP.

TOAR (a Krylov method on the companion linearisation, stored in compact form)
with the shift-and-invert spectral transformation:

* TOAR works on the general (non-symmetric: drag, and the gamma coupling of
  Eq. 34 which has no potential) quadratic problem without forming the
  2n x 2n pencil; memory is n x (ncv + 2) instead of 2n x ncv;
* shift-and-invert factorises P(tau) = tau^2 M + tau C + K once (PETSc's LU
  in serial, MUMPS in parallel) and makes the eigenvalues nearest the target
  converge first;
* PETSc here is real, so the target tau is real.  The eigenvalues sit near
  the imaginary axis, |lambda - tau|^2 ~ tau^2 + omega^2, so a real target
  orders them by |lambda|: the slowest modes come first.

Options: prefix ``rawehelix_`` (``-rawehelix_pep_nev 40``,
``-rawehelix_pep_target 5``, ``-rawehelix_st_pc_factor_mat_solver_type``...).
"""

from __future__ import annotations

from petsc4py import PETSc

from rawehelix.solvers.snes import SolverError, default_options, lu_options

PEP_DEFAULTS = {
    "pep_type": "toar",
    "pep_tol": 1.0e-10,
    "pep_max_it": 500,
    "st_type": "sinvert",
    "st_ksp_type": "preonly",
    "st_pc_type": "lu",  # with lu_options(comm)
}

#: targets tried in turn, relative to the first: LAPACK's Schur reordering
#: (trexc) can fail on nearly equal eigenvalues (the in- and out-of-plane
#: lateral pairs); another target changes the projected problem
TARGET_FACTORS = (1.0, 1.37, 0.61, 2.3, 0.37)


def create_pep(comm, operators, nev: int, target: float, finite: int, prefix: str = "rawehelix_",
               ncv_extra: int = 0):
    """A TOAR PEP with shift-and-invert about a real target; options from ``prefix``.

    ``operators`` = [K, C, M]; ``finite`` bounds the subspace (the number of
    finite eigenvalues)."""
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


def solve(comm, operators, nev: int, target: float, finite: int, scene: str = "scene"):
    """Solve the PEP nearest ``target``, retrying the targets of TARGET_FACTORS
    (with a larger subspace each time) when SLEPc fails; returns the solved PEP
    (the caller destroys it).

    Raises SolverError if every target fails or fewer than nev pairs converge."""
    for attempt, factor in enumerate(TARGET_FACTORS):
        pep = create_pep(comm, operators, nev, target * factor, finite, ncv_extra=7 * attempt)
        try:
            pep.solve()
            break
        except PETSc.Error as err:
            pep.destroy()
            if attempt == len(TARGET_FACTORS) - 1:
                raise SolverError(f"{scene}: SLEPc PEP failed ({err}) for the targets "
                                  f"tried; try -rawehelix_pep_target or other N") from None
    reason, nconv = pep.getConvergedReason(), pep.getConverged()
    nev_used = pep.getDimensions()[0]
    if reason < 0 or nconv < nev_used:
        its = pep.getIterationNumber()
        pep.destroy()
        raise SolverError(
            f"{scene}: SLEPc PEP found {nconv} of {nev_used} eigenpairs "
            f"(reason {reason}) after {its} restarts. Try "
            f"-rawehelix_pep_ncv {2 * nev_used + 20}, -rawehelix_pep_max_it 2000 "
            f"or a target nearer the wanted modes (-rawehelix_pep_target).")
    return pep
