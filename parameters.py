"""Physical parameters of a helix scene (SI) and their normalisation, Eqs. (25)-(29).

Users read and write SI units only (N, m, s, Nm, rpm, Hz).  Every solver works
in the normalised variables of the paper:

    t~ = t / t_scale,  t_scale = sqrt(L0 / g)         (25)
    s~ = s / L0,  r~ = r / L0,  v~ = v / sqrt(g L0)   (25)

This module is numpy-only: both the FEniCSx path and the independent
references (shooting, spline Galerkin) import it, and nothing else in common.
"""

from __future__ import annotations

import dataclasses
import math
import sys
from dataclasses import dataclass, field

import numpy as np

RPM = 2.0 * math.pi / 60.0  # rad/s per rpm


class ParameterError(ValueError):
    """A parameter is outside its allowed range.

    ``key`` is the dotted scene key (``helix.EA_N``) and ``allowed`` says what
    would be accepted, so that a scene loader can name file, key and range.
    """

    def __init__(self, key: str, value, allowed: str):
        self.key, self.value, self.allowed = key, value, allowed
        super().__init__(f"{key} = {value!r}: {allowed}")


def _positive(section: str, obj, *names: str) -> None:
    for name in names:
        value = getattr(obj, name)
        if not (value > 0 and math.isfinite(value)):
            raise ParameterError(f"{section}.{name}", value, "must be a finite number > 0")


def _non_negative(section: str, obj, *names: str) -> None:
    for name in names:
        value = getattr(obj, name)
        if not (value >= 0 and math.isfinite(value)):
            raise ParameterError(f"{section}.{name}", value, "must be a finite number >= 0")


@dataclass(frozen=True)
class EILaw:
    """Tension-dependent bending stiffness, EI = a T + b at the local tension
    T = EA eps (Eq. 64 and Fig. 4 of the paper: a = 52.4 Nm^2/N, b = 2290 Nm^2
    from the lab's bending tests at T_e = 90, 181, 259 N); forms/extensible.py.
    a >= 0 and b > 0, so EI > 0 at every tension T > -b/a."""

    a_Nm2_per_N: float  # a = dEI/dT [N m^2 / N]
    b_Nm2: float  # b = EI at zero tension [N m^2]

    def __post_init__(self):
        _non_negative("helix.EI_law", self, "a_Nm2_per_N")
        _positive("helix.EI_law", self, "b_Nm2")

    def EI_Nm2(self, tension_N):
        """EI = a T + b [N m^2] at the tension T [N]."""
        return self.a_Nm2_per_N * tension_N + self.b_Nm2

    def describe(self) -> str:
        return f"EI law: EI = {self.a_Nm2_per_N:g} Nm^2/N x T + {self.b_Nm2:g} Nm^2"

    def failure_hint(self, EA_N: float) -> str:
        """What a failed solve with the law should be told: its stored energy
        1/2 EA eps^2 + 1/2 (a EA eps + b) kappa^2 is convex only while kappa^2 <
        EI / (a^2 EA) (forms/extensible.py), and a driven or loaded rod may pass it."""
        if self.a_Nm2_per_N == 0:
            return ""
        limit = (self.b_Nm2 / (self.a_Nm2_per_N**2 * EA_N)) ** 0.5
        return (f" With helix.EI_law the rod's stored energy is convex only while the "
                f"curvature kappa < sqrt(EI / EA) / a ({limit:.3g} 1/m at zero tension, "
                f"growing with sqrt(EI(T))); where the rod's curvature passes it the model "
                f"has no stable state and a smaller step will not help: try smaller loads or "
                f"amplitudes, or a smaller a.")


#: the law the paper measured, Eq. (64) and Fig. 4: EI = 52.4 T + 2290
PAPER_EI_LAW = EILaw(a_Nm2_per_N=52.4, b_Nm2=2290.0)


