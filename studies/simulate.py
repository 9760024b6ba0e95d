"""`rawehelix simulate`: the dynamics of a scene (Secs. 5.2, 5.3) from its stationary state.

Writes into the output directory, incrementally (an interrupted run keeps
everything up to the last output time):

    time_series.csv   t [s], spin [rpm] at s = 0, ~L0/2, L0, ground torque [Nm],
                      tension [N] at s = 0 and L0, lateral displacement of the middle [m]
    summary.json      key figures (rewritten at every output; "complete" at the end)
    state.npz         the last good state (normalised, see DynamicsSolver.save_state)
    centre_line.xdmf  (+ .h5) the moving centre line with tension, twist and spin
    dynamics.png      Fig. 6: spins against the target, ground torque, tensions
    helix_<t>s.png, helix.gif   pyvista renderings (if pyvista is installed)
"""

from __future__ import annotations

import csv
import sys
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

from rawehelix.parameters import Parameters
from rawehelix.solvers.dynamics import DynamicsSolver
from rawehelix.solvers.snes import SolverError
from rawehelix.studies import render, writers
from rawehelix.studies.metrics import settling_time
from rawehelix.studies.xdmf_series import PolylineSeries

COLUMNS = ("time_s", "spin_s0_rpm", "spin_mid_rpm", "spin_L0_rpm", "ground_torque_Nm",
           "tension_s0_N", "tension_L0_N", "lateral_mid_m")


class Recorder:
    """Turns solver states into rows, fields and files (rank 0 writes)."""

    def __init__(self, solver: DynamicsSolver, outdir: Path | None, frames_every: int, title: str):
        self.solver, self.q = solver, solver.q
        self.outdir = Path(outdir) if outdir is not None else None
        self.rank0 = solver.comm.rank == 0
        self.rows: list[tuple] = []
        self.frames: list = []
        self.frames_every = max(1, frames_every)
        self.title = title
        self.r_mid0 = None
        top = self.q.top_position(0.0)
        self.chord = top / np.linalg.norm(top)
        self.csv = self.xdmf = None
        if self.outdir is not None and self.rank0:
            self.outdir.mkdir(parents=True, exist_ok=True)
            self._csv_file = open(self.outdir / "time_series.csv", "w", newline="")
            self.csv = csv.writer(self._csv_file)
            self.csv.writerow(COLUMNS)
            self.xdmf = PolylineSeries(self.outdir / "centre_line.xdmf")

    def __call__(self, solver: DynamicsSolver):
        q = self.q
        v = solver.probes.values()
        r_mid = np.array([v["x_mid"], v["y_mid"], v["z_mid"]])
        if self.r_mid0 is None:
            self.r_mid0 = r_mid
        d = r_mid - self.r_mid0
        lateral = np.linalg.norm(d - d.dot(self.chord) * self.chord)  # normal to the chord
        row = (float(q.time_s(solver.t)), *(float(q.spin_rpm(v[k])) for k in ("spin0", "spin_mid", "spin1")),
               float(q.torque_Nm(v["m0"])), float(q.tension_N(v["tension0"])),
               float(q.tension_N(v["tension1"])), float(q.length_m(lateral)))
        self.rows.append(row)
        fields = solver.probes.fields()  # collective
        k = len(self.rows) - 1
        if self.outdir is not None:
            solver.save_state(self.outdir / "state.npz")  # collective
        if not self.rank0 or self.outdir is None:
            if self.rank0 and k % self.frames_every == 0:
                self.frames.append(self._frame(row[0], fields))
            return
        self.csv.writerow([f"{x:.9g}" for x in row])
        self._csv_file.flush()
        x_m = q.length_m(fields["r"])
        self.xdmf.write(row[0], x_m, {
            "s_m": q.length_m(fields["s"]),
            "tension_N": q.tension_N(fields["tension"]),
            "twist_rad_per_m": fields["twist"] / q.L0,
            "alpha_rad": fields["alpha"],
            "spin_rpm": q.spin_rpm(fields["alpha_t"]),
        })
        if k % self.frames_every == 0:
            self.frames.append(self._frame(row[0], fields))

    def _frame(self, t_s, fields):
        return (t_s, self.q.length_m(fields["r"]), np.array(fields["alpha"]))

    def close(self):
        if self.csv is not None:
            self._csv_file.close()
            self.xdmf.close()


