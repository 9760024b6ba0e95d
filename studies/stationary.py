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
from rawehelix.studies import schemes
from rawehelix.studies.analysis import structure_limits
from rawehelix.studies.store import writers
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


def solve(params: Parameters, comm=MPI.COMM_WORLD, top_torque: float = 0.0):
    """Newton alone (no shooting reference): ``(solver, result, planar)`` on the
    FE rod of :func:`compute` (the planar (x, z) rod where ``model.reduction``
    allows it and the state is torque-free; the lifted top's solver with
    ``[lifter] top = "lifted"``, the rotor at rest); ``top_torque`` (normalised, Eq. 39) the
    torque of both ends, balanced (:func:`static_torque`): the twisted state.  The
    parameter studies' stationary quantities take the torque-free one."""
    from rawehelix.solvers.stationary import StationarySolver, reduced

    if params.lifter.active:  # the top held by the lifter's force (solvers/lifted.py)
        from rawehelix.solvers import lifted
        q = params.normalised()
        solver, top = lifted.stationary(params, comm=comm, top_torque_Nm=q.torque_Nm(top_torque))
        return solver, top.result, False
    planar = reduced(params) and top_torque == 0.0
    solver = StationarySolver(params, comm, scene=params.name, planar=planar)
    if top_torque:
        # alpha(0) = 0 pins the free rotation (a Dirichlet end: the ground's torque is
        # its reaction, m0 = mN by the balance); the top's torque enters by Eq. (39)
        solver.set_end_torques(ground=top_torque, top=top_torque)
    return solver, solver.solve(), planar


def static_torque(params: Parameters) -> float:
    """The ends' torque of the static state (Omega = 0) of ``params``, normalised
    (Eqs. 38-39): the rotor's torque.top_Nm at the top, held by the ground.

    The ground torque of Eq. (40), integrated: m0 = mN + k1 (alpha(0) - alpha_dot* t)
    + k2 alpha_t(0) + C.  At rest (alpha_t = 0) it is constant, and balances the top's
    (m0 = mN, C = 0: the twist's stationary equation tau' = 0), unless k1 > 0 and a
    target spin alpha_dot* != 0, which makes it grow in time: that helix spins up to
    the target and has no static state, and this raises SceneError with what to run
    instead.  Without a controller (k1 = k2 = 0) the ground follows the rotor's torque
    (m0 = mN): the static twisted state exists, and is the one a run settles to only
    if something damps the torsional oscillation (a [damping] torsion_s)."""
    c = params.controller
    if c.k1 > 0 and c.target_rpm != 0:
        raise SceneError(
            params.name, "controller.target_rpm",
            f"{c.target_rpm:g} rpm with controller.k1 = {c.k1:g} > 0: the ground torque of "
            f"Eq. (40) spins the helix up to {c.target_rpm:g} rpm, so it has no static state "
            f"(Omega = 0) for 'stationary'; run 'rawehelix simulate {params.name} --until "
            f"{params.time.until_s:g}' for the spin-up and its steady spin, or set "
            f"controller.target_rpm = 0 for the static twisted state")
    hysteresis = params.model.torsion_hysteresis
    if hysteresis.active and params.torque.top_Nm != 0:
        # Bouc-Wen is rate-independent: at rest any internal twist z is static, and the
        # one a torque leaves depends on how it was applied (forms/hysteresis.py)
        raise SceneError(
            params.name, "torsion_hysteresis.rho",
            f"{hysteresis.rho:g} < 1 (hysteretic torsion) with torque.top_Nm = "
            f"{params.torque.top_Nm:g}: the static twist depends on how the torque was "
            f"applied, so 'stationary' has no one state to give; run 'rawehelix simulate "
            f"{params.name} --until {params.time.until_s:g}' for the ramp of Eq. (69), or set "
            f"torque.top_Nm = 0")
    return params.normalised().mN0


def sag_m(params: Parameters, result) -> float:
    """The sag [m] of a stationary result: the centre line's largest distance from the
    chord (to the top of Eq. 66, or to where the lifted top found itself)."""
    from rawehelix.solvers.stationary import sag
    q = params.normalised()
    return q.L0 * sag(result.centre_line,
                      result.centre_line[-1] if params.lifter.active else q.top_position())


def lifter_block(params: Parameters, top) -> dict:
    """summary.json's ``lifter``: where the lifted top found itself and the forces on it
    (solvers/lifted.py's LiftedResult, SI)."""
    return {"top": "lifted", "top_position_m": [float(x) for x in top.top_m],
            "chord_elevation_deg": float(top.chord_elevation_deg),
            "chord_length_m": float(np.linalg.norm(top.top_m)),
            "end_tangent": [float(x) for x in top.end_tangent],
            "force_N": params.lifter.force_N,
            "top_force_N": [float(x) for x in top.load.total_N()]}