@dataclass(frozen=True)
class Helix:
    """The rod: Tables 1, 2 and 4 of the paper.

    ``EI_law`` (None: off) makes the bending stiffness a function of the local
    tension (:class:`EILaw`; a scene's ``EI_law = {a_Nm2_per_N = .., b_Nm2 = ..}``).
    EI_Nm2 then still sets the sections' rotational inertia (delta, Eq. 27,
    2 rho I = 2 M EI / (EA L0)) and the normalisation mu of Eq. (26); the
    bending stiffness is the law's."""

    length_m: float  # L0, unstretched length [m]
    mass_kg: float  # M, total mass [kg]
    EA_N: float  # axial stiffness [N]
    EI_Nm2: float  # bending stiffness [N m^2]
    GJ_Nm2: float  # torsional stiffness [N m^2]
    radius_m: float = 0.19  # R, helix radius [m]: drawing only (delta uses Eq. 27)
    drag_length_m: float = 0.012  # l_a, sum of the bar diameters [m], Eq. (14)
    drag_coefficient: float = 1.0  # C_D, Eq. (14)
    EI_law: EILaw | None = None  # EI = a T + b (Eq. 64); None: EI = EI_Nm2

    def __post_init__(self):
        _positive("helix", self, "length_m", "mass_kg", "EA_N", "EI_Nm2", "GJ_Nm2", "radius_m")
        _non_negative("helix", self, "drag_length_m", "drag_coefficient")
        if self.EI_Nm2 / self.EA_N / self.length_m > self.length_m:
            # a rod (Eqs. 30-34) is slender: the radius of gyration sqrt(EI/EA) of its
            # sections is far below its length (Table 2: 0.6 m of 16 m); past L0 no
            # rod model holds, and the solves fail (EI = 1e20: the Newton step's
            # linear solve diverges)
            raise ParameterError("helix.EI_Nm2", self.EI_Nm2,
                                 f"must be at most helix.EA_N x helix.length_m^2 = "
                                 f"{self.EA_N * self.length_m * self.length_m:.4g} (a slender "
                                 f"rod: sqrt(EI/EA) <= L0)")
        law = self.EI_law
        if isinstance(law, dict):  # {a_Nm2_per_N, b_Nm2}, as in a scene
            names = [f.name for f in dataclasses.fields(EILaw)]
            unknown = sorted(set(law) - set(names))
            missing = [n for n in names if n not in law]
            if unknown or missing:
                raise ParameterError("helix.EI_law", law, f"must have exactly the keys {names}")
            for name in names:
                if isinstance(law[name], bool) or not isinstance(law[name], (int, float)):
                    raise ParameterError(f"helix.EI_law.{name}", law[name], "must be a number")
                if abs(law[name]) > sys.float_info.max:  # an int no float can hold
                    raise ParameterError(f"helix.EI_law.{name}", law[name],
                                         "must be a finite number")
            object.__setattr__(self, "EI_law", EILaw(**{n: float(law[n]) for n in names}))
        elif law is not None and not isinstance(law, EILaw):
            raise ParameterError("helix.EI_law", law,
                                 "must be None or {a_Nm2_per_N = .., b_Nm2 = ..}")


@dataclass(frozen=True)
class Environment:
    g_m_s2: float = 9.81  # gravity [m/s^2]
    air_density_kg_m3: float = 1.225  # rho_0 [kg/m^3]
    wind_speed_m_s: float = 0.0  # v_w0: wind is -v_w0 i_E [m/s]

    def __post_init__(self):
        _positive("environment", self, "g_m_s2")
        _non_negative("environment", self, "air_density_kg_m3")
        if not math.isfinite(self.wind_speed_m_s):
            raise ParameterError("environment.wind_speed_m_s", self.wind_speed_m_s, "must be finite")


@dataclass(frozen=True)
class Ends:
    """Prescribed end positions, Eqs. (35), (36), (66) and (70)."""

    elongation: float  # eps0: chord = (1 + eps0) L0
    elevation_deg: float  # Gamma0, elevation of the chord [deg]
    circle_radius_m: float = 0.0  # R1, radius of the upper end's circle, Eq. (70) [m]
    circle_frequency_Hz: float = 0.0  # f1, frequency of the upper end's circle [Hz]

    def __post_init__(self):
        # The straight-chord tension EA*eps0 must be > 0: a slack helix has no
        # stationary state in this model (the tension law, Eq. 22, is linear).
        if not (self.elongation > 0 and math.isfinite(self.elongation)):
            raise ParameterError(
                "ends.elongation", self.elongation,
                "must be > 0 (the tension EA*elongation must be positive)")
        if not (-90.0 <= self.elevation_deg <= 90.0):
            raise ParameterError("ends.elevation_deg", self.elevation_deg, "must lie in [-90, 90]")
        _non_negative("ends", self, "circle_radius_m", "circle_frequency_Hz")


@dataclass(frozen=True)
class Torque:
    """Torque at the upper end, the ramp of Eq. (69)."""

    top_Nm: float = 0.0  # M_N0, final torque of the rotor [Nm]
    rise_time_s: float = 2.565  # t0 in Eq. (69) [s]

    def __post_init__(self):
        if not math.isfinite(self.top_Nm):
            raise ParameterError("torque.top_Nm", self.top_Nm, "must be finite")
        _positive("torque", self, "rise_time_s")


@dataclass(frozen=True)
class Controller:
    """Ground-torque PD controller, Eq. (40); k1 = k2 = 0 switches it off."""

    k1: float = 0.0  # proportional gain on the spin error (normalised)
    k2: float = 0.0  # derivative gain (normalised)
    target_rpm: float = 0.0  # alpha_dot* [rpm]

    def __post_init__(self):
        _non_negative("controller", self, "k1", "k2")
        if not math.isfinite(self.target_rpm):
            raise ParameterError("controller.target_rpm", self.target_rpm, "must be finite")

    @property
    def active(self) -> bool:
        return self.k1 > 0 or self.k2 > 0


