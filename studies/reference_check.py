"""The stationary state's independent reference, checked where it applies and within
a budget: the shooting solution of Sys. (67) (model.kinematics = "paper"), of the
extensible elastica ("extensible", with the EI law) or of the shearable rod
("shearable"), references/.

A reference check never replaces the result it checks: :func:`solve` gives a
:class:`Check` whose ``status`` is one of

* ``"compared"`` (``reference`` holds the solution),
* ``"not applicable: WHY"``: the scene is outside what the reference models (off the
  x-z plane, another section law, a twisted state, ...), decided before any work;
* ``"did not converge: WHY"``: its root finder failed, or it ran past
  :data:`BUDGET_S` of wall time (``references.shooting.budget``),

and the command prints and stores that status beside its own numbers
(``stationary``'s summary.json ``shooting``; ``converge``'s ``reference.independent_status``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

from rawehelix.models import kinematics
from rawehelix.parameters import Parameters

#: the wall time one reference solve may take [s]; the shooting of a scene it models
#: takes 0.1-3 s (Table 2, 7 segments: 2.5 s at most)
BUDGET_S = 20.0
COMPARED = "compared"


@dataclass(frozen=True)
class Check:
    reference: object | None  # the reference's solution (normalised), or None
    status: str  # COMPARED, "not applicable: ..." or "did not converge: ..."

    @property
    def compared(self) -> bool:
        return self.status == COMPARED


@dataclass(frozen=True)
class Reference:
    """An independent stationary reference (references/): ``solve(normalised)`` its
    solution, ``not_applicable(params)`` why it does not model a scene, or None."""

    solve: Callable
    not_applicable: Callable = lambda params: None


def too_many_segments(params: Parameters) -> str | None:
    """Why Sys. (67)'s shooting does not fit the budget, or None."""
    from rawehelix.references import shooting
    q = params.normalised()
    if shooting.default_segments(q) > shooting.MAX_SEGMENTS:
        return (f"Sys. (67)'s axial mode grows like exp(sqrt(sigma/mu)) = "
                f"e^{math.sqrt(q.sigma / q.mu):.0f} along the rod: its shooting needs "
                f"{shooting.default_segments(q)} segments, more than the {shooting.MAX_SEGMENTS} that fit "
                f"the check's budget of {BUDGET_S:g} s (a larger helix.EI_Nm2 needs fewer)")
    return None


def references() -> dict[str, Reference]:
    """The references by the name a kinematics gives them
    (models/kinematics.py::Kinematics.reference)."""
    from rawehelix.references import drag, shooting, shooting_shear
    return {"shooting": Reference(shooting.solve, too_many_segments),
            "extensible_elastica": Reference(shooting.solve_extensible,
                                             drag.uniform_load_only),
            "shearable_elastica": Reference(shooting_shear.solve_shearable,
                                            lambda p: drag.uniform_load_only(p)
                                            or shooting_shear.not_applicable(p))}


def reference_of(params: Parameters) -> Reference:
    """The reference that the kinematics of ``params`` names."""
    return references()[kinematics.of(params).reference]


def not_applicable(params: Parameters, twisted: bool = False) -> str | None:
    """Why no reference models the stationary state of ``params`` (``twisted``: the
    state carries the ends' torque), or None."""
    from rawehelix import section_laws
    from rawehelix.references import shooting
    law = params.value("section.law")
    if params.lifter.active:
        return ("lifter.top = 'lifted': the references hold the top end fixed (the lifted "
                "top's check is the elastic catenary, tests/test_lifted.py)")
    if twisted:
        return ("the state is twisted by the ends' torque (torque.top_Nm), and the "
                "references are torque-free, planar rods")
    if section_laws.get(law).nonlinear:
        return (f"section.law = {law!r}: the references model the solid section "
                "(helix.EA_N, helix.EI_Nm2)")
    if not params.model.bending:
        return "model.bending = false: the references need a bending stiffness"
    return (reference_of(params).not_applicable(params)
            or shooting.not_applicable(params.normalised()))


def solve(params: Parameters, comm=None, twisted: bool = False,
          budget_s: float = BUDGET_S) -> Check:
    """The reference of ``params``' kinematics where it applies, stopped after
    ``budget_s`` of wall time.  With ``comm`` every rank solves it and all agree on
    the status (rank 0's words)."""
    from rawehelix.references import shooting
    why = not_applicable(params, twisted)
    if why is not None:
        return Check(None, f"not applicable: {why}")
    solve_reference = reference_of(params).solve
    reference, status = None, COMPARED
    try:
        with shooting.budget(budget_s):
            reference = solve_reference(params.normalised())
    except shooting.OverBudget:
        status = f"did not converge: stopped after its budget of {budget_s:g} s of wall time"
    except (RuntimeError, ValueError, ArithmeticError) as err:
        # one line (scipy's messages hold newlines), without the advice to the API's
        # callers (shooting.solve's segments, which no command sets)
        why = " ".join(str(err).split()).replace("; try more segments", "")
        status = f"did not converge: {why.removeprefix('shooting did not converge: ')}"
    if comm is not None:
        statuses = comm.allgather(status)
        failed = [s for s in statuses if s != COMPARED]
        if failed:
            return Check(None, failed[0])
    return Check(reference, status)
