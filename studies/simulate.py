"""Dynamics of a scene (Secs. 5.2, 5.3) from its stationary state: :func:`compute`
returns a :class:`TimeSeries`; :meth:`TimeSeries.write` writes it.

Computing writes nothing.  ``TimeSeries.write(outdir)`` writes:

    time_series.csv   t [s], spin [rpm] at s = 0, ~L0/2, L0, ground torque [Nm],
                      tension [N] at s = 0 and L0, lateral displacement of the middle [m]
    summary.json      key figures; ``solve_s`` is the time loop, ``wall_s`` the whole job
    state.npz         the final (or last good) state (normalised, with SI scales)
    centre_line.xdmf  (+ .h5) the moving centre line with tension, twist, spin and
                      the members' smallest and largest force and the moment ratio,
                      every ``time.fields_every_s``
    dynamics.png      Fig. 6: spins against the target, ground torque, tensions
    members.png       the [section] members' forces: smallest and largest against t
                      (slack and breaking lines), the smallest over (s, t) from the frames
    helix_<t>s.png, helix.gif   pyvista pictures (if pyvista is installed)

A run that fails raises :class:`SimulationError`, which carries the time
series up to the last good state (``err.partial``), so a caller can write it.
Long runs can checkpoint: ``compute(..., checkpoint=f, checkpoint_every_s=60)``
calls ``f(partial)`` every 60 s of wall time (the command line writes the
partial outputs there).
"""

from __future__ import annotations

import csv
import logging
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from mpi4py import MPI

from rawehelix.parameters import Parameters
from rawehelix.solvers import stepsize
from rawehelix.solvers.energy_account import EnergyAccount
from rawehelix.solvers.snes import SolverError
from rawehelix.studies import limits, machine, schemes
from rawehelix.studies.present import network_report
from rawehelix.studies.analysis import metrics, structure_limits
from rawehelix.studies.store import writers
from rawehelix.studies.scene import SceneError

log = logging.getLogger("rawehelix")

#: the limits block takes every k-th output step (its ``sampled_every_s``): at every
#: step it cost 13.5 % of a mobile_end run at N = 8, every 2nd keeps it under 10 %
#: (docs/explanation/structure_limits.md)
LIMITS_EVERY = 2

COLUMNS = ("time_s", "spin_s0_rpm", "spin_mid_rpm", "spin_L0_rpm", "ground_torque_Nm",
           "tension_s0_N", "tension_L0_N", "lateral_mid_m")


class SimulationError(SolverError):
    """The dynamics stopped; ``partial`` is the :class:`TimeSeries` up to the last good state."""

    def __init__(self, message: str, partial: "TimeSeries"):
        super().__init__(message)
        self.partial = partial


@dataclass
class Frame:
    """The fields along s at one time (SI)."""

    t_s: float
    s_m: np.ndarray
    x_m: np.ndarray  # (n, 3) centre line
    alpha_rad: np.ndarray
    tension_N: np.ndarray
    twist_rad_per_m: np.ndarray
    spin_rpm: np.ndarray
    # the members along s (studies/analysis/structure_limits.py::Tracker.profile)
    member_force_min_N: np.ndarray | None = None
    member_force_max_N: np.ndarray | None = None
    moment_ratio: np.ndarray | None = None


