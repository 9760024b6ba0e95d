"""The dynamics' compiled steps (issue 46), ``-rawehelix_ts_compiled 1``: the
DynamicsSolver's integration between its outputs by
:class:`~rawehelix.solvers.compiled_step.CompiledChordAlpha` instead of PETSc TS
(:class:`~rawehelix.solvers.compiled_step.CompiledAdvance`, which registers itself
in ``dynamics.ADVANCES`` when imported: studies/simulate.py and solvers/forced.py
import it when the option is given).  This module is what the DynamicsSolver
asks before it builds anything: the option and what it refuses.

The scheme is TSALPHA2's (same rho_inf, same start, same fixed steps), so a run
gives TS's numbers to the Newton tolerance (tests/test_compiled_steps.py); the
TS keeps the state (its solution vectors and time are set after every stretch of
steps), so the outputs, the states and the failures go through the solver as
before.  One rank, alpha2 with fixed steps (a moving end's default): anything
else is refused before the run.

The machine and the weather (issues 43, 44) step alike (tests/test_compiled_weather.py):
the wind in time, the rotor's wind and a start-up's release ramp are Constants the
formulation's set_time sets at each stage time, which the compiled steps read; the
rotor's and generator's torques, the rotor's spin inertia and a lifted top's terms are
integrals of the same forms (compiled_forms.py assembles their end facets); the
per-step work of a run with a machine (the energy account, the rotor's table check, the
release latch) is the solver's ``on_step``/``_accepted``, called after each step as
TS calls it.  A weather scene steps adaptively unless asked: the compiled steps need
``-rawehelix_ts_adapt_type none`` (the step ``time.dt_s``).
"""

from __future__ import annotations

from rawehelix import section_laws
from rawehelix.errors import SceneError, SolverError

OPTION = "-rawehelix_ts_compiled"


def loop_tension(params) -> bool:
    """True if the compiled loop's T(0), the solid's sigma (|D U| - 1)
    (rod_operator.tension_map), is the section's: not for a law of its own (the
    tensegrity's N(eps) was 8e-7 off at turbulent_rated's start, N = 8), whose runs take
    T(0) from the probe after each step (solvers/forced.py)."""
    return not section_laws.get(params.model.section.law).nonlinear


def refusal(ts_type: str, adapt: str, comm_size: int, end_twist) -> str | None:
    """Why the compiled steps cannot run this solver (None: they can)."""
    if comm_size > 1:
        return "run on one rank (drop it, or run without mpirun)"
    if ts_type != "alpha2":
        return f"steps alpha2 only, not -rawehelix_ts_type {ts_type}"
    if adapt != "none":
        return ("take fixed steps: add -rawehelix_ts_adapt_type none (the step is time.dt_s; "
                "a scene with a moving upper end takes them by default)")
    if end_twist is not None:
        return "does not run the prescribed end twist of the torsion test"
    return None


def wanted(prefix: str, ts_type: str, comm_size: int, end_twist) -> bool:
    """True if the options ask for the compiled steps (``-{prefix}ts_compiled``); a
    SceneError (bad input, exit 2) if they cannot run this solver (:func:`refusal`)."""
    from petsc4py import PETSc
    options = PETSc.Options()
    if not options.getBool(prefix + "ts_compiled", False):
        return False
    why = refusal(ts_type, options.getString(prefix + "ts_adapt_type", "basic"), comm_size,
                  end_twist)
    if why:
        raise SceneError("PETSc options", OPTION, f"the compiled steps {why}")
    return True


def check_loaded(advances: dict):
    """Raise unless solvers/compiled_step.py has registered the compiled steps."""
    if "compiled" not in advances:
        raise SolverError(f"{OPTION}: the compiled steps are not loaded "
                          f"(import rawehelix.solvers.compiled_step first)")
