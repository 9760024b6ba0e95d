"""The periodic-orbit problem: what a method for the periodic orbits of the forced
rod provides, apart from how it discretises the period (in the manner of
BifurcationKit's ``AbstractPeriodicOrbitProblem``, whose ``ShootingProblem``,
``PeriodicOrbitTrapProblem`` and ``PeriodicOrbitOCollProblem`` are continued by
the same ``continuation``).

An orbit at the forcing frequency f1 is a zero of a residual G(X, f1) in the
problem's unknowns X; the pseudo-arclength continuation
(:mod:`rawehelix.periodic_orbits.continuation`) asks a :class:`PeriodicOrbitProblem` for
G, its Jacobians in X and in f1, the problem's Newton at fixed f1 and the orbit
with its Floquet multipliers, and nothing else.  The implementations:

- shooting, :class:`rawehelix.periodic_orbits.floquet.PeriodMap`: X the state at the
  start of the period, G = P(X) - X - Delta e_alpha with P a scheme's period
  map; the FE generalised-alpha map (:class:`rawehelix.solvers.orbits.AlphaMap`)
  and the paper's spline-Galerkin flow
  (:class:`rawehelix.references.spline_galerkin.orbits.SplineMap`).  The
  Jacobian in X is the monodromy less the identity, the multipliers the
  monodromy's eigenvalues, the resolution the steps per period;
- harmonic balance, next to shooting (not yet written): X the Fourier
  coefficients of (U, alpha, ...) up to H harmonics of f1 (the twist's steady
  rotation Delta t / T1 taken out as a known secular term), G the Galerkin
  projection of the rod's residual F(t, U, U_t, U_tt) onto those harmonics,
  evaluated by the alternating frequency-time method on ``resolution`` =
  2H + 1 or more samples per period (the same operator F and its F_U, F_V,
  F_A as the shooting's, :class:`~rawehelix.solvers.rod_operator.RodOperator`,
  at each sample: dG/dX = sum over samples of the DFT of F_U + i k w F_V - k^2
  w^2 F_A), dG/df1 by the chain rule through w = 2 pi f1, the orbit's samples
  its inverse DFT, and the Floquet multipliers by Hill's method (the
  eigenvalues of the Hill matrix sorted by the symmetry of their
  eigenvectors, mu = exp(lambda T1)).  Its internal variables (z of the
  hysteretic torsion) are carried the same way: their rows of dG/dX replaced
  by substitution;
- its linear case, one harmonic about the stationary state with the forcing
  at small amplitude, is the harmonic response of
  :mod:`rawehelix.solvers.response` ((K - w^2 M + i w C) X = f): the shooting
  orbit at small amplitude is that response, its midpoint's lateral ellipse
  and the first harmonic of its samples (T(0)) the response's
  (tests/test_orbits.py, ``test_small_amplitude_orbit_is_the_linear_response``,
  ``test_the_problems_linear_case_is_the_harmonic_response``).

No FE code (numpy only): the spline reference implements it.
"""

from __future__ import annotations

import abc
import contextlib
import dataclasses
from typing import Callable

import numpy as np
import scipy.linalg


#: |mu| within this of 1 is on the unit circle (rounding of an undamped orbit's
#: multipliers), neither growing nor decaying: the stability criterion of every orbit
UNIT_CIRCLE_TOL = 1e-9

#: what a scene without the controller's integral action (k1 = 0, Eq. 40) gets from
#: ``orbits`` and ``envelope``, with the command-line way out (one line): its twist's
#: rotation is free, a family of orbits, so no isolated orbit exists to continue in f1
#: by either method; the shipped forced scenes' gain is k1 = 0.5
FREE_ROTATION = ("without the controller's integral action (k1 = 0, Eq. 40) the twist's "
                 "rotation is free, a family of orbits that no method can continue in f1: add "
                 "to the scene '[controller]' with 'k1 = 0.5' (the shipped scenes' gain), or "
                 "run with --set controller.k1=0.5; 'rawehelix sweep' integrates in time and "
                 "needs no controller")