def run(params: Parameters, outdir: Path | None, name: str = "scene", title: str = "",
        until_s: float | None = None, comm=MPI.COMM_WORLD, log=print, options: dict | None = None,
        picture_times_s=None, progress: bool | None = None) -> dict:
    """Simulate the scene; returns the summary (every rank).  Raises SolverError on failure
    (after writing summary.json with the error and the last good state)."""
    start = time.perf_counter()
    q = params.normalised()
    disc, tm = params.discretisation, params.time
    until_s = until_s if until_s is not None else tm.until_s
    n_out = max(1, int(round(until_s / tm.output_every_s)))
    solver = DynamicsSolver(params, comm, options=options)
    rec = Recorder(solver, outdir, frames_every=max(1, n_out // 60), title=title or name)
    show = (progress if progress is not None else sys.stdout.isatty()) and comm.rank == 0
    bar = None
    if show:
        from tqdm import tqdm
        bar = tqdm(total=round(until_s, 6), unit="s", desc=name, bar_format="{l_bar}{bar}| {n:.2f}/{total:.2f} s [{elapsed}<{remaining}]")

    summary = {"scene": name, "elements": disc.elements, "degree": disc.degree,
               "dofs": solver.rod.dof_count(), "ranks": comm.size,
               "ts_type": solver.ts.getType(), "target_rpm": params.controller.target_rpm,
               "model": params.model.describe()}

    def write_summary(complete: bool, error: str | None = None):
        if comm.rank != 0:
            return
        rows = np.array(rec.rows) if rec.rows else np.zeros((0, len(COLUMNS)))
        summary.update({
            "complete": complete, "error": error,
            "simulated_s": float(rows[-1, 0]) if len(rows) else 0.0,
            "wall_s": time.perf_counter() - start,
            "steps": solver.steps, "newton_iterations": solver.newton_iterations,
            "settling_time_s": settling_time(rows[:, 0], rows[:, 1:4], params.controller.target_rpm),
        })
        if len(rows):
            summary["final"] = {"spin_rpm": {"s0": rows[-1, 1], "mid": rows[-1, 2], "L0": rows[-1, 3]},
                                "ground_torque_Nm": rows[-1, 4], "tension_s0_N": rows[-1, 5],
                                "tension_L0_N": rows[-1, 6], "lateral_mid_m": rows[-1, 7]}
            summary["tension_range_N"] = [float(rows[:, 5:7].min()), float(rows[:, 5:7].max())]
            summary["real_time_factor"] = summary["simulated_s"] / max(summary["wall_s"], 1e-12)
        if outdir is not None:
            writers.write_json(Path(outdir) / "summary.json", summary)

    last_summary = [0.0]

    def on_output(sv):
        rec(sv)
        if bar is not None:
            bar.update(round(rec.rows[-1][0] - bar.n, 6))
        if time.perf_counter() - last_summary[0] > 2.0:  # incremental, cheap
            write_summary(False)
            last_summary[0] = time.perf_counter()

    error = None
    try:
        solver.advance(until_s / q.t_scale, on_output=on_output,
                       output_every=tm.output_every_s / q.t_scale)
    except SolverError as err:
        error = str(err)
    finally:
        if bar is not None:
            bar.close()
        rec.close()
    if outdir is not None:
        solver.save_state(Path(outdir) / "state.npz")
    write_summary(error is None, error)
    if error is not None:
        raise SolverError(error + (f" The last good state is in {Path(outdir) / 'state.npz'}."
                                   if outdir is not None else ""))
    if comm.rank == 0 and outdir is not None:
        _figures(params, rec, Path(outdir), title or name, picture_times_s, log)
        writers.write_json(Path(outdir) / "summary.json", summary)
        log(f"{name}: {summary['steps']} steps, {summary['newton_iterations']} Newton iterations, "
            f"{summary['wall_s']:.1f} s wall, real-time factor {summary.get('real_time_factor', 0):.1f}")
        f = summary.get("final", {})
        if f:
            log(f"  final spin {f['spin_rpm']['s0']:.3f} / {f['spin_rpm']['mid']:.3f} / "
                f"{f['spin_rpm']['L0']:.3f} rpm, ground torque {f['ground_torque_Nm']:.3f} Nm, "
                f"T(0) = {f['tension_s0_N']:.2f} N; wrote {outdir}")
    return comm.bcast(summary, root=0)


def _figures(params, rec: Recorder, outdir: Path, title: str, picture_times_s, log):
    rows = np.array(rec.rows)
    writers.dynamics_png(outdir / "dynamics.png", rows, params.controller.target_rpm, title)
    R = params.helix.radius_m
    frames = rec.frames
    if not frames:
        return
    times = picture_times_s if picture_times_s is not None else [frames[0][0], frames[-1][0]]
    for t in times:
        t_f, x_m, alpha = min(frames, key=lambda f: abs(f[0] - t))
        render.png(outdir / f"helix_{t_f:.2f}s.png", x_m, alpha, R, f"{title}  t = {t_f:.2f} s")
    render.gif(outdir / "helix.gif", [(f"t = {t:.2f} s", x, a) for t, x, a in frames], R)