@dataclass(frozen=True)
class Damping:
    """Structural damping, Kelvin-Voigt on the strain rates (forms/damping.py): each
    viscous stress is the elastic modulus x the retardation time x the strain rate.
    A scene's ``[damping]`` section; all zero (the default) is the paper's model."""

    axial_s: float = 0.0  # tau_a: N_v = EA tau_a d|r'|/dt [s]
    bending_s: float = 0.0  # tau_b: m_v = EI tau_b (objective rate of the curvature) [s]
    torsion_s: float = 0.0  # tau_t: M_v = GJ tau_t d(tau)/dt [s]

    def __post_init__(self):
        _non_negative("damping", self, "axial_s", "bending_s", "torsion_s")

    @property
    def active(self) -> bool:
        return self.axial_s > 0 or self.bending_s > 0 or self.torsion_s > 0

    def describe(self) -> str:
        return (f"damping: Kelvin-Voigt tau_a = {self.axial_s:g} s, tau_b = {self.bending_s:g} s, "
                f"tau_t = {self.torsion_s:g} s")


@dataclass(frozen=True)
class TorsionHysteresis:
    """Hysteretic torsion (forms/hysteresis.py): a Bouc-Wen internal twist z in the
    torsional moment.  A scene's ``[torsion_hysteresis]`` section; ``rho`` = 1 (the
    default) is the paper's elastic moment GJ tau (Eq. 65) and leaves z out.

        M = GJ (rho tau + (1 - rho) z),
        dz/dt = A dtau/dt - beta |dtau/dt| |z|^(n-1) z - gamma dtau/dt |z|^n

    (Bouc 1967 in Wen's 1976 form; tau and z in rad/m, t in s).  Its loop is bounded
    (|z| <= z_u = (A / (beta + gamma))^(1/n)) and dissipates (Wen's condition) when
    beta > 0 and -beta <= gamma <= beta."""

    rho: float = 1.0  # the elastic share of GJ, in (0, 1]; 1: off [-]
    A: float = 1.0  # the slope dz/dtau at z = 0: virgin tangent GJ (rho + (1 - rho) A) [-]
    beta_m_n: float = 0.0  # beta, units (m/rad)^n: the loop's width [(m/rad)^n]
    gamma_m_n: float = 0.0  # gamma, units (m/rad)^n: its shape (> 0 softens on loading) [(m/rad)^n]
    n: float = 1.0  # exponent: the sharpness of the yield, >= 1 [-]

    def __post_init__(self):
        if not (0 < self.rho <= 1):
            raise ParameterError("torsion_hysteresis.rho", self.rho, "must lie in (0, 1]")
        _positive("torsion_hysteresis", self, "A")
        if not (self.n >= 1 and math.isfinite(self.n)):
            raise ParameterError("torsion_hysteresis.n", self.n, "must be a finite number >= 1")
        for name in ("beta_m_n", "gamma_m_n"):
            if not math.isfinite(getattr(self, name)):
                raise ParameterError(f"torsion_hysteresis.{name}", getattr(self, name),
                                     "must be finite")
        if self.active and not (self.beta_m_n > 0 and abs(self.gamma_m_n) <= self.beta_m_n):
            raise ParameterError(
                "torsion_hysteresis.gamma_m_n", self.gamma_m_n,
                f"with torsion_hysteresis.rho = {self.rho!r} < 1 (hysteresis on) needs "
                f"beta_m_n = {self.beta_m_n!r} > 0 and -beta_m_n <= gamma_m_n <= beta_m_n "
                "(Wen 1976: a bounded, dissipative loop)")

    @property
    def active(self) -> bool:
        return self.rho < 1

    def describe(self) -> str:
        return (f"torsion hysteresis: Bouc-Wen rho = {self.rho:g}, A = {self.A:g}, "
                f"beta = {self.beta_m_n:g}, gamma = {self.gamma_m_n:g} (m/rad)^n, n = {self.n:g}")


GAMMA_TREATMENTS = ("regularised", "off")
KINEMATICS = ("paper", "extensible")  # forms/rod.py (Eqs. 30-33), forms/extensible.py


