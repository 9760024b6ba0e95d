"""What a run will need, estimated before anything is allocated, and the refusal
of a run that this machine cannot hold: one check for every command and study.

Memory: a fixed base (Python, DOLFINx, PETSc, matplotlib) plus a cost per
unknown that depends on the command's heaviest step, fitted to the peak RSS
of runs on this machine (``/usr/bin/time``, 2026-12-03, p = 3, mixed bending,
21 unknowns an element):

    stationary  N = 2000: 0.24 GB, N = 8000: 0.43 GB  -> 1.5 kB an unknown
    modes       N =  500: 0.42 GB, N = 2000: 1.12 GB, N = 4000: 1.99 GB
                (linear in N)                         -> 22 kB an unknown
    simulate    N = 1000: 0.38 GB, N = 3000: 0.39 GB  (below the stationary
                state it starts from: counted as stationary)
    spline      modes N = 100: 0.16 GB, N = 300: > 0.47 GB (dense matrices
                of 8 N unknowns)                      -> 4.5 kB N^2

The dense monodromy of ``orbits`` (FE) is (3n)^2 doubles and is refused past
``solvers.orbits.MAX_STATE`` entries from the discretisation alone.  The
limit is the machine's physical memory (all ranks of a run share it).

Counts (the frequencies of a sweep or a response, the points of a study,
the loads of a lab test): each point keeps a record of about 2 kB, and none
takes less than 10 ms (a stationary solve at N = 2); a count whose records
pass the memory limit, or whose time passes 30 days at that least cost, is
refused.

Every refusal is a :class:`SceneError` (exit status 2) naming the key, the
estimate and the limit.
"""

from __future__ import annotations

import math
import os

from rawehelix.errors import SceneError
from rawehelix.parameters import Parameters

BASE_BYTES = 0.25e9  # Python, DOLFINx, PETSc, matplotlib: the smallest run's peak RSS
#: bytes per FE unknown of each command's heaviest step (module docstring)
BYTES_PER_DOF = {"stationary": 1.5e3, "dynamics": 1.5e3, "modes": 22e3}
#: the step that sets each command's (and each study stage's) memory
HEAVIEST = {"stationary": "stationary", "labtest": "stationary", "simulate": "dynamics",
            "spin_up": "dynamics", "sweep": "dynamics", "converge": "modes",
            "modes": "modes", "response": "modes", "orbits": "modes",
            "section": "stationary"}  # section: closed forms, no FE (the smallest estimate)
SPLINE_BYTES_PER_N2 = 4.5e3  # the spline scheme's dense matrices: bytes per N^2
BYTES_PER_POINT = 2e3  # a sweep's, response's or study's record of one point
SECONDS_PER_POINT = 0.01  # the least a point costs (a stationary solve at N = 2)
WALL_LIMIT_S = 30 * 86400.0  # a count longer than this at the least cost is refused


def machine_bytes() -> float:
    """This machine's physical memory [bytes]."""
    return float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))


def _gb(x: float) -> str:
    return f"{x / 1e9:.3g} GB" if x < 1e12 else f"{x / 1e12:,.0f} TB"


def unknowns(params: Parameters, planar: bool = False) -> int:
    """The FE unknowns of the rod: (r, alpha) in P_p, 4 components (2 on the
    planar (x, z) rod), + 3 for the mixed form's curvature, + DG_(p-1) z for the
    hysteretic torsion (compat.rod_element)."""
    disc = params.discretisation
    nodes = disc.degree * disc.elements + 1
    comps = 2 if planar else 4 + 3 * (disc.bending == "mixed")
    internal = disc.degree * disc.elements if params.model.torsion_hysteresis.active else 0
    return comps * nodes + internal


def estimate_bytes(params: Parameters, command: str) -> float:
    """The peak memory of ``command`` on ``params`` (all ranks together) [bytes]."""
    disc = params.discretisation
    if disc.scheme == "spline":
        return BASE_BYTES + SPLINE_BYTES_PER_N2 * float(disc.elements) ** 2
    step = HEAVIEST.get(command, "modes")
    return BASE_BYTES + BYTES_PER_DOF[step] * unknowns(params)


