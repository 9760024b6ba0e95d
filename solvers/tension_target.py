"""``ends.tension_N`` -> ``ends.elongation``: the elongation eps0 whose stationary
state (Sec. 5.1) has the scene's tension as its mean along s,

    T_mean(eps0) = int_0^1 T(s~) ds~ = T_scene / (M g)        (Eq. 29),

found by a secant iteration on eps0 around Newton solves of the stationary state
(solvers/stationary.py), started from the weightless straight rod's eps0 = T / EA.
The state is the torque-free one with the upper end at its circle's centre (Eq. 70,
R1 = 0), on the scene's own discretisation: the one every command starts from.

:func:`resolve` is the one place a scene's elongation is found: the command line and
the API run it on every scene before they solve (a scene with ``ends.elongation``
passes unchanged).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from mpi4py import MPI

from rawehelix.errors import SolverError
from rawehelix.parameters import Parameters

#: the mean tension is met to this relative mismatch
RTOL = 1e-10
#: secant steps before the search gives up (a taut rod needs 3-5: T_mean is
#: nearly linear in eps0, with slope EA)
MAX_ITERATIONS = 30
#: where the tension is met, as summary.json and the printed line say it
WHERE = "mean over s of the torque-free state"


@dataclass(frozen=True)
class TensionTarget:
    """The result of the search: the elongation found and what it gives."""

    tension_N: float  # the scene's ends.tension_N [N]
    elongation: float  # eps0 found
    mean_tension_N: float  # the stationary state's mean tension at that eps0 [N]
    iterations: int  # stationary solves
    where: str = WHERE

    def summary(self) -> dict:
        return {"tension_N": self.tension_N, "at": self.where, "elongation": self.elongation,
                "mean_tension_N": self.mean_tension_N, "stationary_solves": self.iterations}


def resolve(params: Parameters, comm=MPI.COMM_WORLD) -> Parameters:
    """``params`` with ``ends.elongation`` set: unchanged if it is already, else the
    elongation :func:`find` finds for ``ends.tension_N`` (which it keeps).  Collective."""
    if params.ends.resolved:
        return params
    found = find(params, comm)
    return dataclasses.replace(params, ends=dataclasses.replace(params.ends,
                                                                elongation=found.elongation))


def find(params: Parameters, comm=MPI.COMM_WORLD) -> TensionTarget:
    """The elongation whose stationary mean tension is ``params.ends.tension_N``.
    Raises SolverError (what to try) if a stationary solve fails or the secant
    iteration does not meet :data:`RTOL` in :data:`MAX_ITERATIONS` solves."""
    from rawehelix.solvers.stationary import StationarySolver, reduced

    T_N = params.ends.tension_N
    first = T_N / params.helix.EA_N  # the weightless straight rod: T = EA eps0
    trial = params.replace(ends={"elongation": first, "circle_radius_m": 0.0})
    solver = StationarySolver(trial, comm, scene=params.name, planar=reduced(trial))
    q0 = solver.rod.q
    target = T_N / q0.force_scale  # (29)
    history = []

    def mismatch(eps0: float) -> float:
        q = dataclasses.replace(q0, eps0=eps0)
        solver.rod.q = q
        solver.rod.set_top_position(q.top_position(0.0))  # (66)
        try:
            solver.solve()
        except SolverError as err:
            raise SolverError(
                f"ends.tension_N = {T_N:g} N: the stationary state at the trial elongation "
                f"{eps0:.6g} failed ({err}); a larger tension, or ends.elongation given "
                "directly, avoids it") from None
        history.append((eps0, solver.mean_tension()))
        return history[-1][1] - target

    x0, f0 = first, mismatch(first)
    x1 = first - f0 / q0.sigma  # a Newton step with dT/deps0 ~ sigma (EA)
    for _ in range(MAX_ITERATIONS):
        f1 = mismatch(x1)
        if abs(f1) <= RTOL * target:
            return TensionTarget(T_N, float(x1), float(q0.tension_N(history[-1][1])),
                                 len(history))
        slope = (f1 - f0) / (x1 - x0) if x1 != x0 else q0.sigma
        if not slope > 0:  # T_mean grows with eps0 on a taut rod
            slope = q0.sigma
        x0, f0, x1 = x1, f1, x1 - f1 / slope
        if not x1 > 0:
            x1 = 0.5 * x0
    raise SolverError(
        f"ends.tension_N = {T_N:g} N: no elongation found in {MAX_ITERATIONS} stationary "
        f"solves (last mean tension {q0.tension_N(history[-1][1]):.6g} N at eps0 = "
        f"{history[-1][0]:.6g}); give ends.elongation directly, or refine the mesh "
        "(--elements)")