@dataclass(frozen=True)
class Model:
    """Which physics terms a scene switches on."""

    gravity: bool = True  # gravity, the weight term of Eq. (30)
    drag: bool = True  # air drag, Eq. (14)
    bending: bool = True  # the bending stiffness EI, Eqs. (32)-(33)
    # the twist field alpha and its equation (31); false (a torque-free scene,
    # FE scheme) holds alpha = 0: no torsional modes, no twist coupling
    twist: bool = True
    # Frenet torsion gamma, Eq. (34): "off" (the paper's own code) or
    # "regularised" (see forms.kinematics.frenet_torsion).  "off" is the default:
    # at the planar stationary states the regularised coupling shifts the
    # out-of-plane and torsional frequencies by ~0.2 % and makes torsional
    # modes grow (Re lambda ~ +1.5e-4 and more), an artefact of the Frenet frame
    # of an almost straight curve (docs/explanation/modal_convergence.md).
    gamma: str = "off"
    # "auto": solve a reduced model where the scene allows it (the planar (x, z)
    # rod for a planar, torque-free stationary state); "off": always the full one
    reduction: str = "auto"
    gamma_eps: float = 1.0e-3  # regularisation of |r''|^2 in gamma (normalised curvature)
    # "paper": the forces of Eqs. (30)-(33) (bending acts on the whole r, the
    # tension force is T r'); "extensible": stretch and bending from the stored
    # energy 1/2 EA eps^2 + 1/2 EI |t'|^2, t = r'/|r'| (forms/extensible.py)
    kinematics: str = "paper"
    # structural damping: the scene's [damping] section (studies/scene.py puts it here)
    damping: Damping = field(default_factory=Damping)
    # hysteretic torsion: the scene's [torsion_hysteresis] section (studies/scene.py)
    torsion_hysteresis: TorsionHysteresis = field(default_factory=TorsionHysteresis)

    def describe(self, planar: bool = False) -> str:
        """The model that runs, for summary.json: reduction and the terms switched on."""
        if planar:
            head = ("planar (x, z): the ends lie in the x-z plane and carry no torque, so the "
                    "stationary state is planar with alpha = 0 (Sec. 5.1)")
        elif not self.twist:
            head = "centre line only (model.twist = false: alpha = 0, no torsional modes)"
        else:
            head = "full (r, alpha)"
        terms = [name for name in ("gravity", "drag", "bending") if getattr(self, name)]
        if self.gamma != "off" and self.twist and not planar:
            terms.append(f"gamma ({self.gamma})")
        text = (f"{head}; terms: {', '.join(terms) or 'tension only'}; "
                f"kinematics: {self.kinematics}")
        extras = [x.describe() for x in (self.damping, self.torsion_hysteresis) if x.active]
        return "; ".join([text, *extras])

    def __post_init__(self):
        if self.gamma not in GAMMA_TREATMENTS:
            raise ParameterError("model.gamma", self.gamma, f"must be one of {GAMMA_TREATMENTS}")
        if self.reduction not in ("auto", "off"):
            raise ParameterError("model.reduction", self.reduction, "must be one of ('auto', 'off')")
        if self.kinematics not in KINEMATICS:
            raise ParameterError("model.kinematics", self.kinematics, f"must be one of {KINEMATICS}")
        _positive("model", self, "gamma_eps")


#: model switches added after results were stored (sweep checkpoints, the
#: convergence cache): left out of :meth:`Parameters.as_dict` at their
#: defaults, so that those results keep their fingerprints
LATER_MODEL_SWITCHES = {"kinematics": "paper", "damping": dataclasses.asdict(Damping()),
                        "torsion_hysteresis": dataclasses.asdict(TorsionHysteresis())}
#: the same for the helix section
LATER_HELIX_SWITCHES = {"EI_law": None}

#: the largest interior-penalty factor eta: its term's entries grow like eta p^2 mu N^3
#: and its round-off with them; measured with `modes stationary_table2` (N = 16, p = 3):
#: eta = 1e2 to 1e5 move the lowest frequencies by < 1e-6, 1e6 by 1e-5, and at 1e8 the
#: lateral ones come out 20x too high (exit 0); past 1.8e308 / p^2 the form cannot
#: even be compiled ("inf" in the C code)
PENALTY_MAX = 1.0e4

SCHEMES = ("fe", "spline")
MESHES = ("uniform", "graded")
BENDINGS = ("ip", "mixed")  # the FE bending operator: forms/rod.py, forms/mixed.py