@dataclass
class TimeSeries:
    """A dynamic run in SI units (arrays on rank 0; empty elsewhere)."""

    params: Parameters
    rows: np.ndarray  # (n, len(COLUMNS))
    frames: list = field(default_factory=list)  # Frame every time.fields_every_s
    final_state: dict | None = None  # normalised arrays of the last good state (+ SI scales)
    summary: dict = field(default_factory=dict)
    rank: int = 0
    _start: float = 0.0
    #: (n, 3): t [s], the smallest and largest member force [N] at each tracked step
    limits_history: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    columns: tuple = COLUMNS  # + machine.COLUMNS with a rotor or a generator

    @property
    def t_s(self) -> np.ndarray:
        return self.rows[:, 0]

    @property
    def spin_rpm(self) -> np.ndarray:
        """(n, 3): the spin at s = 0, ~L0/2 and L0 [rpm]."""
        return self.rows[:, 1:4]

    @property
    def ground_torque_Nm(self) -> np.ndarray:
        return self.rows[:, 4]

    @property
    def tension_s0_N(self) -> np.ndarray:
        return self.rows[:, 5]

    @property
    def tension_s1_N(self) -> np.ndarray:
        return self.rows[:, 6]

    @property
    def lateral_mid_m(self) -> np.ndarray:
        """Displacement of the middle normal to the chord, from the start [m]."""
        return self.rows[:, 7]

    def write(self, outdir, pictures: bool = True, gif: bool = True) -> Path:
        """Write the files listed in the module docstring into ``outdir`` (rank 0)."""
        outdir = Path(outdir)
        if self.rank != 0:
            return outdir
        outdir.mkdir(parents=True, exist_ok=True)
        with open(outdir / "time_series.csv", "w", newline="") as f:
            out = csv.writer(f)
            out.writerow(self.columns)
            out.writerows([[f"{x:.9g}" for x in row] for row in self.rows])
        if self.final_state is not None:
            writers.write_npz(outdir / "state.npz", self.final_state)
        if self.frames:
            writers.frames_xdmf(outdir / "centre_line.xdmf", self.frames)
        if pictures and len(self.rows):
            self._figures(outdir, gif)
        self.summary["wall_s"] = time.perf_counter() - self._start
        writers.write_json(outdir / "summary.json", self.summary)
        return outdir

    def _figures(self, outdir: Path, gif: bool):
        title = self.params.title or self.params.name
        writers.dynamics_png(outdir / "dynamics.png", self.rows, self.params.controller.target_rpm,
                             title)
        if len(self.limits_history):
            writers.members_png(outdir / "members.png", self.limits_history, self.frames,
                                self.summary["limits"]["criteria"]["breaking"], title)
        from rawehelix.studies.present import render
        if not self.frames or not render.available():
            return
        R = self.params.helix.radius_m
        reference = self.frames[0].x_m
        for frame in (self.frames[0], self.frames[-1]):
            render.helix_png(outdir / f"helix_{frame.t_s:.2f}s.png", frame.x_m, frame.alpha_rad,
                             frame.tension_N, R, title, time_s=frame.t_s, reference_m=reference,
                             reference_label="the stationary state")
        if gif:
            render.helix_gif(outdir / "helix.gif",
                             [(f.t_s, f.x_m, f.alpha_rad, f.tension_N) for f in self.frames], R,
                             title=title, reference_m=reference,
                             reference_label="the stationary state")


class _Recorder:
    """Rows and the limits block at every output time, fields at every
    ``fields_every`` (collective).  ``limits_every``: the limits block takes every
    k-th output step (1: every one)."""

    def __init__(self, solver, fields_every: int, tracker, limits_every: int = 1, machine=None):
        self.q = solver.q
        self.machine = machine  # solvers/end_torques.Machine when active: its columns
        self.rows: list[tuple] = []
        self.frames: list[Frame] = []
        self.fields_every = max(1, fields_every)
        self.tracker, self.limits_every = tracker, max(1, limits_every)
        self._section = (None, None)  # (t [s], SI section state) last tracked
        self.r_mid0 = None
        top = self.q.top_position(0.0)
        self.chord = top / np.linalg.norm(top)

    def __call__(self, solver):
        q = self.q
        v = solver.probes.values()
        r_mid = np.array([v["x_mid"], v["y_mid"], v["z_mid"]])
        if self.r_mid0 is None:
            self.r_mid0 = r_mid
        d = r_mid - self.r_mid0
        lateral = np.linalg.norm(d - d.dot(self.chord) * self.chord)  # normal to the chord
        row = (float(q.time_s(solver.t)),
               *(float(q.spin_rpm(v[k])) for k in ("spin0", "spin_mid", "spin1")),
               float(q.torque_Nm(v["m0"])), float(q.tension_N(v["tension0"])),
               float(q.tension_N(v["tension1"])), float(q.length_m(lateral)))
        if self.machine is not None:
            row += machine.row(self.machine, row[0], row[1], row[3], row[4])
        self.rows.append(row)
        k = len(self.rows) - 1
        if k % self.limits_every == 0:
            self.track(solver, row[0])
        if k % self.fields_every == 0:
            self.frame(solver, row[0])

    def track(self, solver, t_s: float):
        """The limits block's section state at ``t_s`` (collective; rank 0 keeps it)."""
        section = solver.probes.section()
        state = None
        if section is not None:
            state = structure_limits.si(self.q, section)
            self.tracker.add(**state, t_s=t_s)
        self._section = (t_s, state)  # on every rank: frame() calls section() on all or none

    def frame(self, solver, t_s: float):
        f = solver.probes.fields()  # collective
        t_last, state = self._section
        if t_last != t_s:  # a frame off the tracked steps: its section state too
            state = structure_limits.si(self.q, s) if (s := solver.probes.section()) else None
        if f is None or (self.frames and self.frames[-1].t_s == t_s):
            return
        q = self.q
        state = {k: v for k, v in state.items() if k != "s_m"}
        self.frames.append(Frame(t_s, q.length_m(f["s"]), q.length_m(f["r"]), np.array(f["alpha"]),
                                 q.tension_N(f["tension"]), f["twist"] / q.L0,
                                 q.spin_rpm(f["alpha_t"]), **self.tracker.profile(**state)))


