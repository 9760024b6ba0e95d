"""PETSc's options checked as PETSc checks them (``-options_left``), before the work.

PETSc ignores an option no solver asks for: ``-rawehelix_snes_maxit 5`` (a typo)
would change nothing, silently.  :func:`check` sets up one of each of
rawehelix's solvers, on nothing (no operators, no forms), with the options
prefixes and defaults the real ones use; every option they read is then
marked *used* in PETSc's database.  An option left unused is an error (or a
warning, ``unused="warn"``), named with what it could have meant; a value
PETSc refuses (``-rawehelix_snes_type nonexistent``) is an error with
PETSc's own reason.  Both are :class:`SceneError` (bad input, exit 2), raised
on every rank alike (the database is the same on every rank).

Options that only a solve or a factorisation reads (the viewers
``-rawehelix_snes_converged_reason``, ``-rawehelix_ksp_view``, MUMPS'
``-rawehelix_mat_mumps_icntl_14``) cannot be checked before the work
(:data:`AT_SOLVE`): :func:`left_after_run` lists those still unused at the
end of a run, for a warning.

The solvers' prefixes: the stationary Newton solver and the modes' PEP
``rawehelix_`` (``-rawehelix_snes_*``, ``-rawehelix_pep_*``, ``-rawehelix_st_*``),
the dynamics' TS ``rawehelix_`` and its SNES ``rawehelix_ts_``
(``-rawehelix_ts_snes_*``), the lab tests' Newton solver ``rawehelix_labtest_``,
the frequency response's LU ``rawehelix_response_``.
"""

from __future__ import annotations

import difflib
import logging
import re

from petsc4py import PETSc

from rawehelix import compat
from rawehelix.errors import SceneError

LABTEST_PREFIX = "rawehelix_labtest_"
RESPONSE_PREFIX = "rawehelix_response_"
#: options that PETSc itself reads at PetscFinalize, never during a run
AT_FINALIZE = ("options_left", "objects_dump", "malloc_dump", "memory_view", "options_view",
               "log_view", "log_summary", "log_trace", "log_all", "malloc_view")
#: options read only by a solve or a factorisation, after the set-up: the viewers
#: (-rawehelix_snes_converged_reason, -rawehelix_ksp_view) and the matrices' own
#: (-rawehelix_mat_mumps_icntl_14); checked at the end of the run (left_after_run)
AT_SOLVE = re.compile(r"_(view|converged_reason|final_residual|error_(absolute|relative|"
                      r"backward))(_|$)|(^|_)mat_")
#: the answer "did you mean" looks in besides the options used: common ones of each prefix
COMMON = ("snes_monitor", "snes_converged_reason", "snes_view", "snes_max_it", "snes_rtol",
          "snes_atol", "snes_stol", "snes_type", "snes_linesearch_type", "snes_linesearch_monitor",
          "ksp_type", "ksp_rtol", "ksp_monitor", "ksp_view", "ksp_converged_reason", "pc_type",
          "pc_factor_mat_solver_type", "pc_factor_mat_ordering_type", "ts_type", "ts_monitor",
          "ts_adapt_type", "ts_adapt_monitor", "ts_rtol", "ts_atol", "ts_max_snes_failures",
          "ts_max_reject", "ts_alpha_radius", "ts_view", "pep_type", "pep_tol", "pep_max_it",
          "pep_monitor", "pep_view", "st_type", "st_ksp_type", "st_pc_type")

log = logging.getLogger("rawehelix")


def _petsc_error(err: PETSc.Error, options: dict) -> SceneError:
    """PETSc's reason (the last line of its traceback, without ``[0]``) as bad
    input, naming the option whose value it quotes when there is one."""
    lines = [ln.split("]", 1)[-1].strip() for ln in str(err).splitlines() if ln.strip()]
    reason = lines[-1] if lines else f"PETSc error {err.ierr}"
    named = [f"-{k} {v}" for k, v in options.items() if v and f" {v}" in f" {reason} "]
    return SceneError("PETSc options", ", ".join(named) or "-" + " -".join(options),
                      f"{reason} (PETSc error {err.ierr})")


def _set_up(prefix: str, obj, defaults: dict, *inner):
    """``obj.setFromOptions()`` (and of its KSP, PC, ...) with ``defaults``, as the
    solvers do."""
    from rawehelix.solvers.snes import default_options
    with default_options(prefix, defaults):
        obj.setOptionsPrefix(prefix)
        obj.setFromOptions()
        for part in inner:
            part(obj).setFromOptions()


