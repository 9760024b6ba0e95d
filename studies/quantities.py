"""The one registry of named quantities, for ``study``, ``calibrate`` and ``converge``.

A quantity is evaluated in one or both of two ways:

* at a point (``study``, ``calibrate``): a scene -> a float, through the API;
* refined (``converge``): over refinement ladders in N or dt, each run in its
  scheme (:class:`rawehelix.studies.converge.methods.Refinement`; the schemes'
  evaluations are :mod:`rawehelix.studies.schemes`).

At a point, each quantity belongs to one *stage*, the least computation that gives it:

    stationary   Newton on the torque-free stationary state alone (no shooting reference):
                 the state every run starts from (the torque ramp of Eq. 69 starts at 0),
                 which ``rawehelix stationary`` gives for the scene without its torque
    modes        the stationary state and its modes (never a time integration)
    spin_up      the dynamics from the stationary state to ``time.until_s``
    sweep        the brute-force sweep over the scene's [sweep] list (Fig. 8)
    sweep@F1     the sweep at the one frequency F1 [Hz]
    orbits       the branch of periodic orbits over the scene's [sweep] window

:func:`evaluate` runs every stage the asked quantities need once, on
MPI.COMM_SELF (a study runs one scene per rank), and returns the values and,
for the quantities it could not give, the reason.  Each stage calls the same
code as the single-run command of the same name (rawehelix.api), so a study's
value is the command's number.

``tension_max_N@F1`` is a family: the maximum tension at s = 0 of the
periodic response at f1 = F1 Hz, e.g. ``tension_max_N@10``.
"""

from __future__ import annotations

import math
import time
from typing import Callable

from rawehelix.errors import SceneError, SolverError
from rawehelix.families import VIBRATIONS
from rawehelix.parameters import ParameterError, Parameters
from rawehelix.studies.converge import methods as ladders
from rawehelix.studies.converge.methods import Refinement
from rawehelix.studies.converge.quantity import Quantity

AT = "@"  # tension_max_N@F1: the quantity at one forcing frequency
LATERAL = ("lateral_in_plane", "lateral_out_of_plane")


class QuantityError(ValueError):
    """The stage ran but does not give the quantity (no fold, not settled, ...)."""


class PointTimeout(Exception):
    """A point ran past its time limit (``rawehelix study --point-timeout``): raised
    once, by the alarm of :func:`rawehelix.studies.pool.time_limit`."""


#: what a failed point is (recorded with its reason); anything else is a
#: failure of the machinery and stops the whole study
POINT_ERRORS = (SolverError, SceneError, ParameterError, QuantityError, ArithmeticError,
                ValueError, RuntimeError, PointTimeout)


# -- the stages ----------------------------------------------------------------------------
def _comm():
    from mpi4py import MPI
    return MPI.COMM_SELF


def _stationary(params: Parameters, f1=None):
    from rawehelix.studies import stationary
    _, result, _ = stationary.solve(params, _comm())
    q = params.normalised()
    return {"tension_s0_N": float(q.tension_N(result.tension)[0]),
            "sag_m": stationary.sag_m(params, result)}


def _modes(params: Parameters, f1=None):
    from rawehelix.studies import modes
    return modes.compute(params, comm=_comm())


def _spin_up(params: Parameters, f1=None):
    from rawehelix.studies import simulate
    return simulate.compute(params, comm=_comm(), progress=False).summary


def _sweep(params: Parameters, f1=None):
    from rawehelix.studies import sweep
    return sweep.compute(params, None if f1 is None else [f1], comm=_comm(),
                         log=lambda m: None).summary


def _orbits(params: Parameters, f1=None):
    from rawehelix.studies import orbits
    s = params.sweep
    return orbits.compute(params, s.f1_start_Hz, s.f1_stop_Hz, comm=_comm()).summary


STAGES = {"stationary": _stationary, "modes": _modes, "spin_up": _spin_up, "sweep": _sweep,
          "orbits": _orbits}


# -- the picks -----------------------------------------------------------------------------
def _lowest(modes, families):
    """The slowest mode (smallest |eigenvalue|) of ``families``."""
    found = [m for m in modes if m.family in families]
    if not found:
        raise QuantityError(f"no mode of the families {', '.join(families)} was found")
    return min(found, key=lambda m: abs(m.eigenvalue))


