"""The numerical sections of a scene: discretisation, time and sweep."""

from __future__ import annotations

import math
from dataclasses import dataclass

from rawehelix.parameters.checks import ParameterError, _non_negative, _positive

#: the largest interior-penalty factor eta: its term's entries grow like eta p^2 mu N^3
#: and its round-off with them; measured with `modes stationary_table2` (N = 16, p = 3):
#: eta = 1e2 to 1e5 move the lowest frequencies by < 1e-6, 1e6 by 1e-5, and at 1e8 the
#: lateral ones come out 20x too high (exit 0); past 1.8e308 / p^2 the form cannot
#: even be compiled ("inf" in the C code)
PENALTY_MAX = 1.0e4

SCHEMES = ("fe", "spline", "network")
#: the schemes that are a model of their own, compared beside the continuum (the FE
#: scheme): the scene's model options (kinematics, section law, damping, ...) are the
#: continuum's and are checked as the FE scheme's (Discretisation.continuum_scheme)
BESIDE_CONTINUUM = ("network",)


def check_scheme(name: str) -> None:
    """Refuse a scheme name that is none of :data:`SCHEMES` (the scene's
    ``discretisation.scheme``, the scheme registry studies/schemes.py)."""
    if name not in SCHEMES:
        raise ParameterError("discretisation.scheme", name, f"must be one of {SCHEMES}")
MESHES = ("uniform", "graded")
BENDINGS = ("ip", "mixed")  # the FE bending operator: forms/rod.py, forms/mixed.py


#: the largest cell quadrature degree a scene may ask for: 3p at p = 8 is 24, UFL's own
#: estimate 20 at p = 3 (forms/rod.py::quadrature_degree)
QUADRATURE_MAX = 40


@dataclass(frozen=True)
class Discretisation:
    # "fe" (FEniCSx, C0 interior penalty), "spline" (paper, Sec. 3) or "network" (the
    # rings and tethers of [section], references/network: stationary and modes, beside the FE)
    scheme: str = "fe"
    elements: int = 16  # N
    degree: int = 3  # Lagrange degree p of the FE scheme (>= 2)
    mesh: str = "uniform"  # "uniform" or "graded" (gmsh, refined toward the ends)
    grading: float = 4.0  # graded mesh: ratio of the largest to the smallest element
    penalty: float = 8.0  # interior-penalty factor eta: penalty = eta p^2 mu / h
    # "ip": C0 interior penalty on r'' (fourth order); "mixed": the curvature
    # kappa = r'' as its own field (Ciarlet-Raviart, second order, docs/explanation/large_n.md)
    bending: str = "ip"
    quadrature_degree: int = 0  # cell quadrature: 0 the rule 3p, -1 UFL's estimate, > 0 that degree

    @property
    def continuum_scheme(self) -> str:
        """The scheme of the continuum a run computes: its own, or "fe" for a scheme
        compared beside it (:data:`BESIDE_CONTINUUM`)."""
        return "fe" if self.scheme in BESIDE_CONTINUUM else self.scheme

    def __post_init__(self):
        check_scheme(self.scheme)
        if self.bending not in BENDINGS:
            raise ParameterError("discretisation.bending", self.bending, f"must be one of {BENDINGS}")
        if self.mesh not in MESHES:
            raise ParameterError("discretisation.mesh", self.mesh, f"must be one of {MESHES}")
        if self.elements < 1:
            raise ParameterError("discretisation.elements", self.elements, "must be an integer >= 1")
        if self.scheme == "spline" and self.elements < 2:
            raise ParameterError("discretisation.elements", self.elements,
                                 "must be >= 2 for the spline scheme")
        if not (2 <= self.degree <= 8):
            raise ParameterError(
                "discretisation.degree", self.degree,
                "must be an integer from 2 to 8 (the bending term needs second derivatives)")
        if not self.grading >= 1:
            raise ParameterError("discretisation.grading", self.grading, "must be >= 1")
        if not (0 < self.penalty <= PENALTY_MAX):
            raise ParameterError("discretisation.penalty", self.penalty,
                                 f"must be a number in (0, {PENALTY_MAX:g}]: a larger one spoils "
                                 "the bending operator by its round-off (parameters.PENALTY_MAX)")
        if not -1 <= self.quadrature_degree <= QUADRATURE_MAX:
            raise ParameterError("discretisation.quadrature_degree", self.quadrature_degree,
                                 f"must be 0 (the rule 3p), -1 (UFL's estimate) or a degree from "
                                 f"1 to {QUADRATURE_MAX} (3p is 24 at p = 8; a rule of degree "
                                 f"262401, which a fuzzed scene asked for, compiles for minutes)")

    def ip_limit(self) -> int:
        """The largest N at which the IP bending form is trusted: 512 (3/p)^(4/3).

        Its Jacobian entries grow like mu p^4 N^3, and the round-off of the
        lowest lateral eigenvalue with them: measured at p = 3 (docs/explanation/large_n.md)
        7.7e-4 at N = 512, 1.9e-2 at N = 1000.  The mixed form has no such limit
        up to N = 10^4."""
        return int(512 * (3 / self.degree) ** (4 / 3))


