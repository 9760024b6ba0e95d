"""`rawehelix stationary`: the stationary state of Sec. 5.1, checked against shooting."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

from rawehelix.parameters import Parameters
from rawehelix.solvers import shooting
from rawehelix.solvers.planar import planar_allowed
from rawehelix.solvers.stationary import StationarySolver, sag
from rawehelix.studies import writers


def run(params: Parameters, outdir: Path | None, name: str = "scene", title: str = "",
        comm=MPI.COMM_WORLD, log=print) -> dict:
    """Solve, compare with shooting, write summary.json, PNG and XDMF into ``outdir``.

    Returns the summary (on every rank).  Nothing is written if ``outdir`` is None."""
    start = time.perf_counter()
    q = params.normalised()
    disc = params.discretisation
    planar = params.model.reduction == "auto" and planar_allowed(params)
    solver = StationarySolver(params, comm, scene=name, planar=planar)
    result = solver.solve()
    reference = shooting.solve(q)  # the independent reference, Sys. (67)
    residual_at_shooting = solver.residual_at(reference.centre_line)  # collective
    summary = None
    if comm.rank == 0:
        x = q.length_m(result.centre_line)
        x_ref = q.length_m(reference.centre_line(result.s))
        T = q.tension_N(result.tension)
        summary = {
            "scene": name,
            "elements": disc.elements,
            "degree": disc.degree,
            "mesh": disc.mesh,
            "dofs": solver.rod.dof_count(),
            "model": params.model.describe(planar),
            "ranks": comm.size,
            "newton_iterations": result.newton_iterations,
            "tension_N": {"s0": float(T[0]), "s1": float(T[-1]),
                          "min": float(T.min()), "max": float(T.max())},
            "sag_m": q.L0 * sag(result.centre_line, q.top_position()),
            "shooting_max_diff_m": float(np.max(np.linalg.norm(x - x_ref, axis=1))),
            "shooting_tension_s0_N": float(q.tension_N(reference.tension(0.0))),
            "residual_at_shooting": float(residual_at_shooting),
            "wall_s": time.perf_counter() - start,
        }
        log(f"{name}: {'planar' if planar else 'full'} model, N = {disc.elements}, p = {disc.degree}: "
            f"{summary['newton_iterations']} Newton iterations, {summary['wall_s']:.2f} s")
        log(f"  tension T(0) = {T[0]:.3f} N, T(L0) = {T[-1]:.3f} N "
            f"(shooting T(0) = {summary['shooting_tension_s0_N']:.3f} N)")
        log(f"  sag {summary['sag_m']:.5f} m; FE vs shooting max |dr| = "
            f"{summary['shooting_max_diff_m']:.3e} m; FE residual at shooting = "
            f"{residual_at_shooting:.3e}")
        if outdir is not None:
            outdir = Path(outdir)
            outdir.mkdir(parents=True, exist_ok=True)
            s_m = q.length_m(result.s)
            writers.centre_line_png(outdir / "stationary.png", s_m, x, q.length_m(result.s_tension),
                                    T, title or name, reference_x_m=x_ref)
            writers.centre_line_xdmf(outdir / "centre_line.xdmf", x, {
                "s_m": s_m, "tension_N": np.interp(result.s, result.s_tension, T)})
            writers.write_json(outdir / "summary.json", summary)
            log(f"  wrote {outdir}/summary.json, stationary.png, centre_line.xdmf")
    return comm.bcast(summary, root=0)