def _given(value, what: str) -> float:
    if value is None or not math.isfinite(value):
        raise QuantityError(what)
    return float(value)


def _settling(summary):
    return _given(summary.get("settling_time_s"),
                  f"the spins did not settle within 2 % by t = {summary['simulated_s']:g} s")


def _statistic(field: str, what: str):
    """A field of a simulate run's ``statistics`` block (studies/simulate.py)."""
    return lambda summary: _given(summary["statistics"].get(field), what)


def _limit(field: str):
    """The value of a simulate run's ``limits`` block entry ``field``."""
    def pick(summary):
        entry = (summary.get("limits") or {}).get(field)
        return _given(None if entry is None else entry["value"],
                      f"the run's limits block has no {field} (no member was checked)")
    return pick


def _resonance(summary):
    return _given(summary.get("resonance_Hz"), "no periodic point of the sweep has a T max")


def _along(summary) -> str:
    """The orbits' f1 range, for a quantity that the branch does not give."""
    f = [p["f1_Hz"] for p in summary["branch"]]
    return f"in f1 = {min(f):g}-{max(f):g} Hz"


def _fold(summary):
    if not summary["folds"]:
        raise QuantityError(f"the branch has no fold {_along(summary)}")
    return float(summary["folds"][0]["f1_Hz"])


def _peak(field: str):
    """The highest local maximum of T max along the orbits (``peaks`` of kind peak)."""
    def pick(summary):
        found = [x for x in summary["peaks"] if x["kind"] == "peak"]
        if not found:
            raise QuantityError(f"T max has no peak along the branch {_along(summary)}")
        return float(max(found, key=lambda x: x["tension_max_N"])[field])
    return pick


def _tension_max(summary):
    point = summary["points"][0]
    return _given(point.get("tension_max_N"),
                  f"the sweep point f1 = {point['f1_Hz']:g} Hz failed or went slack")


def _modal(family: str, field: str):
    return lambda modes: float(getattr(_lowest(modes, (family,)), field))


def _refined(name: str, unit: str, doc: str, methods: list, evaluate, components: list,
             **more) -> Quantity:
    """A quantity of ``converge``: ``methods`` refined against the finest run of FE p = 4."""
    return Quantity(name, unit, None, None, doc,
                    Refinement(methods, "FE p=4", evaluate, components, **more))


_N = ladders.DT_LADDER_ELEMENTS
#: the time reference of the dt ladders: the finest run of alpha2 at their N
_DT_REFERENCE = {"time_reference": f"FE N={_N} p=3 alpha2 (dt)"}