@dataclasses.dataclass
class Orbit:
    """A periodic orbit at one f1 (normalised state, SI outputs)."""

    f1_Hz: float
    X: np.ndarray  # (U, V, A) at the start of the period, phase 0
    delta: float  # twist rotation per period (normalised)
    tension_max_N: float
    tension_min_N: float
    multipliers: np.ndarray  # Floquet multipliers, by decreasing modulus (the
    # free twist rotation's pair without a controller set aside: symmetry_multiplier)
    newton_iterations: int
    residual: float  # |G| / |X| at the orbit
    steps: int  # steps per period
    wall_s: float
    monodromy: np.ndarray | None = dataclasses.field(default=None, repr=False)  # dP/dX at X
    symmetry_multiplier: complex | None = None  # the free rotation's pair (no controller)
    #: the scheme's periodicity defects at the orbit (``PeriodMap.defects``; {}: none)
    defects: dict = dataclasses.field(default_factory=dict)
    #: multipliers of the carried variables, set aside (``PeriodMap.set_aside``; None: none)
    internal_multipliers: np.ndarray | None = dataclasses.field(default=None, repr=False)
    #: G = P(X) - X - Delta e_alpha at X, from the Floquet period (None: not kept)
    G: np.ndarray | None = dataclasses.field(default=None, repr=False)
    #: dG/dX at X where the problem keeps it apart from a monodromy (harmonic balance)
    jacobian: object = dataclasses.field(default=None, repr=False)
    #: the resolution's own accuracy at the orbit (harmonic balance: H, samples, tail)
    accuracy: dict = dataclasses.field(default_factory=dict)

    def release(self):
        """Drop the matrices only the branch's newest point needs (its tangent's): a
        branch kept every point's, 1.1 MB a point at N = 4 by harmonic balance.  A
        trace started again from a released point has them evaluated again
        (``PeriodicOrbitProblem.jacobian``)."""
        self.monodromy = self.jacobian = self.G = None

    @property
    def max_multiplier(self) -> float:
        return float(np.abs(self.multipliers[0]))

    @property
    def stable(self) -> bool:
        """No multiplier outside the unit circle by more than :data:`UNIT_CIRCLE_TOL`: an
        undamped orbit's multipliers sit on the circle to rounding (|mu| = 1 + 4e-16),
        neutrally stable, not unstable."""
        return self.max_multiplier <= 1.0 + UNIT_CIRCLE_TOL

    def entry(self) -> dict:
        out = {"f1_Hz": self.f1_Hz, "tension_max_N": self.tension_max_N,
               "tension_min_N": self.tension_min_N, "stable": self.stable,
               "max_multiplier": self.max_multiplier,
               "newton_iterations": self.newton_iterations, "residual": self.residual,
               "steps_per_period": self.steps, "wall_s": self.wall_s}
        if self.defects:
            out["defects"] = dict(self.defects)
        if self.accuracy:
            out["accuracy"] = dict(self.accuracy)
        if self.internal_multipliers is not None:
            mu = self.internal_multipliers
            out["internal_multipliers"] = {
                "count": int(mu.size),
                "max_modulus": float(np.abs(mu).max()) if mu.size else None,
                "max_distance_to_1": float(np.abs(mu - 1.0).max()) if mu.size else None}
        return out


@dataclasses.dataclass(frozen=True)
class Observable:
    """A scalar the caller reads off the orbits (BifurcationKit's
    ``record_from_solution``): ``of_samples`` from one period's samples
    (:meth:`PeriodicOrbitProblem.samples`, a corrected point before its
    Floquet period), ``of_orbit`` from a finished :class:`Orbit`; ``name``: its
    key in the events reported.  ``of_samples`` None: an observable of the orbit
    alone, not of the samples (the section along s over a period, issue 29's
    moment_ratio_max): no step guard can read it (:meth:`samples_value`)."""

    name: str
    of_samples: Callable[[np.ndarray], float] | None
    of_orbit: Callable[[Orbit], float]

    def __post_init__(self):
        if not self.name:
            raise ValueError("Observable: a name is needed (the events' key)")

    def samples_value(self, samples) -> float:
        """``of_samples(samples)``; a ValueError for an observable of the orbit alone."""
        if self.of_samples is None:
            raise ValueError(f"Observable {self.name!r}: of a finished orbit only, not of "
                             f"the tension samples")
        return self.of_samples(samples)


class DenseLU:
    """scipy's LU of a dense matrix, with solve(r, transpose)."""

    def __init__(self, K):
        self.lu = scipy.linalg.lu_factor(K)

    def solve(self, r, transpose: bool = False) -> np.ndarray:
        return scipy.linalg.lu_solve(self.lu, r, trans=1 if transpose else 0)