def _state_file(solver) -> dict | None:
    """The solver's last good state as arrays (rank 0), with its SI scales."""
    a = solver.state_arrays()  # collective
    if a is None:
        return None
    q, disc = solver.q, solver.params.discretisation
    return {**a, "t_s": q.time_s(a["t"]), "L0_m": q.L0, "t_scale_s": q.t_scale,
            "elements": disc.elements, "degree": disc.degree}


def compute(params: Parameters, until_s: float | None = None, comm=MPI.COMM_WORLD,
            options: dict | None = None, progress: bool | None = None,
            checkpoint=None, checkpoint_every_s: float = 60.0) -> TimeSeries:
    """Integrate the scene from its stationary state to ``until_s`` [s] (default
    ``time.until_s``); returns the :class:`TimeSeries` (complete on rank 0).

    ``options``: PETSc options of the time integrator (without the prefix).
    ``progress``: a progress bar on rank 0 (default: when stdout is a terminal).
    ``checkpoint(partial)``: called every ``checkpoint_every_s`` of wall time.
    Raises :class:`SceneError` for a scene this solver cannot run and
    :class:`SimulationError` (with the partial series) when the dynamics stop."""
    start = time.perf_counter()
    refusal = schemes.of(params).simulate_refusal
    if refusal:
        raise SceneError(params.name, "discretisation.scheme", refusal)
    if until_s is not None and not (until_s > 0 and np.isfinite(until_s)):
        raise SceneError(params.name, "until", f"{until_s!r}: must be a number of seconds > 0")
    own = schemes.of(params).time_series(params, until_s if until_s is not None
                                         else params.time.until_s)
    if own is not None:  # a scheme with its own time integration (the network)
        series = TimeSeries(params, own[0], summary=own[1], _start=own[3])
        if own[2] is not None:  # why it stopped early
            raise SimulationError(own[2], series)
        return series
    limits.check_bending_resolution(params, "simulate")
    # a fixed step must resolve the forcing and the modes a moving end excites
    adapt = (options or {}).get("ts_adapt_type")
    stepsize.check(params, fixed_steps=None if adapt is None else adapt == "none")
    q = params.normalised()
    disc, tm = params.discretisation, params.time
    until_s = until_s if until_s is not None else tm.until_s
    ends = machine.of(params)  # the rotor and the generator (issue 43); off: the paper's
    solver, start_point = machine.solver(params, ends, comm, options)
    if solver.compiled_wanted:  # -rawehelix_ts_compiled 1: registers the compiled steps
        import rawehelix.solvers.compiled_step  # noqa: F401
    top_start = machine.top_position(params, solver)  # a lifted top's [m]; None: fixed
    tracker = structure_limits.of_params(params)
    rec = _Recorder(solver, fields_every=int(round(tm.fields_every_s / tm.output_every_s)),
                    tracker=tracker, limits_every=LIMITS_EVERY,
                    machine=ends if ends.active else None)
    columns = COLUMNS + (machine.COLUMNS if ends.active else ())
    account = EnergyAccount() if ends.active else None
    if account is not None:
        account(solver)
    if LIMITS_EVERY > 1:
        tracker.sampled_every_s = LIMITS_EVERY * tm.output_every_s
    show = (progress if progress is not None else sys.stdout.isatty()) and comm.rank == 0
    bar = None
    if show:
        from tqdm import tqdm
        bar = tqdm(total=round(until_s, 6), unit="s", desc=params.name,
                   bar_format="{l_bar}{bar}| {n:.2f}/{total:.2f} s [{elapsed}<{remaining}]")
    summary = {"scene": params.name, "elements": disc.elements, "degree": disc.degree,
               "dofs": solver.rod.dof_count(), "ranks": comm.size,
               "ts_type": solver.ts.getType(), "target_rpm": params.controller.target_rpm,
               "model": params.describe_model()}
    if start_point:
        summary["machine"] = start_point
    loop_start = time.perf_counter()

    def result(complete: bool, error: str | None = None) -> TimeSeries:
        rows = np.array(rec.rows) if rec.rows else np.zeros((0, len(columns)))
        slack = comm.bcast(tracker.slack_time_fraction() if comm.rank == 0 else None, root=0)
        series = TimeSeries(params, rows, list(rec.frames), _state_file(solver), dict(summary),
                            comm.rank, start, np.array(tracker.history).reshape(-1, 3), columns)
        s = series.summary
        s.update({"complete": complete, "error": error,
                  "simulated_s": float(rows[-1, 0]) if len(rows) else 0.0,
                  "solve_s": time.perf_counter() - loop_start,
                  "wall_s": time.perf_counter() - start,
                  "steps": solver.steps, "newton_iterations": solver.newton_iterations,
                  "settling_time_s": metrics.settling_time(rows[:, 0], rows[:, 1:4],
                                                           params.controller.target_rpm),
                  "limits": comm.bcast(tracker.block() if comm.rank == 0 else None, root=0)})
        if account is not None:  # work in = generator + dissipated + stored (issue 43)
            s["energy"] = account.summary(q)
        if top_start is not None:  # the lifted top moving (issue 44)
            s["lifter"] = machine.lifter_block(top_start, machine.top_position(params, solver))
        if solver.release is not None:  # a start-up from rest (issue 44)
            s["startup"] = machine.startup(ends, solver.release, rows)
        if len(rows):
            s["final"] = {"spin_rpm": {"s0": rows[-1, 1], "mid": rows[-1, 2], "L0": rows[-1, 3]},
                          "ground_torque_Nm": rows[-1, 4], "tension_s0_N": rows[-1, 5],
                          "tension_L0_N": rows[-1, 6], "lateral_mid_m": rows[-1, 7]}
            s["tension_range_N"] = [float(rows[:, 5:7].min()), float(rows[:, 5:7].max())]
            if ends.active:  # the machine's columns (studies/machine.py)
                s["final"].update(zip(machine.COLUMNS, map(float, rows[-1, len(COLUMNS):])))
            s["statistics"] = metrics.run_statistics(rows, columns, slack)
            s["real_time_factor"] = s["simulated_s"] / max(s["solve_s"], 1e-12)
        return series

    last_checkpoint = [time.perf_counter()]

    def on_output(sv):
        rec(sv)
        if bar is not None:
            bar.update(round(rec.rows[-1][0] - bar.n, 6))
        if checkpoint is not None and time.perf_counter() - last_checkpoint[0] > checkpoint_every_s:
            checkpoint(result(False))  # collective
            last_checkpoint[0] = time.perf_counter()

    stopped = []  # a step's own stop (the rotor out of its table), raised through PETSc

    def on_step(sv):
        try:
            machine.check_step(ends, sv)
        except SolverError as err:
            stopped.append(err)
            raise
        account(sv)

    try:
        solver.advance(until_s / q.t_scale, on_output=on_output,
                       on_step=on_step if account is not None else None,
                       output_every=tm.output_every_s / q.t_scale)
    except SolverError as err:
        err = stopped[0] if stopped else err
        rec.frame(solver, float(q.time_s(solver.state().t)))
        raise SimulationError(str(err), result(False, str(err))) from None
    finally:
        if bar is not None:
            bar.close()
    rec.frame(solver, rec.rows[-1][0] if rec.rows else 0.0)  # the last fields too
    series = result(True)
    s = series.summary
    if comm.rank == 0:
        log.debug("%s: %d steps, %d Newton iterations, %.1f s, real-time factor %.1f",
                 params.name, s["steps"], s["newton_iterations"], s["solve_s"],
                 s.get("real_time_factor", 0.0))
    series.summary = comm.bcast(s, root=0)
    return series


