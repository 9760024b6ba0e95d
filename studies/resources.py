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

Time and count keys (issue 41): what a run keeps grows with them too, and is
counted before anything is allocated (:func:`check_simulate`, :func:`check_sweep`,
:func:`check_branches`):

    simulate    per output step (``time.output_every_s`` up to ``--until`` /
                ``time.until_s``) its row, its output time and the limits
                history: 498 B at peak, measured with tracemalloc (nominal_operation,
                N = 2, 1000 and 3000 outputs, 2026-12-05) -> BYTES_PER_OUTPUT;
                per frame (``time.fields_every_s``) its fields along s;
                and at least SECONDS_PER_STEP a time step of ``time.dt_s``
                (3.3 ms measured at N = 2: the bound is a third of it)
    sweep       per point its tension series (``sweep.samples_per_period`` x
                ``sweep.record_periods``) and period extremes (``sweep.max_periods``),
                one point's section samples for its limits block, and at least
                ``sweep.min_periods`` periods of fixed steps a point
    orbits, envelope   per branch point its orbit (X) and record; the points of a
                window: at most --max-points (400), about POINTS_PER_HZ a Hz of
                the window; an envelope has COUNT branches (``--vary``)

Every refusal is a :class:`SceneError` (exit status 2) naming the key, the
estimate and the limit.
"""

from __future__ import annotations

import math
import os

from rawehelix.errors import SceneError
from rawehelix.parameters import Parameters, schemes, wind_time
from rawehelix.parameters.schemes import FECore
from rawehelix.studies import needs

BASE_BYTES = 0.25e9  # Python, DOLFINx, PETSc, matplotlib: the smallest run's peak RSS
#: bytes per FE unknown of each command's heaviest step (module docstring; the scheme's
#: memory_bytes, parameters/schemes.py, counts a run's working memory)
BYTES_PER_DOF = FECore.BYTES_PER_UNKNOWN
#: the step that sets the memory of a study's stage that is no command (a command's:
#: its entry in studies/needs.py)
STAGE_STEPS = {"spin_up": "dynamics"}
BYTES_PER_POINT = 2e3  # a sweep's, response's or study's record of one point
SECONDS_PER_POINT = 0.01  # the least a point costs (a stationary solve at N = 2)
WALL_LIMIT_S = 30 * 86400.0  # a count longer than this at the least cost is refused
BYTES_PER_OUTPUT = 500.0  # simulate: a row, its output time, the limits history (docstring)
BYTES_PER_FRAME = 1.5e3  # simulate: a frame's arrays' headers ...
BYTES_PER_FRAME_NODE = 100.0  # ... and its fields at a node (11 float64 and headroom)
SECONDS_PER_STEP = 1e-3  # the least a fixed time step costs (3.3 ms measured at N = 2)
#: a turbulent wind's synthesis at its peak, a sample (pyconturb, 4 points: 241 MB for 1 h
#: at 0.02 s, 180001 samples, measured by issue 44's wind, operation/turbulence.py)
BYTES_PER_WIND_SAMPLE = 1.4e3
BYTES_PER_SECTION_NODE = 100.0  # sweep: a section sample of the limits block at a node
POINTS_PER_HZ = 25  # a branch's points a Hz of f1 (docs/envelope, N = 4: 13-23 a Hz)
MAX_BRANCH_POINTS = 400  # orbits' --max-points default (and the envelope's branches')


def machine_bytes() -> float:
    """This machine's physical memory [bytes]."""
    return float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))


def _gb(x: float) -> str:
    return f"{x / 1e9:.3g} GB" if x < 1e12 else f"{x / 1e12:,.0f} TB"


#: the FE unknowns of the rod (parameters/schemes.py::FECore.unknowns)
unknowns = FECore().unknowns


def heaviest(command: str) -> str:
    """The step that sets ``command``'s memory (studies/needs.py; a study's stage:
    :data:`STAGE_STEPS`); an internal error for a command registered without one
    (tests/test_resource_keys.py)."""
    if command in STAGE_STEPS:
        return STAGE_STEPS[command]
    return needs.get(command).memory_step


def estimate_bytes(params: Parameters, command: str) -> float:
    """The peak memory of ``command`` on ``params`` (all ranks together) [bytes]."""
    return BASE_BYTES + schemes.of(params).memory_bytes(params, heaviest(command))[0]


def check(params: Parameters, command: str, copies: int = 1):
    """Refuse ``command`` on ``params`` (``copies`` at once: a study's ranks)
    when its estimate passes the machine's memory, or (orbits, FE) when the
    dense monodromy passes MAX_STATE; before anything is allocated."""
    disc = params.discretisation
    scheme = schemes.of(params)
    need = copies * estimate_bytes(params, command)
    have = machine_bytes()
    if need > have:
        how = scheme.memory_bytes(params, heaviest(command))[1]
        raise SceneError(params.name, "discretisation.elements",
                         f"{disc.elements}: '{command}' needs about {_gb(need)} ({how}"
                         + (f", {copies} at once" if copies > 1 else "")
                         + f"), more than the {_gb(have)} this machine has (the limit: its "
                         f"physical memory; estimates in studies/resources.py); use fewer "
                         f"elements")
    if command == "orbits" and scheme.fe_assembled:  # the FE period map's dense monodromy
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
        key = "--f1" if f1_Hz is None else "f1_Hz"
        check_count(key, count, copies)
    check(params, command, copies)
    if command == "sweep":  # its samples and periods, past the discretisation's own check
        try:
            top = max(float(f) for f in f1_Hz) if f1_Hz is not None else params.sweep.f1_stop_Hz
        except (TypeError, ValueError):
            top = None  # not a list of numbers: the sweep's own check says so
        check_sweep(params, count, top, key, copies)


