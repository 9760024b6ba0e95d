"""The paper's lab tests (Sec. 4, Fig. 2 a-c) run as virtual tests on the rod model.

A 6.76 m segment with the mass per length of the scene's helix (Table 2 by
default), clamped at a wall (solvers/cantilever.py), gravity on, no wind;
the tension T_e a dead load along the undeformed (horizontal) axis at the
free end.  Each test reads the simulated segment as the experimenters read
theirs:

- axial (Fig. 3): T_e = EA (L - L0) / L0, Eq. (62), L the end's distance
  from the wall along the axis; one EA from the regression over the tensions;
- bending (Fig. 4): at each T_e, loads F_N along gravity (normal to the
  axis), y_e the end's displacement along F_N from the state at F_N = 0;
  F_N = EI 3 y_e / L0^3, Eq. (63), regressed: the apparent EI per tension;
- torsion (Fig. 5): at each T_e, end torques M_t, alpha the end's rotation
  about the tangent (int tau ds); M_t = GJ alpha / L0, Eq. (65), regressed.

Every regression is a least-squares line through the origin, as the
formulas have no intercept.  ``bending`` with ``fit``: the intrinsic bending
law EI = a T + b whose simulated test reproduces Eq. (64) at the paper's
tensions (docs/explanation/labtest.md), on the rod with ``helix.EI_law`` (extensible
kinematics, which the law needs): per tension a 1-D root find of a constant
EI (secant, from the closed-form inverse of solvers/analytic.py), the line
through the roots, then Gauss-Newton on (a, b) with the law in the rod, at
small loads (the law's energy couples the axial force to kappa^2, so its
test softens with the load: docs/explanation/labtest.md); the fit is
:mod:`rawehelix.studies.analysis.labfit`.  Any test with ``fit`` also fits the scene's
``[section]`` members at the section level (``summary["section_fit"]``,
labfit.section_fit; docs/explanation/section.md).

:func:`compute` returns a :class:`LabTest`; :meth:`LabTest.write` writes
summary.json and labtest.png.  Computing writes nothing.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from mpi4py import MPI

from rawehelix import fits
from rawehelix.errors import SolverError
from rawehelix.parameters import ParameterError, Parameters
from rawehelix.solvers import analytic
from rawehelix.studies.analysis import labfit, labmembers
from rawehelix.studies.present import labtest_figure
from rawehelix.studies.store import writers
from rawehelix.studies.scene import SceneError, toml_value
from rawehelix.studies.study import EXIT_UNMET

log = logging.getLogger("rawehelix")

TESTS = ("axial", "bending", "torsion")
LAB_LENGTH_M = 6.76  # L0 of the lab segment, Sec. 4
LAB_ELEMENTS = 8  # N of the segment unless the caller sets it (smooth: N = 8, p = 3 to ~1e-6)
EQ64 = (52.4, 2290.0)  # Eq. (64): EI [N m^2] = 52.4 T_e [N] + 2290
LAB_EA_N = 3.64e4  # Eq. (62)'s regression over the axial test (Sec. 4, Fig. 3; Table 2)
PAPER_BENDING_TENSIONS_N = (90.0, 181.0, 259.0)  # Sec. 4, Fig. 4
DEFAULT_TENSIONS_N = {"axial": (50.0, 100.0, 150.0, 200.0, 250.0),
                      "bending": PAPER_BENDING_TENSIONS_N,
                      "torsion": (200.0,)}  # T_e0 ~ 200 N, Fig. 5
DEFAULT_LOADS = {"bending": (2.5, 5.0, 7.5, 10.0),  # F_N [N]
                 "fit": (0.1, 0.2, 0.3, 0.4),  # F_N [N]: the small-load limit (docs/explanation/labtest.md)
                 "torsion": (5.0, 10.0, 15.0, 20.0, 25.0)}  # M_t [Nm], up to ~25 Nm (Sec. 4)


def eq64(tension_N):
    """EI [N m^2] of Eq. (64) at T_e [N]."""
    return EQ64[0] * np.asarray(tension_N, dtype=float) + EQ64[1]


def lab_parameters(helix_scene: Parameters, elements: int | None = None,
                   degree: int | None = None, gravity: bool = True, law: bool = False) -> Parameters:
    """The lab segment: L0 = 6.76 m, the scene helix's mass per length, EA, GJ and
    EI law (EI is set per test), no wind or drag; ``gravity`` as in the lab.
    ``law``: a rod with an EI law (Eq. 64 until the caller sets another), which
    needs the extensible kinematics (parameters.py)."""
    h = helix_scene.helix
    disc = {"elements": LAB_ELEMENTS if elements is None else elements}
    if degree is not None:
        disc["degree"] = degree
    helix = {"length_m": LAB_LENGTH_M, "mass_kg": h.mass_kg / h.length_m * LAB_LENGTH_M}
    model = {"drag": False, "gravity": gravity}
    if law:
        model["kinematics"] = "extensible"
        if h.EI_law is None:
            helix["EI_law"] = {"a_Nm2_per_N": EQ64[0], "b_Nm2": EQ64[1]}
    # the segment's ends are the lab's (a wall, a dead load): the scene's stretch does not
    # enter, so a scene with ends.tension_N needs no elongation found (T / EA stands in)
    ends = {} if helix_scene.ends.tension_N is None else {
        "elongation": helix_scene.ends.tension_N / h.EA_N}
    try:  # --elements and --degree checked as a scene's (exit 2, one line)
        return helix_scene.replace(helix=helix, environment={"wind_speed_m_s": 0.0},
                                   model=model, discretisation=disc, ends=ends,
                                   name=f"{helix_scene.name}_lab")
    except ParameterError as err:
        raise SceneError(f"labtest ({helix_scene.name})", err.key,
                         f"{toml_value(err.value)} {err.allowed}") from None


slope = labfit.slope  # the least-squares line through the origin, y = slope x


# -- the three tests on one solver ------------------------------------------------------

def axial_test(solver, tensions_N) -> dict:
    """Eq. (62) over the tensions: strains and the apparent EA."""
    L0 = solver.q.L0
    strain = []
    for T in tensions_N:
        tip = solver.solve(T * solver.axis)
        strain.append((tip.position_m @ solver.axis - L0) / L0)
    return {"tension_N": list(tensions_N), "strain": strain,
            "apparent_EA_N": slope(strain, tensions_N)}


def bending_test(solver, tension_N: float, loads_N) -> dict:
    """Eq. (63) at one tension: end deflections under the loads and the apparent EI."""
    L0 = solver.q.L0
    solver.reset()  # each tension's load path from the straight segment, as in the lab
    zero = solver.solve(tension_N * solver.axis).position_m
    deflection = []
    for F in loads_N:
        try:
            tip = solver.solve(tension_N * solver.axis + F * NORMAL)
        except SolverError as err:
            hint = (" With the EI law in the rod the energy 1/2 EI(eps) kappa^2 stops being "
                    "convex at kappa^2 = EI / (a^2 EA) (docs/explanation/labtest.md): try smaller --loads."
                    if solver.rod.c.bending_law else "")
            raise SolverError(f"bending test at T_e = {tension_N:g} N, F_N = {F:g} N: "
                              f"{err}{hint}") from None
        deflection.append(float((tip.position_m - zero) @ NORMAL))
    x = 3 * np.asarray(deflection) / L0**3
    return {"tension_N": tension_N, "load_N": list(loads_N), "deflection_m": deflection,
            "apparent_EI_Nm2": slope(x, loads_N)}


def torsion_test(solver, tension_N: float, torques_Nm) -> dict:
    """Eq. (65) at one tension: end rotations under the torques and the apparent GJ;
    the tension at the wall at each torque (the lab saw it rise, Sec. 4)."""
    L0 = solver.q.L0
    angle, wall_tension = [], []
    for M in torques_Nm:
        tip = solver.solve(tension_N * solver.axis, torque_Nm=M)
        angle.append(tip.twist_rad)
        wall_tension.append(tip.tension_wall_N)
    solver.solve(tension_N * solver.axis)  # back to no torque for the next tension
    return {"tension_N": tension_N, "torque_Nm": list(torques_Nm), "angle_rad": angle,
            "wall_tension_N": wall_tension,
            "apparent_GJ_Nm2": slope(np.asarray(angle) / L0, torques_Nm)}


# -- the study ----------------------------------------------------------------------------

NORMAL = np.array([0.0, 0.0, 1.0])  # F_N along k_E: down, with gravity (Fig. 2b's ballast)


@dataclass
class LabTest:
    """One virtual lab test (arrays and summary on every rank; rank 0 writes)."""

    params: Parameters
    test: str
    rows: list  # per tension: the dicts of axial_test / bending_test / torsion_test
    summary: dict = field(default_factory=dict)
    rank: int = 0

    @property
    def exit_status(self) -> int:
        """0; EXIT_UNMET if its fit ran into data that could not determine the law
        (summary "undetermined": labfit.fit)."""
        return EXIT_UNMET if self.summary.get("undetermined") else 0

    def write(self, outdir) -> Path:
        """summary.json and labtest.png (the paper's Figs. 3-5 axes) into ``outdir``."""
        def figure(d):
            return labtest_figure.labtest_png(d / "labtest.png", self, LAB_LENGTH_M)
        return writers.summary_and_figure(outdir, self.rank, self.summary, figure)


def compute(helix_scene: Parameters, test: str, tensions_N=None, loads=None, fit: bool = False,
            rod_EI_Nm2: float | None = None, elements: int | None = None,
            degree: int | None = None, gravity: bool = True, comm=MPI.COMM_WORLD) -> LabTest:
    """Run one lab test on the lab segment of ``helix_scene`` (see the module doc).

    ``loads``: F_N [N] (bending) or M_t [Nm] (torsion); ``rod_EI_Nm2``: the
    rod's constant EI (default: Eq. (64) at each test's T_e, the paper's
    use of it; the axial and torsion tests at the scene's EI if not given).
    ``fit`` (bending): identify the intrinsic law instead, with the law in the
    rod (extensible kinematics, which the law needs).  A scene helix with an
    EI law: the bending test's rod has it (unless ``rod_EI_Nm2``)."""
    from rawehelix.solvers.cantilever import CantileverSolver

    start = time.perf_counter()
    if helix_scene.model.torsion_hysteresis.active:  # a static solve holds z = 0
        raise SceneError(helix_scene.name, "torsion_hysteresis",
                         "the lab tests are static and hold the Bouc-Wen twist at z = 0 "
                         "(forms/hysteresis.py); the hysteretic torsion test runs in time: "
                         "rh.torsion_loop (studies/torsion_loop.py)")
    _check(test, tensions_N, loads, fit, rod_EI_Nm2)
    tensions = tuple(float(t) for t in (tensions_N or DEFAULT_TENSIONS_N[test]))
    loads = tuple(float(x) for x in (loads or DEFAULT_LOADS.get("fit" if fit and test == "bending" else test, ())))
    scene_law = helix_scene.helix.EI_law if rod_EI_Nm2 is None else None
    params = lab_parameters(helix_scene, elements, degree, gravity,
                            law=fit or scene_law is not None)
    solver = CantileverSolver(params, comm)
    h = params.helix
    summary = {"test": test, "scene": helix_scene.name, "length_m": LAB_LENGTH_M,
               "mass_per_length_kg_m": h.mass_kg / h.length_m, "gravity": gravity,
               "elements": params.discretisation.elements,
               "degree": params.discretisation.degree,
               "model": _describe(params),
               "EA_N": h.EA_N, "GJ_Nm2": h.GJ_Nm2}
    if scene_law is not None:  # the scene's law, at the local tension
        solver.set_bending_law(scene_law.a_Nm2_per_N, scene_law.b_Nm2)
    else:
        solver.set_bending_stiffness(rod_EI_Nm2 or h.EI_Nm2)
    rod = ("the scene's EI law at the local tension" if scene_law is not None
           else rod_EI_Nm2 or h.EI_Nm2)
    if test == "axial":
        rows = [axial_test(solver, tensions)]
        summary.update(rod_EI_Nm2=rod, tension_N=list(tensions),
                       strain=rows[0]["strain"], apparent_EA_N=rows[0]["apparent_EA_N"])
    elif test == "torsion":
        rows = [torsion_test(solver, T, loads) for T in tensions]
        summary.update(rod_EI_Nm2=rod, tension_N=list(tensions),
                       torque_Nm=list(loads),
                       apparent_GJ_Nm2=[r["apparent_GJ_Nm2"] for r in rows])
    elif fit:
        rows, law_summary = labfit.fit(solver, tensions, eq64(tensions), loads, bending_test)
        summary.update(law_summary)
        summary["model"] = _describe(params.replace(helix={"EI_law": law_summary["law"]}))
    else:
        rod_EI = [float(scene_law.EI_Nm2(T)) if scene_law is not None
                  else rod_EI_Nm2 or float(eq64(T)) for T in tensions]
        rows = []
        for T, EI in zip(tensions, rod_EI):
            if scene_law is None:
                solver.set_bending_stiffness(EI)
            rows.append(bending_test(solver, T, loads))
        apparent = [r["apparent_EI_Nm2"] for r in rows]
        summary.update(rod_EI=("the scene's EI law at the local tension" if scene_law is not None
                               else "Eq. (64) at T_e" if rod_EI_Nm2 is None else "constant"),
                       tension_N=list(tensions), load_N=list(loads), rod_EI_Nm2=rod_EI,
                       apparent_EI_Nm2=apparent, eq64_EI_Nm2=eq64(tensions).tolist(),
                       closed_form_apparent_EI_Nm2=closed_form_apparent_EI(params, rod_EI, tensions))
    if fit:  # the members (issue 29): fitted at the section level, then run in the rod
        members = helix_scene.model.section.members(helix_scene.helix, width=0.0)
        block = labfit.section_fit(test, members, helix_scene.helix.EA_N, LAB_LENGTH_M,
                                   section_lab(test, tensions, loads))
        block["rod"] = rod_check(helix_scene, block, elements, degree, gravity, comm)
        summary["section_fit"] = block
    summary["wall_s"] = time.perf_counter() - start
    summary["status"] = ("fit not determined" if fit and summary.get("undetermined")
                         else "done")
    log.debug("labtest %s: %.2f s", test, summary["wall_s"])
    return LabTest(params, test, rows, summary, comm.rank)


def rod_check(helix_scene: Parameters, block: dict, elements: int | None = None,
              degree: int | None = None, gravity: bool = True, comm=MPI.COMM_WORLD) -> dict:
    """The members' fit (``block``, labfit.section_fit) through the FE section law in
    this module's simulated tests on the lab segment (labmembers.rod_check)."""
    from rawehelix.solvers.cantilever import CantileverSolver

    def solver(section: dict, **helix):
        scene = helix_scene.replace(model={"kinematics": "extensible"}, section=section,
                                    **({"helix": helix} if helix else {}))
        return CantileverSolver(lab_parameters(scene, elements, degree, gravity), comm)

    tests = {"axial": lambda S: axial_test(S, DEFAULT_TENSIONS_N["axial"]),
             "torsion": torsion_test,
             "bending": lambda S, T: bending_test(S, T, DEFAULT_LOADS["fit"])}
    return {"gravity": gravity, **labmembers.rod_check(block, solver, tests, LAB_LENGTH_M)}


def section_lab(test: str, tensions, loads) -> dict:
    """The members' fit's inputs (labfit.section_fit): this test's tensions and loads,
    the defaults for the other two."""
    lab = {"axial": DEFAULT_TENSIONS_N["axial"], "torsion": DEFAULT_LOADS["torsion"],
           "bending": PAPER_BENDING_TENSIONS_N, "bending_loads": DEFAULT_LOADS["fit"]}
    if test == "axial":
        lab["axial"] = tensions
    elif test == "torsion":
        lab["torsion"] = loads
    else:
        lab.update(bending=tensions, bending_loads=loads)
    lab["eq64"] = eq64(lab["bending"]).tolist()
    return lab


def _describe(params) -> str:
    """summary.json's "model": the rod's terms and law, the clamp and the loads."""
    return (params.describe_model() + "; clamped at s = 0 (Nitsche slope), dead end loads "
            "(forms/cantilever.py)")


def closed_form_apparent_EI(params, rod_EI, tensions) -> list:
    """Eq. (63) on the closed-form tensioned cantilever of the scene's kinematics
    (solvers/analytic.py), linear in F_N and without gravity."""
    out = []
    for EI, T_e in zip(rod_EI, tensions):
        T, EI_t = analytic.cantilever_transverse(T_e, EI, params.helix.EA_N, params.model.kinematics)
        out.append(float(analytic.cantilever_apparent_EI(EI_t, T, LAB_LENGTH_M)))
    return out


def _check(test, tensions, loads, fit, rod_EI):
    if test not in TESTS:
        raise SceneError("labtest", test, f"must be one of {', '.join(TESTS)}")
    if fit and rod_EI is not None:
        raise SceneError("labtest --EI", rod_EI, "cannot be given with --fit (the fit finds EI)")
    for name, values, low in (("--tension", tensions, 0.0 if test == "bending" else 1e-300),
                              ("--loads", loads, 1e-300)):
        if values is not None and (len(values) == 0 or not all(
                np.isfinite(v) and v >= low for v in values)):
            raise SceneError(f"labtest {name}", values,
                             f"must be a list of finite numbers {'>= 0' if low == 0 else '> 0'}")
    if fit and test == "bending":  # EI = a T + b: known before any work (exit 2)
        why = fits.undetermined(fits.polynomial(tensions or DEFAULT_TENSIONS_N[test], 1), 2)
        if why:
            raise SceneError("labtest --tension", ",".join(f"{t:g}" for t in tensions),
                             f"cannot determine the fit's law EI = a T + b: {why}; give at "
                             "least 2 distinct tensions, e.g. --tension 90,181,259")
    if loads is not None and test == "axial":
        raise SceneError("labtest --loads", loads, "the axial test's loads are its --tension list")
    if rod_EI is not None and not (np.isfinite(rod_EI) and rod_EI > 0):
        raise SceneError("labtest --EI", rod_EI, "must be a finite number > 0")


def report(result: LabTest) -> str:
    """The short table a user reads after a lab test (and the members' fit, --fit)."""
    text = _report(result)
    block = result.summary.get("section_fit")
    return text if block is None else "\n".join([text, *labmembers.report(block)])


def _report(result: LabTest) -> str:
    s = result.summary
    head = (f"labtest {s['test']}: {s['length_m']} m segment of {s['scene']}, N = {s['elements']}, "
            f"p = {s['degree']}, gravity {'on' if s['gravity'] else 'off'}")
    if s["test"] == "axial":
        rows = [f"  {T:8.1f} N   strain {e:.5e}" for T, e in zip(s["tension_N"], s["strain"])]
        return "\n".join([head, *rows, f"  apparent EA (Eq. 62) = {s['apparent_EA_N']:.5g} N "
                          f"(rod EA = {s['EA_N']:.5g} N, ratio {s['apparent_EA_N'] / s['EA_N']:.5f})"])
    if s["test"] == "torsion":
        rows = [f"  T_e {r['tension_N']:7.1f} N: apparent GJ (Eq. 65) = {r['apparent_GJ_Nm2']:.5g} "
                f"N m^2 (rod GJ = {s['GJ_Nm2']:.5g}); wall tension {min(r['wall_tension_N']):.2f}"
                f"-{max(r['wall_tension_N']):.2f} N over the torques" for r in result.rows]
        return "\n".join([head, *rows])
    lines = [head, "   T_e [N]   rod EI [N m^2]   apparent EI (Eq. 63)   Eq. (64)   apparent/Eq.64"]
    rod = s["intrinsic_EI_Nm2"] if s.get("fit") else s["rod_EI_Nm2"]
    for T, EI, app, e64 in zip(s["tension_N"], rod, s["apparent_EI_Nm2"], s["eq64_EI_Nm2"]):
        lines.append(f"  {T:8.1f}   {EI:14.1f}   {app:20.1f}   {e64:8.1f}   {app / e64:14.4f}")
    if s.get("fit"):
        law = s["law"]
        if s.get("undetermined"):
            lines.append(f"  the law EI = a T + b is not determined: {s['undetermined']} "
                         f"(exit status {EXIT_UNMET}); give more distinct tensions")
        else:
            lines.append(f"  intrinsic law EI = {law['a_Nm2_per_N']:.3f} T + {law['b_Nm2']:.1f} "
                         f"N m^2 (Eq. 64: {EQ64[0]} T + {EQ64[1]:.0f}); reproduces Eq. (64) "
                         f"within {100 * max(abs(e) for e in s['relative_error']):.3f} %")
    return "\n".join(lines)