@dataclass(frozen=True)
class Discretisation:
    scheme: str = "fe"  # "fe" (FEniCSx, C0 interior penalty) or "spline" (paper, Sec. 3)
    elements: int = 16  # N
    degree: int = 3  # Lagrange degree p of the FE scheme (>= 2)
    mesh: str = "uniform"  # "uniform" or "graded" (gmsh, refined toward the ends)
    grading: float = 4.0  # graded mesh: ratio of the largest to the smallest element
    penalty: float = 8.0  # interior-penalty factor eta: penalty = eta p^2 mu / h
    # "ip": C0 interior penalty on r'' (fourth order); "mixed": the curvature
    # kappa = r'' as its own field (Ciarlet-Raviart, second order, docs/explanation/large_n.md)
    bending: str = "ip"
    quadrature_degree: int = 0  # cell quadrature: 0 the rule 3p, -1 UFL's estimate, > 0 that degree

    def __post_init__(self):
        if self.scheme not in SCHEMES:
            raise ParameterError("discretisation.scheme", self.scheme, f"must be one of {SCHEMES}")
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
        if self.quadrature_degree < -1:
            raise ParameterError("discretisation.quadrature_degree", self.quadrature_degree,
                                 "must be 0 (the rule 3p), -1 (UFL's estimate) or a degree >= 1")

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

    def frequencies(self) -> list[float]:
        n = int(math.floor((self.f1_stop_Hz - self.f1_start_Hz) / self.f1_step_Hz + 1e-9))
        return [round(self.f1_start_Hz + k * self.f1_step_Hz, 10) for k in range(n + 1)]


@dataclass(frozen=True)
class Parameters:
    """Everything physical and numerical about one scene, in SI units."""

    helix: Helix
    ends: Ends
    environment: Environment = field(default_factory=Environment)
    torque: Torque = field(default_factory=Torque)
    controller: Controller = field(default_factory=Controller)
    model: Model = field(default_factory=Model)
    discretisation: Discretisation = field(default_factory=Discretisation)
    time: Time = field(default_factory=Time)
    sweep: Sweep = field(default_factory=Sweep)
    name: str = "scene"  # the scene file's stem: labels outputs, changes no number
    title: str = ""  # the scene's title, for figures

    def __post_init__(self):
        if not self.model.twist:
            # model.twist = false removes the twist field: alpha = 0 everywhere
            if self.torque.top_Nm != 0 or self.controller.active:
                raise ParameterError("model.twist", False,
                                     "needs a torque-free scene (torque.top_Nm = 0, controller off): "
                                     "torque is carried by the twist, Eq. (31)")
            if self.discretisation.scheme != "fe":
                raise ParameterError("model.twist", False, "is implemented by the FE scheme only")
        if self.model.kinematics == "extensible" and (
                self.discretisation.scheme != "fe" or self.discretisation.bending != "ip"):
            raise ParameterError("model.kinematics", "extensible",
                                 "is implemented by the FE scheme with discretisation.bending "
                                 "= 'ip' only (forms/extensible.py)")
        if self.helix.EI_law is not None and self.model.kinematics != "extensible":
            raise ParameterError(
                "helix.EI_law", self.helix.EI_law,
                "needs model.kinematics = 'extensible': the law is built from the stored "
                "energy 1/2 EI(eps) kappa^2, whose variation gives the axial force its "
                "1/2 EI'(eps) kappa^2; the paper's forces (Eqs. 32-33) are not the "
                "variation of an energy and act with EI on axial motion (forms/extensible.py)")
        if self.model.damping.active and (
                self.discretisation.scheme != "fe" or self.discretisation.bending != "ip"):
            raise ParameterError("damping", self.model.damping,
                                 "structural damping is implemented by the FE scheme with "
                                 "discretisation.bending = 'ip' only (forms/damping.py)")
        if self.model.torsion_hysteresis.active and (
                self.discretisation.scheme != "fe" or self.discretisation.bending != "ip"
                or not self.model.twist):
            raise ParameterError("torsion_hysteresis", self.model.torsion_hysteresis,
                                 "hysteretic torsion is implemented by the FE scheme with "
                                 "discretisation.bending = 'ip' and model.twist = true only "
                                 "(forms/hysteresis.py)")

        self._check_groups()

    def _check_groups(self):
        """The groups of Eqs. (25)-(29) a solve starts from must be floats: finite,
        and not 0 where the values they scale are not (:data:`GROUP_KEYS`)."""
        q = Normalised.from_parameters(self)
        for group, (formula, equation, numerators, others) in GROUP_KEYS.items():
            scaled = [self.value(k) for k in numerators]
            value = getattr(q, group)
            if None in scaled or math.isfinite(value) and (value != 0 or 0 in scaled):
                continue
            keys = [*numerators, *others]
            # named: the key of the most extreme size, the likeliest culprit
            culprit = max(keys, key=lambda k: abs(math.log10(abs(self.value(k)) or 1.0)))
            raise ParameterError(
                culprit, self.value(culprit),
                f"makes {group} = {formula} = {value!r} ({equation}), out of a float's range "
                f"(1e-308 to 1e308): {', '.join(keys)} must keep it finite and not 0")

    def value(self, key: str):
        """The value of a dotted scene key (``damping.axial_s``, ``helix.EI_law.b_Nm2``);
        None below an absent EI law."""
        section, *names = key.split(".")
        obj = getattr(self, section) if hasattr(self, section) else getattr(self.model, section)
        for name in names:
            obj = None if obj is None else getattr(obj, name)
        return obj

    def replace(self, **sections) -> "Parameters":
        """A copy with some fields of some sections changed:
        ``p.replace(discretisation={"elements": 32})``; ``damping={...}`` changes
        the model's damping (the scene's ``[damping]`` section), ``torsion_hysteresis={...}``
        its hysteretic torsion."""
        sections = dict(sections)
        for nested in ("damping", "torsion_hysteresis"):  # held by Model
            if nested in sections:
                value = dataclasses.replace(getattr(self.model, nested), **sections.pop(nested))
                sections["model"] = {**sections.get("model", {}), nested: value}
        changed = {name: values if isinstance(values, str)
                   else dataclasses.replace(getattr(self, name), **values)
                   for name, values in sections.items()}
        return dataclasses.replace(self, **changed)

    def as_dict(self) -> dict:
        """Every section as plain data, without the labels (name, title): what
        fingerprints of results hash."""
        data = dataclasses.asdict(self)
        data.pop("name")
        data.pop("title")
        for section, switches in (("model", LATER_MODEL_SWITCHES),
                                  ("helix", LATER_HELIX_SWITCHES)):
            for key, default in switches.items():  # fingerprints stored before them
                if data[section][key] == default:
                    data[section].pop(key)
        return data

    def normalised(self) -> "Normalised":
        return Normalised.from_parameters(self)

    def describe_model(self, planar: bool = False) -> str:
        """:meth:`Model.describe` and the helix's EI law when it has one: summary.json's "model"."""
        text = self.model.describe(planar)
        return text if self.helix.EI_law is None else f"{text}; {self.helix.EI_law.describe()}"