def limits_block(params: Parameters, solver) -> dict | None:
    """The ``limits`` block (studies/analysis/structure_limits.py) of the stationary solver's
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
    allows it and the ends carry no torque) under the ends' balanced torque
    (:func:`static_torque`: a twisted state), checked against the independent
    reference of its kinematics where one applies (studies/reference_check.py: the
    shooting solution of Sys. (67), the extensible elastica, the shearable rod), within
    a time budget; ``summary["shooting"]`` says "compared", "not applicable (why)" or
    "did not converge (why)", beside the FE result.  A scene with ``ends.tension_N``
    comes with its elongation found (api: solvers/tension_target.py); the summary's
    ``ends`` block gives both."""
    from rawehelix.studies import reference_check

    scheme = schemes.of(params)
    if not scheme.fe_assembled and not scheme.beside_continuum:
        raise SceneError(params.name, "discretisation.scheme",
                         "'stationary' runs the FE scheme; the spline reference's stationary "
                         "state is part of 'modes'")
    top_torque = static_torque(params)  # refuses an unbalanced scene before any work
    beside = scheme.stationary_beside(params)  # a model of its own, beside the FE's
    params = params.replace(discretisation={"scheme": params.discretisation.continuum_scheme})
    start = time.perf_counter()
    q = params.normalised()
    disc = params.discretisation
    top = None  # the lifted top's result (solvers/lifted.py), or None: the top fixed
    if params.lifter.active:
        from rawehelix.solvers import lifted
        # refuses a lifter too weak to hold the helix up before any work
        solver, top = lifted.stationary(params, comm=comm,
                                        top_torque_Nm=q.torque_Nm(top_torque))
        result, planar = top.result, False
    else:
        solver, result, planar = solve(params, comm, top_torque)
    block = limits_block(params, solver)  # collective; before residual_at moves the state
    twist = twist_of(solver) if top_torque else None  # collective
    mean_tension = solver.mean_tension()  # collective
    check = reference_check.solve(params, comm, twisted=bool(top_torque))
    if check.compared:
        reference = check.reference
        residual_at_shooting = solver.residual_at(  # collective
            reference.centre_line, getattr(reference, "director", None))
        solver.rod.set_chord()
        residual_scale = solver.newton.residual_norm()  # collective: Newton's first guess
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
                          "min": float(T.min()), "max": float(T.max()),
                          "mean": float(q.tension_N(mean_tension))},
            "sag_m": sag_m(params, result),
            "ends": ends_block(params, q.tension_N(mean_tension)),
            "torque": None if twist is None else {
                "top_Nm": params.torque.top_Nm, "ground_Nm": params.torque.top_Nm,
                "twist_end_to_end_rad": twist,
                "held_by": "the ground: Eq. (40) at rest, m0 = mN"},
            "shooting": check.status,
            "limits": block,
        }
        if top is not None:
            summary["lifter"] = lifter_block(params, top)
        if beside is not None:
            summary["beside"] = beside
        if check.compared:
            x_ref = q.length_m(reference.centre_line(result.s))
            out.shooting_centre_line_m = x_ref
            summary.update({
                "shooting_max_diff_m": float(np.max(np.linalg.norm(x - x_ref, axis=1))),
                "shooting_tension_s0_N": float(q.tension_N(reference.tension(0.0))),
                "residual_at_shooting": float(residual_at_shooting),
                "residual_at_chord": float(residual_scale),
                "residual_at_shooting_relative": float(residual_at_shooting / residual_scale)})
        summary["wall_s"] = time.perf_counter() - start
        log.debug("%s: %s model, N = %d, p = %d: %d Newton iterations, %.2f s", params.name,
                 "planar" if planar else "full", disc.elements, disc.degree,
                 result.newton_iterations, summary["wall_s"])
    out.summary = comm.bcast(summary, root=0)
    return out


def twist_of(solver) -> float | None:
    """alpha(L0) - alpha(0) [rad] of the solver's state, on rank 0.  Collective."""
    return solver.end_twist()


def ends_block(params: Parameters, mean_tension_N: float) -> dict:
    """summary.json's ``ends``: the elongation, and for a scene with ``ends.tension_N``
    the tension asked for, where it is met and the state's mean tension."""
    from rawehelix.solvers.tension_target import WHERE
    e = params.ends
    block = {"elongation": e.elongation}
    if e.tension_N is not None:
        block.update({"tension_N": e.tension_N, "tension_at": WHERE,
                      "elongation_found": True, "mean_tension_N": float(mean_tension_N)})
    return block