#: every named quantity, at a point or refined
QUANTITIES = {q.name: q for q in [
    _refined("tension_s0", "N", "stationary tension at s = 0 (Sec. 5.1)",
             ladders.space_methods(ladders.FE_LADDER, ladders.SPLINE_LADDER),
             ladders.tension_s0, ["T(0)"], independent=ladders.shooting_tension_s0),
    _refined("eigenvalues", "1/s", "|lambda| of the lowest mode of each family (Table 3)",
             ladders.space_methods((2, 4, 8, 16, 32), (2, 4, 8, 16)), ladders.eigenvalues,
             list(VIBRATIONS)),
    _refined("spin_overshoot", "rpm", "largest spin at s = 0 above the target (Sec. 5.2)",
             ladders.dynamic_methods((2, 4, 8, 16), (2, 4, 8), ladders.SPIN_DTS, _N),
             ladders.spin_overshoot, ["overshoot"], **_DT_REFERENCE, **ladders.SPIN_SCALE),
    _refined("settling_time", "s", "when the three spins stay in the settling band (Sec. 5.2)",
             ladders.dynamic_methods((2, 4, 8, 16), (2, 4, 8), ladders.SPIN_DTS, _N),
             ladders.settling_time, ["settling"], **_DT_REFERENCE),
    _refined("tension_max", "N", "T max at s = 0 of the periodic response at 10 Hz (Fig. 8)",
             ladders.dynamic_methods((4, 8, 16), (2, 3, 4, 6), ladders.TENSION_MAX_DTS, _N),
             ladders.tension_max, ["T max at 10 Hz"], **_DT_REFERENCE),
    Quantity("tension_s0_N", "N", "stationary", lambda r: r["tension_s0_N"],
             "tension at the ground end s = 0 of the torque-free stationary state"),
    Quantity("sag_m", "m", "stationary", lambda r: r["sag_m"],
             "largest distance of the torque-free stationary centre line from the chord"),
    Quantity("lateral_frequency_Hz", "Hz", "modes",
             lambda m: min(_lowest(m, (f,)).frequency_Hz for f in LATERAL),
             "the lower frequency of the lowest lateral modes of the two planes"),
    *[Quantity(f"{f}_{field}", unit, "modes", _modal(f, field),
               f"{what} of the lowest {f.replace('_', ' ')} mode")
      for f in VIBRATIONS
      for field, unit, what in (("frequency_Hz", "Hz", "frequency"),
                                ("decay_per_s", "1/s", "decay rate"))],
    Quantity("settling_time_s", "s", "spin_up", _settling,
             "time after which the spins stay within 2 % of the target (Sec. 5.2)"),
    # a simulate run's statistics (issue 44: a seed study, --vary wind.seed=...)
    Quantity("power_mean_W", "W", "spin_up",
             _statistic("power_mean_W", "the scene has no generator: no power"),
             "the generator's mean power over the run's outputs"),
    Quantity("tension_s0_max_N", "N", "spin_up",
             _statistic("tension_s0_max_N", "the run has no output"),
             "the largest tension at the ground end s = 0 over the run"),
    Quantity("tension_L0_max_N", "N", "spin_up",
             _statistic("tension_L0_max_N", "the run has no output"),
             "the largest tension at the top end s = L0 over the run"),
    Quantity("member_force_min_N", "N", "spin_up", _limit("min_member_force_N"),
             "the smallest tether (member) force over the run (the limits block)"),
    Quantity("moment_ratio_max", "-", "spin_up", _limit("moment_ratio_max"),
             "the largest moment ratio |M| / (N R) over the run (the limits block)"),
    Quantity("twist_max_rad_m", "rad/m", "spin_up", _limit("twist_per_length_max"),
             "the largest twist per length over the run (the limits block)"),
    Quantity("slack_time_fraction", "-", "spin_up",
             _statistic("slack_time_fraction", "the run's limits block sampled no time"),
             "the fraction of the run's sampled times at which any tether is slack"),
    Quantity("resonance_Hz", "Hz", "sweep", _resonance,
             "f1 of the largest T max of the sweep over the scene's [sweep] list (Fig. 8)"),
    Quantity("fold_Hz", "Hz", "orbits", _fold,
             "f1 of the first fold of the periodic orbits over the [sweep] window"),
    Quantity("peak_Hz", "Hz", "orbits", _peak("f1_Hz"),
             "f1 of the highest peak of T max along the orbits over the [sweep] window"),
    Quantity("peak_tension_N", "N", "orbits", _peak("tension_max_N"),
             "the highest peak of T max along the orbits over the [sweep] window"),
    Quantity(f"tension_max_N{AT}F1", "N", "sweep@F1", _tension_max,
             "largest tension at s = 0 of the periodic response at f1 = F1 Hz"),
]}


#: the quantities at a point (``study``, ``calibrate``)
AT_A_POINT = {name: q for name, q in QUANTITIES.items() if q.stage is not None}


def names() -> list[str]:
    """The quantities of ``study`` and ``calibrate``."""
    return list(AT_A_POINT)


def refined() -> dict[str, Quantity]:
    """The quantities of ``converge`` by name (each with its :class:`Refinement`)."""
    return {name: q for name, q in QUANTITIES.items() if q.refinement is not None}


def other_command(name: str) -> str:
    """A hint when ``name`` is the other command's quantity: ``converge`` refines
    ``tension_s0``, ``study`` takes ``tension_s0_N`` at a point ("" if neither)."""
    base = name.partition(AT)[0]
    if base in refined():
        near = [n for n in AT_A_POINT if n.partition(AT)[0] == base + "_N"]
        return (f" ({base} is rawehelix converge's refined quantity"
                + (f"; at a point it is {' or '.join(near)}" if near else "") + ")")
    if any(n.partition(AT)[0] == base for n in AT_A_POINT):
        near = [n for n in refined() if base.startswith(n + "_")]
        return (f" ({base} is rawehelix study's quantity at a point"
                + (f"; refined it is {' or '.join(near)}" if near else "") + ")")
    return ""