class PeriodicOrbitProblem(abc.ABC):
    """The periodic orbits of the forced rod as a problem in unknowns X and f1 [Hz]
    (see the module docstring).  ``resolution``: the discretisation of the period
    (steps per period, harmonics, samples), an argument of every evaluation so that
    a continuation can hold it over a corrector."""

    #: the internal variables the problem carries: entries of X its Newton does not
    #: solve for but sets to what one period makes of them (floquet.py, "Carried
    #: entries"); their multipliers are reported apart
    carried = np.zeros(0, dtype=int)

    # What the studies read off every problem (set by each method's constructor):

    #: the stationary state as an unknown X: a branch's first orbit starts from it
    #: (studies/orbits.py), and the spline scheme linearises about it
    X_stationary: np.ndarray
    #: the scene's normalised parameters without forcing (parameters/normalised.py, its
    #: steady torque); ``q_base.at_frequency(f1_Hz, 0.0)`` is the forced scene at f1
    q_base: object
    #: the normalised scene at the last f1 evaluated (``q_base`` before any): its
    #: scales turn samples into units (``q.tension_N``, the branch's T max)
    q: object

    @abc.abstractmethod
    def continuable(self) -> None:
        """Raise SolverError if the problem's orbits cannot be continued in f1
        (a family of orbits at each f1)."""

    @abc.abstractmethod
    def resolution(self, f1_Hz: float) -> int:
        """The problem's own discretisation of the period at f1."""

    @abc.abstractmethod
    def residual(self, X, f1_Hz: float, jacobian: bool = False, resolution: int | None = None):
        """(G(X, f1), the orbit's samples over the period, dG/dX or None): dG/dX
        with ``jacobian``, the carried entries' rows those of the substitution."""

    @abc.abstractmethod
    def residual_f1(self, X, f1_Hz: float, resolution: int, G=None) -> np.ndarray:
        """dG/df1 at fixed resolution (``G``: G at (X, f1) if known), zero in the
        carried entries."""

    @abc.abstractmethod
    def jacobian(self, orbit: Orbit) -> np.ndarray:
        """dG/dX at an orbit of :meth:`finish`, as :meth:`residual` gives it."""

    def factor(self, K):
        """A factorisation of K (dG/dX, or the continuation's bordered matrix on it) with
        ``solve(r, transpose=False)``: dense LU here; a problem with sparse Jacobians
        gives its own (harmonic balance: PETSc's)."""
        return DenseLU(K)

    def refine(self, prev: Orbit, orbit: Orbit) -> Orbit | None:
        """Where ``orbit`` (the point after ``prev``) is not resolved to the problem's
        accuracy: raise the resolution for the rest of the branch and return ``prev``
        solved again at it (the continuation retries the step from there); None: it is
        resolved (shooting: the steps per period follow f1 by themselves)."""
        return None

    def embed(self, X, resolution: int) -> np.ndarray:
        """X (or a vector in X's space) at another resolution (:meth:`refine`)."""
        return X

    def resume_from(self, orbit: Orbit) -> None:
        """Take up the resolution of a stored branch's last point (a resumed trace)."""

    def sections(self, X, f1_Hz: float, steps: int | None = None) -> list | None:
        """The section along s over the orbit's period, [(t, section dict)] for its
        limits block (studies/analysis/branch_limits.py); None: the problem has no fields along s
        (the spline reference)."""
        return None

    @abc.abstractmethod
    def norm(self, G, X) -> float:
        """|G| relative to X over the entries the Newton solves for."""

    @abc.abstractmethod
    def settle(self, X, G) -> np.ndarray:
        """X with its carried entries set to what a period makes of them (G at X)."""

    @abc.abstractmethod
    def orbit(self, X0, f1_Hz: float, tol: float = 1e-7, max_it: int = 12,
              steps: int | None = None) -> Orbit:
        """The orbit near X0 at fixed f1 by the problem's own Newton (``steps``: the
        resolution).  A method's own knobs are its own keywords (shooting's lead-in
        and linear chord, floquet.py::PeriodMap.orbit), used by its own
        :meth:`first_orbit` and :meth:`predicted_orbit`."""

    def first_orbit(self, f1_Hz: float) -> Orbit:
        """A branch's first orbit at f1, from the stationary state (``X_stationary``)."""
        return self.orbit(self.X_stationary, f1_Hz)

    def predicted_orbit(self, X, f1_Hz: float, tol: float, max_it: int) -> Orbit:
        """The orbit from a continuation's predicted point (its natural step), at the
        resolution the problem holds at f1."""
        return self.orbit(X, f1_Hz, tol=tol, max_it=max_it, steps=self.resolution(f1_Hz))

    @abc.abstractmethod
    def finish(self, X, f1_Hz: float, iterations: int, residual: float, start: float,
               resolution: int | None = None) -> Orbit:
        """The orbit through the solution X at f1, with its Floquet multipliers,
        its samples' extremes and its Jacobian (``start``: perf_counter at the
        Newton's start, for the wall time)."""

    def deferred_stability(self, last: Orbit):
        """A context in which :meth:`finish` may give an orbit the multipliers of an
        earlier one, until :meth:`stability` says otherwise (a continuation's trace from
        its branch's ``last`` point); default: none (every finish computes them)."""
        return contextlib.nullcontext()

    def stability(self, orbit: Orbit, event: bool) -> None:
        """The orbit's multipliers brought up to date once the continuation has accepted
        it (``event``: a fold just passed, the window's end or a bisection's probe);
        default: nothing (:meth:`finish` computed them)."""

    @abc.abstractmethod
    def multipliers(self, X, f1_Hz: float, resolution: int | None = None) -> np.ndarray:
        """The Floquet multipliers of the orbit through X, by decreasing modulus
        (the internal variables' and a symmetry's set aside)."""

    @abc.abstractmethod
    def samples(self, X, f1_Hz: float, resolution: int | None = None) -> np.ndarray:
        """The orbit's samples over one period from X: the tension at s = 0
        (normalised) at the resolution's times."""