def report(result: Stationary) -> str:
    """The lines a user reads after a stationary solve."""
    s = result.summary
    T, ends, torque = s["tension_N"], s["ends"], s.get("torque")
    lines = [f"{s['scene']}: N = {s['elements']}, p = {s['degree']} "
             f"({s['model'].split(';')[0]}): {s['newton_iterations']} Newton iterations, "
             f"{s['wall_s']:.2f} s"]
    if "tension_N" in ends:
        here = " under the torque" if torque else ""
        lines.append(f"  ends.tension_N = {ends['tension_N']:g} N ({ends['tension_at']}): "
                     f"elongation found {ends['elongation']:.6g}; mean tension{here} "
                     f"{ends['mean_tension_N']:.3f} N")
    if "lifter" in s:
        lift = s["lifter"]
        x, y, z = lift["top_position_m"]
        lines.append(f"  lifted top at ({x:.4f}, {y:.4f}, {z:.4f}) m (z down): chord "
                     f"{lift['chord_length_m']:.4f} m at {lift['chord_elevation_deg']:.3f} deg "
                     f"elevation, under the lifter's {lift['force_N']:g} N")
    if torque:
        lines.append(f"  torque {torque['top_Nm']:g} N m at the top, held by the ground "
                     f"(Eq. 40 at rest): twist alpha(L0) - alpha(0) = "
                     f"{torque['twist_end_to_end_rad']:.6g} rad")
    ref_T = (f" (shooting T(0) = {s['shooting_tension_s0_N']:.3f} N)"
             if "shooting_tension_s0_N" in s else "")
    lines.append(f"  tension T(0) = {T['s0']:.3f} N, T(L0) = {T['s1']:.3f} N{ref_T}")
    if "shooting_max_diff_m" not in s:
        lines.append(f"  sag {s['sag_m']:.5f} m; shooting reference {_status(s['shooting'])}")
    else:
        lines.append(f"  sag {s['sag_m']:.5f} m; FE vs shooting max |dr| = "
                     f"{s['shooting_max_diff_m']:.3e} m")
        lines.append(f"  FE residual at the shooting state = {s['residual_at_shooting_relative']:.3g}"
                     f" x the load's (|F| at the chord, Newton's first guess): the reference "
                     f"is not the discrete solution, which differs from it by the |dr| above "
                     f"(both |F| fall like N^-1/2, Sec. 5.1)")
    if s.get("beside"):
        lines.append(_beside_line(s["beside"], s))
    return "\n".join(lines) + structure_limits.line(s.get("limits"))


def _beside_line(b: dict, s: dict) -> str:
    """The scheme run beside the FE continuum (--scheme network), against it."""
    def gap(mine, theirs):
        return f"{100 * (mine / theirs - 1):+.2f} %" if theirs else "-"
    f_fe = ((s.get("limits") or {}).get("min_member_force_N") or {}).get("value")
    tether = (f"smallest tether force {b['smallest_tether_force_N']:.2f} N at s = "
              f"{b['smallest_at_s_m']:.2f} m"
              + (f" (continuum {f_fe:.2f} N)" if f_fe is not None else ""))
    torque = s.get("torque")
    twist = (f", twist {b['twist_end_to_end_rad']:.6g} rad "
             f"({gap(b['twist_end_to_end_rad'], torque['twist_end_to_end_rad'])})"
             if torque else "")
    from rawehelix import section_laws
    law = (s.get("limits") or {}).get("law")
    other = ("; the continuum's section is not the members' (section.law = "
             f"{law!r}): --set section.law=tensegrity --set model.kinematics=extensible "
             "compares the same members"
             if law is not None and not section_laws.get(law).members else "")
    return (f"  {b['scheme']} beside it ({b['rings']} rings, l = {b['spacing_m']:.4g} m, "
            f"{b['newton_iterations']} Newton iterations, {b['wall_s']:.2f} s): sag "
            f"{b['sag_m']:.5f} m ({gap(b['sag_m'], s['sag_m'])}), T(0) = "
            f"{b['tension_s0_N']:.3f} N ({gap(b['tension_s0_N'], s['tension_N']['s0'])}){twist}, "
            f"{tether}, {b['slack_tethers']} slack{other}")


def _status(status: str) -> str:
    """"not applicable: why" -> "not applicable (why)" (the printed form)."""
    head, _, why = status.partition(": ")
    return f"{head} ({why})" if why else head
