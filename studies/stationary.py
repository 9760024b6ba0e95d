"""The stationary state of Sec. 5.1, checked against shooting: :func:`compute`
returns a :class:`Stationary`; :meth:`Stationary.write` writes summary.json,
stationary.png and centre_line.xdmf.  Computing writes nothing."""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from mpi4py import MPI

from rawehelix.parameters import Parameters
from rawehelix.studies import structure_limits, writers
from rawehelix.studies.scene import SceneError

log = logging.getLogger("rawehelix")


@dataclass
class Stationary:
    """A stationary state in SI units (arrays on rank 0, None elsewhere)."""

    params: Parameters
    s_m: np.ndarray | None  # arc length of the centre-line nodes [m]
    centre_line_m: np.ndarray | None  # (n, 3) [m]; z points down (Sec. 2)
    s_tension_m: np.ndarray | None  # arc length of the tension nodes [m]
    tension_N: np.ndarray | None  # T(s) [N], Eq. (29)
    shooting_centre_line_m: np.ndarray | None  # the shooting reference at s_m [m]
    summary: dict = field(default_factory=dict)
    state: object = None  # the RodState (normalised) for solvers that take it
    rank: int = 0

    def write(self, outdir) -> Path:
        """summary.json, stationary.png (centre line and tension) and
        centre_line.xdmf (for ParaView) into ``outdir`` (rank 0 writes)."""
        outdir = Path(outdir)
        if self.rank != 0:
            return outdir
        outdir.mkdir(parents=True, exist_ok=True)
        title = self.params.title or self.params.name
        writers.centre_line_png(outdir / "stationary.png", self.s_m, self.centre_line_m,
                                self.s_tension_m, self.tension_N, title,
                                reference_x_m=self.shooting_centre_line_m)
        writers.centre_line_xdmf(outdir / "centre_line.xdmf", self.centre_line_m, {
            "s_m": self.s_m, "tension_N": np.interp(self.s_m, self.s_tension_m, self.tension_N)})
        writers.write_json(outdir / "summary.json", self.summary)
        return outdir


def solve(params: Parameters, comm=MPI.COMM_WORLD):
    """Newton alone (no shooting reference): ``(solver, result, planar)`` on the
    FE rod of :func:`compute` (the planar (x, z) rod where ``model.reduction``
    allows it); the parameter studies' stationary quantities take it."""
    from rawehelix.solvers.planar import planar_allowed
    from rawehelix.solvers.stationary import StationarySolver

    planar = params.model.reduction == "auto" and planar_allowed(params)
    solver = StationarySolver(params, comm, scene=params.name, planar=planar)
    return solver, solver.solve(), planar


def sag_m(params: Parameters, result) -> float:
    """The sag [m] of a stationary result: the centre line's largest distance from the chord."""
    from rawehelix.solvers.stationary import sag
    q = params.normalised()
    return q.L0 * sag(result.centre_line, q.top_position())


def limits_block(params: Parameters, solver) -> dict | None:
    """The ``limits`` block (studies/structure_limits.py) of the stationary solver's
    state (t = None), on rank 0 (None elsewhere).  Collective."""
    from rawehelix.solvers.probes import SectionProbe
    section = SectionProbe.of_rod(solver.rod).section()
    if section is None:
        return None
    tracker = structure_limits.of_params(params)
    structure_limits.add_normalised(tracker, params.normalised(), section)
    return tracker.block()