_L0, _M, _g, _GJ = "helix.length_m", "helix.mass_kg", "environment.g_m_s2", "helix.GJ_Nm2"
_T = (_L0, _g)  # t_scale = sqrt(L0/g)
#: the normalised groups made of more than one scene value, Eqs. (25)-(29): group ->
#: (formula, equation, the keys whose values it scales, the keys it is scaled by);
#: Parameters refuses a scene whose group is not finite, or 0 where those it
#: scales are not (a float's range is exceeded)
GROUP_KEYS = {
    "t_scale": ("sqrt(L0/g)", "Eq. 25", (_L0,), (_g,)),
    "force_scale": ("M g", "Eq. 29", (_M, _g), ()),
    "torque_scale": ("GJ/L0", "Eqs. 38-39", (_GJ,), (_L0,)),
    "sigma": ("EA/(M g)", "Eq. 27", ("helix.EA_N",), (_M, _g)),
    "mu": ("EI/(M g L0^2)", "Eq. 26", ("helix.EI_Nm2",), (_M, _g, _L0)),
    "beta": ("GJ/(M g L0^2)", "Eq. 26", (_GJ,), (_M, _g, _L0)),
    "nu": ("rho0 l_a L0^2 C_D/(2 M)", "Eq. 26",
           ("environment.air_density_kg_m3", "helix.drag_length_m", "helix.drag_coefficient"),
           (_L0, _M)),
    "delta": ("beta sigma/(2 mu)", "Eq. 27", (_GJ, "helix.EA_N"), ("helix.EI_Nm2", _M, _g)),
    "v_w0": ("v_w0/sqrt(g L0)", "Eq. 27", ("environment.wind_speed_m_s",), _T),
    "r1": ("R1/L0", "Eq. 70", ("ends.circle_radius_m",), (_L0,)),
    "omega1": ("2 pi f1 sqrt(L0/g)", "Eq. 70", ("ends.circle_frequency_Hz",), _T),
    "mN0": ("M_N0 L0/GJ", "Eq. 69", ("torque.top_Nm",), (_L0, _GJ)),
    "t0": ("t0/sqrt(L0/g)", "Eq. 69", ("torque.rise_time_s",), _T),
    "spin_target": ("alpha_dot* sqrt(L0/g)", "Eq. 40", ("controller.target_rpm",), _T),
    "tau_axial": ("tau_a/sqrt(L0/g)", "Eq. 25", ("damping.axial_s",), _T),
    "tau_bending": ("tau_b/sqrt(L0/g)", "Eq. 25", ("damping.bending_s",), _T),
    "tau_torsion": ("tau_t/sqrt(L0/g)", "Eq. 25", ("damping.torsion_s",), _T),
    "mu_per_tension": ("a/L0^2", "Eq. 64", ("helix.EI_law.a_Nm2_per_N",), (_L0,)),
    "mu_at_zero_tension": ("b/(M g L0^2)", "Eq. 64", ("helix.EI_law.b_Nm2",), (_M, _g, _L0)),
    "bw_beta": ("beta/L0^n", "Eq. 25", ("torsion_hysteresis.beta_m_n",),
                (_L0, "torsion_hysteresis.n")),
    "bw_gamma": ("gamma/L0^n", "Eq. 25", ("torsion_hysteresis.gamma_m_n",),
                 (_L0, "torsion_hysteresis.n")),
}