def check_quantities(params: Parameters, wanted, copies: int = 1):
    """The check of a study's or a calibration's point: each stage its
    quantities need (:mod:`rawehelix.studies.quantities`), ``copies`` points
    at once (one a rank)."""
    from rawehelix.studies import quantities
    for stage in {quantities.parse(name)[0].stage.partition("@")[0] for name in wanted}:
        check(params, stage, copies)
        STAGE_CHECKS.get(stage, lambda p, c: None)(params, copies)


#: a study stage's own check beyond its solver's memory: a simulate run a point keeps
#: its outputs, frames and wind (check_simulate), ``copies`` at once
STAGE_CHECKS = {"spin_up": lambda params, copies: check_simulate(params, copies=copies)}


def _refuse(key: str, value, what: str, need: float, have: float, advice: str):
    raise SceneError(key, value, f"{what} need about {_gb(need)}, more than the {_gb(have)} "
                                 f"this machine has (estimates in studies/resources.py); {advice}")


def _refuse_wall(key: str, value, what: str, wall: float, advice: str):
    if wall > WALL_LIMIT_S:
        raise SceneError(key, value, f"{what} take at least {wall / 86400:.3g} days, more than "
                                     f"the limit of {WALL_LIMIT_S / 86400:g} days; {advice}")


def _nodes(params: Parameters) -> int:
    disc = params.discretisation
    return disc.degree * disc.elements + 1


def check_simulate(params: Parameters, until_s: float | None = None, key: str = "--until",
                   copies: int = 1):
    """Refuse a simulation whose outputs (``time.output_every_s``), frames
    (``time.fields_every_s``), turbulence synthesis (``wind.duration_s`` /
    ``wind.time_step_s``) or time steps (``time.dt_s``) up to ``until_s`` (None:
    ``time.until_s``, then ``key`` is that) pass the memory or the wall limit;
    ``copies`` runs at once (a study's ranks)."""
    tm = params.time
    if until_s is None:
        until_s, key = tm.until_s, "time.until_s"
    short = wind_time.too_short(params, until_s, key)  # the wind's series must cover the run
    if short:
        raise SceneError(*short)
    outputs, frames = until_s / tm.output_every_s, until_s / tm.fields_every_s
    samples = wind_time.synthesis_samples(params)
    kept = (BYTES_PER_OUTPUT * outputs,
            frames * (BYTES_PER_FRAME + BYTES_PER_FRAME_NODE * _nodes(params)),
            BYTES_PER_WIND_SAMPLE * samples)
    need, have = copies * (estimate_bytes(params, "simulate") + sum(kept)), machine_bytes()
    if need > have:
        at_once = f" ({copies} runs at once: fewer ranks)" if copies > 1 else ""
        causes = {"time.output_every_s": f"{outputs:.3g} output steps of {tm.output_every_s:g} s",
                  "time.fields_every_s": f"{frames:.3g} frames of the fields every "
                                         f"{tm.fields_every_s:g} s",
                  "wind.time_step_s": f"{samples:.3g} samples of turbulence"}
        by = list(causes)[int(max(range(3), key=lambda i: kept[i]))]  # the largest part
        _refuse(key, f"{until_s:g} s", causes[by] + at_once, need, have,
                f"a shorter {key} or a longer {by} (--set {by}=...)")
    _refuse_wall(key, f"{until_s:g} s", f"{until_s / tm.dt_s:.3g} time steps of time.dt_s = "
                 f"{tm.dt_s:g} s at {SECONDS_PER_STEP * 1e3:g} ms each",
                 until_s / tm.dt_s * SECONDS_PER_STEP, f"a shorter {key}")