def check(params: Parameters, command: str, copies: int = 1):
    """Refuse ``command`` on ``params`` (``copies`` at once: a study's ranks)
    when its estimate passes the machine's memory, or (orbits, FE) when the
    dense monodromy passes MAX_STATE; before anything is allocated."""
    disc = params.discretisation
    need = copies * estimate_bytes(params, command)
    have = machine_bytes()
    if need > have:
        how = ("the spline scheme's dense matrices, 4.5 kB N^2" if disc.scheme == "spline"
               else f"{unknowns(params)} unknowns at "
                    f"{BYTES_PER_DOF[HEAVIEST.get(command, 'modes')] / 1e3:g} kB each")
        raise SceneError(params.name, "discretisation.elements",
                         f"{disc.elements}: '{command}' needs about {_gb(need)} ({how}"
                         + (f", {copies} at once" if copies > 1 else "")
                         + f"), more than the {_gb(have)} this machine has (the limit: its "
                         f"physical memory; estimates in studies/resources.py); use fewer "
                         f"elements")
    if command == "orbits" and disc.scheme == "fe":
        from rawehelix.solvers.orbits import MAX_STATE
        n = unknowns(params)
        if 3 * n > MAX_STATE:
            raise SceneError(params.name, "discretisation.elements",
                             f"{disc.elements}: the orbits' state has 3n = {3 * n} entries at "
                             f"p = {disc.degree}; the dense monodromy ((3n)^2 doubles, an LU "
                             f"a step) is limited to {MAX_STATE}: use fewer elements or a "
                             f"lower degree")


def check_count(key: str, count: int, copies: int = 1):
    """Refuse ``count`` points (frequencies, design points, loads) whose records
    pass the memory limit or whose time at the least cost passes WALL_LIMIT_S."""
    need, have = BYTES_PER_POINT * float(count), machine_bytes()
    if need > have:
        raise SceneError(key, f"{count:.6g} points",
                         f"their records alone need about {_gb(need)}, more than the "
                         f"{_gb(have)} this machine has; use fewer points")
    wall = SECONDS_PER_POINT * float(count) / max(copies, 1)
    if wall > WALL_LIMIT_S:
        raise SceneError(key, f"{count:.6g} points",
                         f"at least {wall / 86400:.3g} days at {SECONDS_PER_POINT * 1e3:g} ms a "
                         f"point on {copies} rank(s), more than the limit of "
                         f"{WALL_LIMIT_S / 86400:g} days; use fewer points")


def frequency_count(params: Parameters) -> int:
    """The number of f1 of the scene's [sweep] list, without building it
    (the count of :meth:`rawehelix.parameters.Sweep.frequencies`)."""
    s = params.sweep
    span = (s.f1_stop_Hz - s.f1_start_Hz) / s.f1_step_Hz
    return int(math.floor(span + 1e-9)) + 1 if math.isfinite(span) else 2**63


def check_run(params: Parameters, command: str, f1_Hz=None, copies: int = 1):
    """The check of one command: its discretisation and, for a sweep or a
    response, its frequency list (given, or the scene's)."""
    if command in ("sweep", "response"):
        count = len(f1_Hz) if f1_Hz is not None else frequency_count(params)
        check_count("--f1" if f1_Hz is None else "f1_Hz", count, copies)
    check(params, command, copies)


def check_quantities(params: Parameters, wanted, copies: int = 1):
    """The check of a study's or a calibration's point: each stage its
    quantities need (:mod:`rawehelix.studies.quantities`), ``copies`` points
    at once (one a rank)."""
    from rawehelix.studies import quantities
    for stage in {quantities.parse(name)[0].stage.partition("@")[0] for name in wanted}:
        check(params, stage, copies)