def compute(params: Parameters, comm=MPI.COMM_WORLD) -> Stationary:
    """Newton on the FE rod (the planar (x, z) rod where ``model.reduction``
    allows it), compared with the shooting solution of Sys. (67) (of the extensible
    elastica, references/shooting.py::solve_extensible, with model.kinematics = "extensible")
    where it applies: a scene off the x-z plane (the circle of Eq. 70) is solved
    without it, and ``summary["shooting"]`` says why."""
    from rawehelix.references import shooting, shooting_shear

    if params.discretisation.scheme != "fe":
        raise SceneError(params.name, "discretisation.scheme",
                         "'stationary' runs the FE scheme; the spline reference's stationary "
                         "state is part of 'modes'")
    start = time.perf_counter()
    q = params.normalised()
    disc = params.discretisation
    solver, result, planar = solve(params, comm)
    block = limits_block(params, solver)  # collective; before residual_at moves the state
    # the independent reference: Sys. (67), or the extensible elastica (with the EI law);
    # planar only: a scene off the x-z plane is reported without it
    not_applicable = shooting.not_applicable(q) or shooting_shear.not_applicable(params)
    reference = None
    if not_applicable is None:
        # the reference of each kinematics (model.kinematics), by name
        solve_reference = {"paper": shooting.solve, "extensible": shooting.solve_extensible,
                           "shearable": shooting_shear.solve_shearable}
        reference = solve_reference[params.model.kinematics](q)
        residual_at_shooting = solver.residual_at(  # collective
            reference.centre_line, getattr(reference, "director", None))
    out = Stationary(params, None, None, None, None, None, state=result.state, rank=comm.rank)
    summary = None
    if comm.rank == 0:
        x = q.length_m(result.centre_line)
        T = q.tension_N(result.tension)
        out.s_m, out.centre_line_m = q.length_m(result.s), x
        out.s_tension_m, out.tension_N = q.length_m(result.s_tension), T
        summary = {
            "scene": params.name,
            "elements": disc.elements,
            "degree": disc.degree,
            "mesh": disc.mesh,
            "dofs": solver.rod.dof_count(),
            "model": params.describe_model(planar),
            "ranks": comm.size,
            "newton_iterations": result.newton_iterations,
            "tension_N": {"s0": float(T[0]), "s1": float(T[-1]),
                          "min": float(T.min()), "max": float(T.max())},
            "sag_m": sag_m(params, result),
            "shooting": "compared" if reference else f"not applicable: {not_applicable}",
            "limits": block,
        }
        if reference:
            x_ref = q.length_m(reference.centre_line(result.s))
            out.shooting_centre_line_m = x_ref
            summary.update({
                "shooting_max_diff_m": float(np.max(np.linalg.norm(x - x_ref, axis=1))),
                "shooting_tension_s0_N": float(q.tension_N(reference.tension(0.0))),
                "residual_at_shooting": float(residual_at_shooting)})
        summary["wall_s"] = time.perf_counter() - start
        log.debug("%s: %s model, N = %d, p = %d: %d Newton iterations, %.2f s", params.name,
                 "planar" if planar else "full", disc.elements, disc.degree,
                 result.newton_iterations, summary["wall_s"])
    out.summary = comm.bcast(summary, root=0)
    return out


def report(result: Stationary) -> str:
    """The lines a user reads after a stationary solve."""
    s = result.summary
    T = s["tension_N"]
    head = (f"{s['scene']}: N = {s['elements']}, p = {s['degree']} "
            f"({s['model'].split(';')[0]}): {s['newton_iterations']} Newton iterations, "
            f"{s['wall_s']:.2f} s\n")
    if "shooting_tension_s0_N" not in s:
        return (head + f"  tension T(0) = {T['s0']:.3f} N, T(L0) = {T['s1']:.3f} N\n"
                f"  sag {s['sag_m']:.5f} m; shooting reference {s['shooting']}"
                + structure_limits.line(s.get("limits")))
    return (head + f"  tension T(0) = {T['s0']:.3f} N, T(L0) = {T['s1']:.3f} N "
            f"(shooting T(0) = {s['shooting_tension_s0_N']:.3f} N)\n"
            f"  sag {s['sag_m']:.5f} m; FE vs shooting max |dr| = {s['shooting_max_diff_m']:.3e} m; "
            f"FE residual at shooting = {s['residual_at_shooting']:.3e}"
            + structure_limits.line(s.get("limits")))