def check_sweep(params: Parameters, count: int, f1_max_Hz: float, key: str, copies: int = 1):
    """Refuse a sweep whose ``count`` points' records (their series,
    ``sweep.samples_per_period`` x ``sweep.record_periods``, and period extremes,
    ``sweep.max_periods``), one point's section samples, or its time (at least
    ``sweep.min_periods`` periods of the highest f1 a point, in fixed steps) pass the
    limits."""
    sw = params.sweep
    samples = float(sw.samples_per_period) * sw.record_periods
    record = BYTES_PER_POINT + 16.0 * samples + 16.0 * sw.max_periods
    sections = samples * _nodes(params) * BYTES_PER_SECTION_NODE
    need, have = estimate_bytes(params, "sweep") + count * record + sections, machine_bytes()
    if need > have:
        big = "sweep.max_periods"
        if sections + count * 16 * samples >= count * 16 * sw.max_periods:
            # the series and section samples: name the factor furthest above its default
            default = type(sw)()
            big = max(("sweep.samples_per_period", "sweep.record_periods"),
                      key=lambda k: getattr(sw, k[6:]) / getattr(default, k[6:]))
        _refuse(big, f"{getattr(sw, big.split('.')[1]):g}", f"{count:g} points at "
                f"sweep.samples_per_period = {sw.samples_per_period:g}, sweep.record_periods = "
                f"{sw.record_periods:g}, sweep.max_periods = {sw.max_periods:g}", need, have,
                f"fewer points ({key}), samples or periods")
    if schemes.of(params).fixed_time_step and f1_max_Hz is not None and \
            0 < f1_max_Hz < math.inf:  # else refused by the sweep's own check of f1
        steps = count * sw.min_periods / (f1_max_Hz * params.time.dt_s)
        _refuse_wall("sweep.min_periods", f"{sw.min_periods:g}", f"{count:g} points of at least "
                     f"{sw.min_periods:g} periods in steps of time.dt_s = {params.time.dt_s:g} s",
                     steps * SECONDS_PER_STEP / max(copies, 1),
                     f"fewer points ({key}) or periods")


def branch_points(f1_lo_Hz: float, f1_hi_Hz: float, max_points: int = MAX_BRANCH_POINTS) -> int:
    """The points a branch over the window is expected to hold (module docstring)."""
    width = abs(float(f1_hi_Hz) - float(f1_lo_Hz))
    if not math.isfinite(width):  # a window the command refuses itself: count the most
        return int(max_points)
    return int(min(max_points, math.ceil(POINTS_PER_HZ * width) + 1))


def orbit_size(params: Parameters, method: str = "hb") -> int:
    """The entries of an orbit's unknown X, the method's (studies/orbit_method.py):
    harmonic balance's (2 H + 1) unknowns at its first H (H_START: it grows where the
    orbit needs it), shooting's state (3n), the spline scheme's 8 N."""
    from rawehelix.studies import orbit_method
    return orbit_method.get(method).state_size(params)


def store_bytes_per_point(params: Parameters, method: str = "hb") -> float:
    """Disk of one stored branch point (orbits_store.py): the continuation's Jacobian
    as CSR (12 B a stored entry, up to n^2), X and the state's vectors, the record.
    Measured (2026-12-05, mobile_end, p = 3, H = 3): N = 2, n = 196: 0.47 MB; N = 4,
    n = 364: 1.10 MB a point (this bound: 0.47 and 1.61 MB)."""
    n = float(orbit_size(params, method))
    return 12.0 * n * n + 48.0 * n + 4e3  # + 4 vectors of n, the zip headers and the record


def check_branches(params: Parameters, branches: int, f1_lo_Hz: float, f1_hi_Hz: float,
                   method: str = "hb", key: str = "--vary", max_points: int = MAX_BRANCH_POINTS):
    """Refuse ``branches`` branches (an envelope's COUNT, orbits' ranks) whose points
    kept in memory (X and the record) pass the machine's memory; returns the expected
    points (for the disk's estimate, studies/store/outdir.py)."""
    check_count(key, branches)
    points = branches * branch_points(f1_lo_Hz, f1_hi_Hz, max_points)
    n = float(orbit_size(params, method))
    # + the continuation's dense n x n matrices (its Jacobian, LU and bordered system)
    need = (estimate_bytes(params, "envelope") + points * (BYTES_PER_POINT + 16.0 * n)
            + 3 * 8.0 * n * n)
    have = machine_bytes()
    if need > have:
        _refuse(key, f"{branches:g} branches", f"about {points:g} orbits ({orbit_size(params, method)} "
                f"entries each)", need, have, "fewer values or elements, or a narrower --f1")
    return points


def simulate_output_bytes(params: Parameters, until_s: float | None = None) -> float:
    """The disk of a simulation's series (time_series.csv, ~150 B an output step) and
    frames (centre_line.xdmf/.h5, ~100 B a node a frame) up to ``until_s``
    (studies/store/outdir.py's extra_bytes)."""
    tm = params.time
    until_s = tm.until_s if until_s is None else until_s
    return (150.0 * until_s / tm.output_every_s
            + BYTES_PER_FRAME_NODE * _nodes(params) * until_s / tm.fields_every_s)


def sweep_output_bytes(params: Parameters, count: int) -> float:
    """The disk of a sweep's ``count`` stored points beyond outdir.py's record: each
    point's JSON series (``sweep.samples_per_period`` x ``sweep.record_periods`` pairs,
    ~50 B each) and period extremes (``sweep.max_periods``, ~50 B each), and its
    final state (.npz: a few vectors of the FE unknowns)."""
    sw = params.sweep
    series = 50.0 * (float(sw.samples_per_period) * sw.record_periods + 2.0 * sw.max_periods)
    return count * (series + 4 * 8.0 * unknowns(params))