def parse(name: str, where: str = "--quantity") -> tuple[Quantity, float | None]:
    """The quantity of a name (``tension_max_N@10`` -> the family at f1 = 10 Hz)."""
    base, sep, f1_text = name.partition(AT)
    key = f"{base}{AT}F1" if sep else base
    if key not in AT_A_POINT or (key.endswith(f"{AT}F1") and not sep):
        raise SceneError(where, name, "unknown quantity" + other_command(name)
                         + "; known are " + ", ".join(AT_A_POINT))
    if not sep:
        return AT_A_POINT[key], None
    try:
        f1 = float(f1_text)
    except ValueError:
        f1 = -1.0
    if not (f1 > 0 and math.isfinite(f1)):
        raise SceneError(where, name, f"F1 in {base}{AT}F1 must be a frequency > 0 in Hz")
    return AT_A_POINT[key], f1


def parse_list(text: str, where: str = "--quantity") -> list[str]:
    """``Q[,Q...]`` -> the names, each checked (:func:`parse`)."""
    items = [t.strip() for t in str(text).split(",") if t.strip()]
    if not items:
        raise SceneError(where, text, "give at least one quantity: " + ", ".join(AT_A_POINT))
    for item in items:
        parse(item, where)
    return items


def evaluate(params: Parameters, wanted: list[str], timed_out: Callable | None = None) -> dict:
    """Every quantity of ``wanted`` for one scene, each stage computed once on
    COMM_SELF: ``{"values": {name: float | None}, "errors": {name: reason},
    "cpu_s": {stage: s}, "wall_s": {stage: s}}``.  A stage that fails leaves
    its quantities None with the reason; exceptions other than POINT_ERRORS
    (a failure of the machinery) propagate.  ``timed_out() -> reason | None``:
    once it gives a reason, the stage then running (whatever it raised, e.g. a
    PETSc error from a callback that the alarm interrupted) and the stages after
    it fail with that reason."""
    stages: dict[tuple, list] = {}
    for name in wanted:
        quantity, f1 = parse(name)
        stage = ("sweep", f1) if quantity.stage == f"sweep{AT}F1" else (quantity.stage, None)
        stages.setdefault(stage, []).append((name, quantity))
    values, errors, cpu, wall = {}, {}, {}, {}
    try:  # ends.tension_N: the point's own elongation (solvers/tension_target.py)
        from rawehelix.solvers import tension_target
        params = tension_target.resolve(params, _comm())
    except POINT_ERRORS as err:
        reason = f"ends.tension_N: {type(err).__name__}: {err}"
        return {"values": dict.fromkeys(wanted), "errors": dict.fromkeys(wanted, reason),
                "cpu_s": cpu, "wall_s": wall}
    for (stage, f1), members in stages.items():
        label = stage if f1 is None else f"{stage}{AT}{f1:g}"
        late = timed_out() if timed_out else None
        c0, w0 = time.process_time(), time.perf_counter()
        if late:
            result, failure = None, f"{label}: not run, the point {late}"
        else:
            try:
                result, failure = STAGES[stage](params, f1), None
            except POINT_ERRORS as err:
                result, failure = None, f"{label}: {type(err).__name__}: {err}"
            if timed_out and (late := timed_out()):
                result, failure = None, f"{label}: {late}"
            cpu[label], wall[label] = time.process_time() - c0, time.perf_counter() - w0
        for name, quantity in members:
            values[name] = None
            if failure:
                errors[name] = failure
                continue
            try:
                values[name] = float(quantity.pick(result))
            except QuantityError as err:
                errors[name] = f"{label}: {err}"
    return {"values": values, "errors": errors, "cpu_s": cpu, "wall_s": wall}


def table() -> str:
    """The quantities, one a line (for --help and docs/explanation/study.md)."""
    return "\n".join(f"  {q.name:<36} [{q.unit}] ({q.stage}) {q.doc}" for q in AT_A_POINT.values())