def report(result: TimeSeries) -> str:
    """The lines a user reads after a run."""
    s = result.summary
    lines = [f"{s['scene']}: {s['simulated_s']:.2f} s simulated in {s['solve_s']:.1f} s "
             f"({s['steps']} steps, {s['newton_iterations']} Newton iterations, real-time factor "
             f"{s.get('real_time_factor', 0.0):.1f})"]
    f = s.get("final")
    if f:
        settle = s.get("settling_time_s")
        lines.append(f"  final spin {f['spin_rpm']['s0']:.3f} / {f['spin_rpm']['mid']:.3f} / "
                     f"{f['spin_rpm']['L0']:.3f} rpm (s = 0, L0/2, L0), ground torque "
                     f"{f['ground_torque_Nm']:.3f} Nm, T(0) = {f['tension_s0_N']:.2f} N"
                     + (f"; settled (2 %) at {settle:.3f} s" if settle is not None else ""))
    if f and "power_W" in f:
        lines.append(f"  rotor {f['rotor_rpm']:.3f} rpm, generator power {f['power_W']:.2f} W, "
                     f"thrust {f['thrust_N']:.2f} N at a hub wind of {f['wind_hub_m_s']:.3g} m/s")
    lines[-1] += (machine.lifter_line(s.get("lifter"))
                  + machine.startup_line(s.get("startup"), s["simulated_s"])
                  + structure_limits.line(s.get("limits")) + EnergyAccount.line(s.get("energy"))
                  + network_report.line(s))
    return "\n".join(lines)
