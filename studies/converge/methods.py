"""How the refinement studies evaluate a quantity: the methods (refinement
ladders), one run of a method (:func:`with_method`, each scheme's evaluation
asked of :mod:`rawehelix.studies.schemes`) and the ladders of each quantity.
The quantities themselves, by name, are in the one registry
:mod:`rawehelix.studies.quantities` (their :class:`Refinement`).

An evaluator is a function (params, method, ladder value) -> array of values
that computes no more than it needs: the stationary ones solve the
stationary problem only, the modal one linearises about it and never
integrates in time, the Sec. 5.2 ones integrate the spin-up, and T max the
forced periodic response.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from mpi4py import MPI

from rawehelix.parameters import Parameters
from rawehelix.families import VIBRATIONS
from rawehelix.studies.analysis import metrics
from rawehelix.studies import schemes


@dataclass(frozen=True)
class Method:
    """One curve of the work-precision figure."""

    label: str  # "FE p=3", "spline", ...
    scheme: str  # "fe" or "spline"
    degree: int | None = None
    ladder: tuple = ()  # refinement values: elements N (or dt in s for time schemes)
    variable: str = "elements"  # what the ladder refines: "elements" or "dt_s"
    ts_type: str | None = None  # PETSc TS type for the FE dynamics (default alpha2)
    elements: int | None = None  # fixed N of a time-step ladder

    def resolution(self, value) -> float:
        """A mesh size h (or dt) whose ratio gives the observed order."""
        return 1.0 / value if self.variable == "elements" else float(value)


@dataclass(frozen=True)
class Refinement:
    """How ``rawehelix converge`` refines a quantity: its methods and reference."""

    methods: list
    reference: str  # label of the reference method (its finest run is the reference)
    evaluate: object  # (params, method, ladder value) -> np.ndarray of values
    components: list = field(default_factory=list)
    independent: object = None  # params -> (independent value or None, its status), or None
    # label of the method whose finest run is the reference of the dt ladders
    # (their time error alone, at their N); None: the main reference
    time_reference: str | None = None
    # params -> the scale of the error (|value - reference| / scale) where the
    # value itself can be ~0; None: relative to the reference value
    error_scale: object = None
    scale_note: str = ""


def with_method(params: Parameters, method: Method, value) -> Parameters:
    """The scene with the discretisation (and time step) of one run."""
    disc = {"scheme": method.scheme,
            "elements": int(value) if method.variable == "elements"
            else method.elements or params.discretisation.elements}
    if method.degree is not None:
        disc["degree"] = method.degree
    if method.variable == "elements":
        return params.replace(discretisation=disc)
    return params.replace(discretisation=disc, time={"dt_s": float(value)})


# -- stationary (Sec. 5.1) -------------------------------------------------------------

def tension_s0(params: Parameters, method: Method, value) -> np.ndarray:
    """Stationary tension at s = 0 [N] (Sec. 5.1)."""
    p = with_method(params, method, value)
    return np.array([schemes.of(p).stationary_tension_N(p)])


def shooting_tension_s0(params: Parameters):
    """(T(0) [N] of the shooting reference or None, the check's status): the reference
    where it applies and within its budget (studies/reference_check.py)."""
    from rawehelix.studies import reference_check
    check = reference_check.solve(params)
    if not check.compared:
        return None, check.status
    q = params.normalised()
    return np.array([q.tension_N(check.reference.tension(0.0))]), check.status


def eigenvalues(params: Parameters, method: Method, value) -> np.ndarray:
    """|lambda| [1/s] of the lowest mode of each family (Sec. 5.1, Table 3)."""
    p = with_method(params, method, value)
    q = p.normalised()
    modes = schemes.of(p).spectrum(p, MPI.COMM_SELF, shapes=False).modes
    lowest = {}
    for m in modes:
        lam = abs(complex(m.eigenvalue)) / q.t_scale  # Eq. (25)
        if m.family in VIBRATIONS and lam > 1e-9:
            lowest[m.family] = min(lowest.get(m.family, math.inf), lam)
    return np.array([lowest.get(f, math.nan) for f in VIBRATIONS])


# -- dynamics (Sec. 5.2) -------------------------------------------------------------

SPIN_RUN_S = 15.0  # the spin settles in ~5 s (Fig. 6)
SPIN_SAMPLE_S = 0.005


def _spin_series(params: Parameters, method: Method, value):
    """(t [s], spin [rpm] at s = 0, L0/2, L0) of the Sec. 5.2 run, sampled every
    5 ms, or at every step of a fixed-step (dt ladder) run: cutting its steps to
    land on the sample times would make every dt above 5 ms a 5 ms run."""
    p = with_method(params, method, value)
    return schemes.of(p).spin_series(p, SPIN_RUN_S, SPIN_SAMPLE_S, method.ts_type,
                                     fixed_steps=method.variable == "dt_s")


def spin_overshoot(params: Parameters, method: Method, value) -> np.ndarray:
    """Largest spin at s = 0 above the target [rpm] (Sec. 5.2)."""
    _, spin = _spin_series(params, method, value)
    return np.array([metrics.overshoot(spin[:, 0], params.controller.target_rpm)])


def settling_time(params: Parameters, method: Method, value) -> np.ndarray:
    """When all three spins stay within the settling band of the target [s]
    (Sec. 5.2, :func:`rawehelix.studies.analysis.metrics.settling_time`); nan if they
    have not settled by the end of the run."""
    t, spin = _spin_series(params, method, value)
    settled = metrics.settling_time(t, spin, params.controller.target_rpm)
    return np.array([math.nan if settled is None else settled])


# -- mobile end (Sec. 5.3) -------------------------------------------------------------

TENSION_MAX_F1_HZ = 10.0
#: fixed step of the FE runs refined in space [s]: its time error in T max at
#: 10 Hz is ~0.02 N (1e-4), from 244.658 / 244.460 / 244.397 N at 0.5 / 0.25 /
#: 0.125 ms (N = 8, p = 3, alpha2); the scene's 0.5 ms would put 0.28 N into
#: every space error
TENSION_MAX_SPACE_DT_S = 1.25e-4


def tension_max(params: Parameters, method: Method, value) -> np.ndarray:
    """Maximum tension at s = 0 [N] of the periodic response at f1 = 10 Hz
    (Fig. 8 inset), from the stationary state with a 3 s lead-in; periodic to
    5e-4 of the oscillation T max - T min (4.4 N of 244 N: 1e-5 of T max,
    which moved T max by 2e-6 relative against 1e-4 and 1e-6)."""
    from rawehelix.solvers.periodic import periodic_response
    p = with_method(params, method, value).replace(
        sweep={"lead_in_s": 3.0, "periodic_tolerance": 5e-4})
    scheme = schemes.of(p)
    if method.variable == "elements" and scheme.fixed_time_step:
        p = p.replace(time={"dt_s": TENSION_MAX_SPACE_DT_S})
    q = p.normalised()
    backend = scheme.forced_backend(p, MPI.COMM_SELF, accurate=True, ts_type=method.ts_type)
    result, _, _ = periodic_response(backend, q, TENSION_MAX_F1_HZ, backend.stationary(), 0.0,
                                     p.sweep, lead_in=True)
    return np.array([result.tension_max_N])


# -- the ladders ---------------------------------------------------------------------

#: the Sec. 5.2 spin approaches its target from below (the PD controller of
#: Eq. 40 is well damped): the overshoot is ~0 and its error is measured
#: against the target spin instead
SPIN_SCALE = {"error_scale": lambda params: params.controller.target_rpm,
              "scale_note": "the spin at s = 0 never rises above the target; its largest "
                            "value is within 1e-3 rpm of it at every resolution"}

FE_LADDER = (2, 4, 8, 16, 32, 64)
SPLINE_LADDER = (2, 4, 8, 16, 32)
#: the TS schemes of the dt ladders, with fixed steps [s] at N elements, p = 3
SPIN_DTS = {"alpha2": (0.02, 0.01, 0.005, 0.00125), "cn": (0.02, 0.01, 0.005)}
# cn works on the first-order form, whose Jacobian costs ~9x alpha2's to
# assemble (twice the fields): it gets the longer steps
TENSION_MAX_DTS = {"alpha2": (5e-4, 2.5e-4, 1.25e-4, 3.125e-5), "cn": (1e-3, 5e-4, 2.5e-4)}
DT_LADDER_ELEMENTS = 8


def space_methods(ladder: tuple, spline_ladder: tuple) -> list:
    """FE p = 2, 3, 4 and the spline reference, refined in space (elements N)."""
    return ([Method(f"FE p={p}", "fe", p, ladder) for p in (2, 3, 4)]
            + [Method("spline", "spline", None, spline_ladder)])


def dynamic_methods(ladder_fe, ladder_spline, dts: dict, N: int) -> list:
    """FE p = 2, 3, 4 in space (adaptive alpha2), the spline reference, and two
    TS schemes with fixed steps at N elements, p = 3 (the dt ladder)."""
    return (space_methods(ladder_fe, ladder_spline)
            + [Method(f"FE N={N} p=3 {ts} (dt)", "fe", 3, dts[ts], "dt_s", ts, N)
               for ts in ("alpha2", "cn")])