def probe():
    """Set up one solver of each kind rawehelix makes, on COMM_SELF, so that PETSc
    marks every option they read as used.  Raises PETSc.Error on a bad value."""
    from rawehelix.solvers.dynamics import PREFIX, TS_DEFAULTS
    from rawehelix.solvers.pep import PEP_DEFAULTS
    from rawehelix.solvers.snes import SNES_DEFAULTS, direct_solver, lu_options

    comm = PETSc.COMM_SELF  # serial LU reads a superset of MUMPS' set-up options
    lu = lu_options(comm)
    ksp_pc = (lambda s: s.getKSP(), lambda s: s.getKSP().getPC())
    made = []
    for prefix in (PREFIX, LABTEST_PREFIX):  # the stationary and the lab tests' Newton solver
        made.append(PETSc.SNES().create(comm))
        _set_up(prefix, made[-1], {**SNES_DEFAULTS, **lu}, *ksp_pc)
    made.append(PETSc.TS().create(comm))  # the dynamics (solvers/dynamics.py)
    _set_up(PREFIX, made[-1], TS_DEFAULTS)
    _set_up(PREFIX + "ts_", made[-1].getSNES(), {**SNES_DEFAULTS, **lu}, *ksp_pc)
    PETSc.Options().getReal(PREFIX + "ts_jacobian_reuse", 0.0)
    PETSc.Options().getBool(PREFIX + "ts_compiled", False)  # solvers/compiled_dynamics.py
    made.append(direct_solver(comm))  # the frequency response (solvers/response.py)
    _set_up(RESPONSE_PREFIX, made[-1], {})
    from slepc4py import SLEPc  # the modes (solvers/pep.py)
    made.append(SLEPc.PEP().create(comm))
    _set_up(PREFIX, made[-1], {**PEP_DEFAULTS, **{"st_" + k: v for k, v in lu.items()}},
            lambda p: p.getST().getKSP(), lambda p: p.getST().getKSP().getPC())
    for obj in made:
        obj.destroy()


def _user_options() -> dict:
    return {k: v for k, v in PETSc.Options().getAll().items()}


def unused(names=None) -> list[str]:
    """The options (without '-') in PETSc's database that nothing has read."""
    names = _user_options() if names is None else names
    return [n for n in names if not compat.petsc_option_used(n)]


def _meant(name: str, known: list[str]) -> str:
    """" (did you mean -x or --y?)" for the known options close to ``name``
    (``-elemnts``: ``--elements``), or ""."""
    close = difflib.get_close_matches(name, known, n=3, cutoff=0.75)
    return f" (did you mean {' or '.join(close)}?)" if close else ""


def check(unused_policy: str = "error", ours: tuple = ()):
    """Refuse (SceneError) a PETSc option no solver of rawehelix reads, or a value
    PETSc refuses; ``unused_policy="warn"``: log the unused ones instead.

    ``ours``: the command's own options (``--elements``), for "did you mean"."""
    options = _user_options()
    try:
        probe()
    except PETSc.Error as err:
        raise _petsc_error(err, options) from None
    left = [n for n in unused(options) if n not in AT_FINALIZE and not AT_SOLVE.search(n)]
    if not left:
        return
    used = [n for n in options if n not in left]
    prefixes = ("rawehelix_", "rawehelix_ts_", LABTEST_PREFIX, RESPONSE_PREFIX)
    known = ["-" + n for n in used] + [f"-{p}{c}" for p in prefixes for c in COMMON]
    named = ", ".join("-" + n + _meant("-" + n, known + list(ours)) for n in left)
    what = "no solver of rawehelix reads"
    for n in left:  # said here once: PETSc >= 3.19 would list them again at its finalize
        PETSc.Options().delValue(n)
    if unused_policy == "warn":
        log.warning("PETSc options %s: %s them", named, what)
        return
    raise SceneError("PETSc options", named, f"{what} them (to go on anyway: --petsc-unused warn)")


def left_after_run() -> list[str]:
    """The options still unused at the end of a run (those only a solve reads,
    :data:`AT_SOLVE`, which :func:`check` passes over), for a warning."""
    return [n for n in unused() if n not in AT_FINALIZE and AT_SOLVE.search(n)]