@dataclass(frozen=True)
class Time:
    """Time integration settings (dynamics and sweeps)."""

    until_s: float = 30.0  # end of the simulation [s]
    dt_s: float = 1.0e-3  # (initial) time step [s]
    output_every_s: float = 0.05  # sampling of the time series [s]
    fields_every_s: float = 0.5  # sampling of the fields along s (XDMF, pictures) [s]

    def __post_init__(self):
        _positive("time", self, "until_s", "dt_s", "output_every_s", "fields_every_s")


def periods_to_judge(record_periods: int) -> int:
    """Periods the periodicity test (solvers/periodic.py's transient) needs before it
    can judge: three blocks of ``record_periods``, and the one before them."""
    return 3 * record_periods + 1


@dataclass(frozen=True)
class Sweep:
    """A sweep over the frequency f1 of the upper end's circle (Sec. 5.3, Fig. 8)."""

    f1_start_Hz: float = 0.5  # first f1 [Hz]
    f1_stop_Hz: float = 15.0  # last f1 (included when on the step) [Hz]
    f1_step_Hz: float = 0.5  # step [Hz]
    lead_in_s: float = 10.0  # simulated time before the first point of a chunk is judged [s]
    periodic_tolerance: float = 1.0e-3  # remainder of the transient / (T max - T min)
    min_periods: int = 4  # periods integrated at each f1 before judging periodicity
    max_periods: int = 500  # cap; a point that hits it is flagged not periodic
    record_periods: int = 4  # periods over which max, min and mean tension are taken
    samples_per_period: int = 64  # tension samples per forcing period

    def __post_init__(self):
        _positive("sweep", self, "f1_start_Hz", "f1_stop_Hz", "f1_step_Hz", "periodic_tolerance")
        _non_negative("sweep", self, "lead_in_s")
        if self.f1_stop_Hz < self.f1_start_Hz:
            raise ParameterError("sweep.f1_stop_Hz", self.f1_stop_Hz, "must be >= sweep.f1_start_Hz")
        for name in ("min_periods", "max_periods", "record_periods"):
            if getattr(self, name) < 1:
                raise ParameterError(f"sweep.{name}", getattr(self, name), "must be an integer >= 1")
        if self.max_periods < self.min_periods or self.record_periods > self.max_periods:
            raise ParameterError("sweep.max_periods", self.max_periods,
                                 "must be >= sweep.min_periods and >= sweep.record_periods")
        if self.samples_per_period < 8:
            raise ParameterError("sweep.samples_per_period", self.samples_per_period,
                                 "must be an integer >= 8")

    @property
    def periods_to_judge(self) -> int:
        """:func:`periods_to_judge` of this sweep's record_periods."""
        return periods_to_judge(self.record_periods)

    def frequencies(self) -> list[float]:
        n = int(math.floor((self.f1_stop_Hz - self.f1_start_Hz) / self.f1_step_Hz + 1e-9))
        return [round(self.f1_start_Hz + k * self.f1_step_Hz, 10) for k in range(n + 1)]