@dataclass(frozen=True)
class Normalised:
    """The dimensionless groups of Eqs. (25)-(29) and the scales to undo them."""

    # scales
    L0: float  # [m]
    t_scale: float  # sqrt(L0/g) [s], Eq. (25)
    force_scale: float  # M g [N], Eq. (29)
    torque_scale: float  # GJ / L0 [Nm], Eqs. (38)-(39)
    # groups
    sigma: float  # EA / (M g), Eq. (27)
    mu: float  # EI / (M g L0^2), Eq. (26)
    beta: float  # GJ / (M g L0^2), Eq. (26)
    nu: float  # rho0 l_a L0^2 C_D / (2 M), Eq. (26)
    delta: float  # beta sigma / (2 mu), Eq. (27)
    v_w0: float  # v_w0 / sqrt(g L0), Eq. (27)
    # ends
    eps0: float
    Gamma0: float  # [rad]
    r1: float  # R1 / L0, Eq. (70)
    omega1: float  # 2 pi f1 t_scale, Eq. (70)
    phase0: float  # phase of the circle at t~ = 0: omega1 t~ + phase0 in Eq. (70) [rad]
    # torque ramp (69) and controller (40)
    mN0: float
    t0: float
    k1: float
    k2: float
    spin_target: float  # alpha_dot* t_scale
    # switches
    gravity: float
    drag: float
    bending: float
    # structural damping: the retardation times / t_scale (0: off), forms/damping.py
    tau_axial: float = 0.0
    tau_bending: float = 0.0
    tau_torsion: float = 0.0
    # the EI law (helix.EI_law): mu = mu_per_tension T~ + mu_at_zero_tension at the
    # local normalised tension T~ = sigma eps, i.e. a / L0^2 and b / (M g L0^2)
    bending_law: bool = False
    mu_per_tension: float = 0.0
    mu_at_zero_tension: float = 0.0
    # hysteretic torsion (forms/hysteresis.py): tau~ = tau L0 and z~ = z L0, so
    # beta~ = beta / L0^n and gamma~ = gamma / L0^n; rho = 1: off
    bw_rho: float = 1.0
    bw_A: float = 1.0
    bw_beta: float = 0.0
    bw_gamma: float = 0.0
    bw_n: float = 1.0

    @property
    def damped(self) -> bool:
        return self.tau_axial > 0 or self.tau_bending > 0 or self.tau_torsion > 0

    @property
    def hysteretic(self) -> bool:
        return self.bw_rho < 1

    @classmethod
    def from_parameters(cls, p: Parameters) -> "Normalised":
        """The groups of ``p``; a group past the float range is inf, 0 or nan here
        (numpy arithmetic, IEEE as Python's floats), never an exception:
        :meth:`Parameters.__post_init__` refuses such a scene with :data:`GROUP_KEYS`."""
        with np.errstate(all="ignore"):
            q = cls._groups(p)
        return dataclasses.replace(q, **{f.name: float(getattr(q, f.name))
                                         for f in dataclasses.fields(q)
                                         if isinstance(getattr(q, f.name), np.floating)})

    @classmethod
    def _groups(cls, p: Parameters) -> "Normalised":
        h, e, env = p.helix, p.ends, p.environment
        law = h.EI_law
        L0, M, g = np.float64(h.length_m), np.float64(h.mass_kg), np.float64(env.g_m_s2)
        t_scale = np.sqrt(L0 / g)  # (25)
        mu = h.EI_Nm2 / (M * g * L0**2)  # (26)
        beta = h.GJ_Nm2 / (M * g * L0**2)  # (26)
        sigma = h.EA_N / (M * g)  # (27)
        bw = p.model.torsion_hysteresis
        return cls(
            L0=L0, t_scale=t_scale, force_scale=M * g, torque_scale=h.GJ_Nm2 / L0,
            sigma=sigma, mu=mu, beta=beta,
            nu=env.air_density_kg_m3 * h.drag_length_m * L0**2 * h.drag_coefficient / (2 * M),
            delta=beta * sigma / (2 * mu),  # (27)
            v_w0=env.wind_speed_m_s / np.sqrt(g * L0),
            eps0=e.elongation, Gamma0=math.radians(e.elevation_deg),
            r1=e.circle_radius_m / L0, omega1=2 * math.pi * e.circle_frequency_Hz * t_scale,
            phase0=0.0,
            mN0=p.torque.top_Nm / (h.GJ_Nm2 / L0), t0=p.torque.rise_time_s / t_scale,
            k1=p.controller.k1, k2=p.controller.k2,
            spin_target=p.controller.target_rpm * RPM * t_scale,
            gravity=float(p.model.gravity), drag=float(p.model.drag),
            bending=float(p.model.bending),
            tau_axial=p.model.damping.axial_s / t_scale,
            tau_bending=p.model.damping.bending_s / t_scale,
            tau_torsion=p.model.damping.torsion_s / t_scale,
            bending_law=law is not None,
            mu_per_tension=0.0 if law is None else law.a_Nm2_per_N / L0**2,
            mu_at_zero_tension=0.0 if law is None else law.b_Nm2 / (M * g * L0**2),
            bw_rho=bw.rho, bw_A=bw.A, bw_beta=bw.beta_m_n / L0**bw.n,
            bw_gamma=bw.gamma_m_n / L0**bw.n, bw_n=bw.n,
        )

    # -- units back to SI ---------------------------------------------------
    def tension_N(self, T):
        return np.asarray(T) * self.force_scale

    def torque_Nm(self, m):
        return np.asarray(m) * self.torque_scale

    def time_s(self, t):
        return np.asarray(t) * self.t_scale

    def length_m(self, x):
        return np.asarray(x) * self.L0

    def spin_rpm(self, alpha_t):
        return np.asarray(alpha_t) / self.t_scale / RPM

    # -- boundary data ------------------------------------------------------
    def top_position(self, t: float = 0.0) -> np.ndarray:
        """r~(1, t~): Eq. (66), with the circle of Eq. (70) when r1 > 0."""
        c, s = math.cos(self.Gamma0), math.sin(self.Gamma0)
        a = 1.0 + self.eps0
        sw, cw = math.sin(self.phase(t)), math.cos(self.phase(t))
        r1 = self.r1
        return np.array([-(a * c + r1 * s * sw), r1 * cw, -(a * s - r1 * c * sw)])

    def phase(self, t: float) -> float:
        """omega1 t~ + phase0, the angle of the upper end on its circle, Eq. (70)."""
        return self.omega1 * t + self.phase0

    def at_frequency(self, f1_Hz: float, t_start: float = 0.0) -> "Normalised":
        """The same scene with the circle at f1, at phase 0 at time t~ = t_start.

        A sweep keeps time running (torque ramp, controller) and restarts the
        circle's phase at each new frequency, so the end does not jump."""
        omega1 = 2 * math.pi * f1_Hz * self.t_scale
        return dataclasses.replace(self, omega1=omega1, phase0=-omega1 * t_start)

    @property
    def moving_end(self) -> bool:
        """Does the upper end move on its circle (Eq. 70: R1 > 0 and f1 > 0)?"""
        return self.r1 > 0 and self.omega1 > 0

    def top_velocity(self, t: float = 0.0) -> np.ndarray:
        """d r~(1, t~)/dt~ of Eq. (70)."""
        c, s, w, r1 = math.cos(self.Gamma0), math.sin(self.Gamma0), self.omega1, self.r1
        cw, sw = math.cos(self.phase(t)), math.sin(self.phase(t))
        return r1 * w * np.array([-s * cw, -sw, c * cw])

    def top_acceleration(self, t: float = 0.0) -> np.ndarray:
        """d^2 r~(1, t~)/dt~^2 of Eq. (70)."""
        c, s, w, r1 = math.cos(self.Gamma0), math.sin(self.Gamma0), self.omega1, self.r1
        cw, sw = math.cos(self.phase(t)), math.sin(self.phase(t))
        return r1 * w**2 * np.array([s * sw, -cw, -c * sw])

    def top_torque(self, t: float) -> float:
        """m_N(t~) = m_N0 [1 - exp(-t~/t~0)], Eq. (69); m_N0 at all times if t~0 = 0
        (:meth:`steady_torque`)."""
        if self.t0 == 0:
            return self.mN0
        return self.mN0 * (1.0 - math.exp(-t / self.t0))

    def steady_torque(self) -> "Normalised":
        """The same scene with the torque ramp (69) at its final value m_N0 from t~ = 0
        (periodic orbits: the forcing must be periodic)."""
        return dataclasses.replace(self, t0=0.0)

    def top_torque_rate(self, t: float) -> float:
        """d m_N / dt~ of Eq. (69)."""
        return 0.0 if self.t0 == 0 else self.mN0 / self.t0 * math.exp(-t / self.t0)

    def top_torque_accel(self, t: float) -> float:
        """d^2 m_N / dt~^2 of Eq. (69)."""
        return 0.0 if self.t0 == 0 else -self.mN0 / self.t0**2 * math.exp(-t / self.t0)

    def chord_tension(self) -> float:
        """sigma eps0: the tension of the straight chord, normalised (Eq. 29)."""
        return self.sigma * self.eps0
