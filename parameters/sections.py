"""The physical sections of a scene (SI): helix, environment, ends, torque,
controller and the model's switches."""

from __future__ import annotations

import dataclasses
import math
import sys
from dataclasses import dataclass

from rawehelix.parameters import components
from rawehelix.parameters.checks import ParameterError, _non_negative, _positive
from rawehelix.parameters.eilaw import EILaw


#: where the helix's EA, EI and GJ come from (Helix.stiffness; Parameters fills them
#: from the section's members for "from_section": parameters/section.py::helix_stiffness)
STIFFNESS = ("given", "from_section")
STIFFNESS_KEYS = ("EA_N", "EI_Nm2", "GJ_Nm2")


@dataclass(frozen=True)
class Helix:
    """The rod: Tables 1, 2 and 4 of the paper.

    ``stiffness = "from_section"`` takes EA_N, EI_Nm2 and GJ_Nm2 from the members of
    ``[section]`` (their taut moduli at zero strain, members.py: n tethers of stiffness
    section.tether_EA_N at the radius, laid at the lay angle, with the self-stress and
    the bars); :class:`~rawehelix.parameters.Parameters` fills them in, again after
    every ``replace`` (so they follow the section).  A scene file or ``--set`` that
    gives one of them too is refused (studies/scene.py); values passed to this
    dataclass directly are replaced.

    ``EI_law`` (None: off) makes the bending stiffness a function of the local
    tension (:class:`EILaw`; a scene's ``EI_law = {a_Nm2_per_N = .., b_Nm2 = ..}``).
    EI_Nm2 then still sets the sections' rotational inertia (delta, Eq. 27,
    2 rho I = 2 M EI / (EA L0)) and the normalisation mu of Eq. (26); the
    bending stiffness is the law's."""

    length_m: float  # L0, unstretched length [m]
    mass_kg: float  # M, total mass [kg]
    EA_N: float | None = None  # axial stiffness [N]; required unless stiffness = "from_section"
    EI_Nm2: float | None = None  # bending stiffness [N m^2]; required unless stiffness = "from_section"
    GJ_Nm2: float | None = None  # torsional stiffness [N m^2]; required unless stiffness = "from_section"
    # R, the helix radius: the tethers' radius (section.radius_m unless that is given),
    # which the members' moduli, their forces and every limit use, and the drawings';
    # the solid's torsional inertia does not (delta, Eq. 27) [m]
    radius_m: float = 0.19
    drag_length_m: float = 0.012  # l_a, sum of the bar diameters [m], Eq. (14)
    drag_coefficient: float = 1.0  # C_D, Eq. (14)
    EI_law: EILaw | None = None  # EI = a T + b (Eq. 64); None: EI = EI_Nm2
    GA_N: float | None = None  # GA, the shear stiffness [N] (the shearable rod); None: none
    # where EA_N, EI_Nm2 and GJ_Nm2 come from: "given" (these keys, the paper's) or
    # "from_section" (the section table's members' taut moduli, members.py, with
    # section.tether_EA_N and a lay angle or a self-stress; then give none of the three)
    stiffness: str = "given"

    def __post_init__(self):
        if self.stiffness not in STIFFNESS:
            raise ParameterError("helix.stiffness", self.stiffness, f"must be one of {list(STIFFNESS)}")
        missing = [name for name in STIFFNESS_KEYS if getattr(self, name) is None]
        if missing and self.stiffness == "given":
            raise ParameterError(f"helix.{missing[0]}", None,
                                 "is required (or set helix.stiffness = 'from_section': the "
                                 "[section]'s members give EA_N, EI_Nm2 and GJ_Nm2)")
        _positive("helix", self, "length_m", "mass_kg", "radius_m",
                  *(name for name in STIFFNESS_KEYS if name not in missing))
        _non_negative("helix", self, "drag_length_m", "drag_coefficient")
        if self.GA_N is not None:
            _positive("helix", self, "GA_N")
        if not missing and self.EI_Nm2 / self.EA_N / self.length_m > self.length_m:
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
    """Prescribed end positions, Eqs. (35), (36), (66) and (70).

    A scene gives exactly one of ``elongation`` and ``tension_N`` (the scene loader
    refuses both or neither): with ``tension_N`` the stationary solve finds the
    elongation whose stationary state has that mean tension along s
    (solvers/tension_target.py); every command then runs with that elongation."""

    elevation_deg: float  # Gamma0, elevation of the chord [deg]
    # eps0: chord = (1 + eps0) L0, Eq. (66); a scene gives exactly one of
    # ends.elongation and ends.tension_N
    elongation: float | None = None
    # T, the mean along s of the tension of the torque-free stationary state (the one
    # every run starts from) [N]: the stationary solve finds the elongation that gives
    # it (T / EA, the weightless straight rod's, misses it); instead of ends.elongation
    tension_N: float | None = None
    circle_radius_m: float = 0.0  # R1, radius of the upper end's circle, Eq. (70) [m]
    circle_frequency_Hz: float = 0.0  # f1, frequency of the upper end's circle [Hz]

    def __post_init__(self):
        if self.elongation is None and self.tension_N is None:
            raise ParameterError("ends.elongation", None, ONE_OF_ENDS)
        # The straight-chord tension EA*eps0 must be > 0: a slack helix has no
        # stationary state in this model (the tension law, Eq. 22, is linear).
        if self.elongation is not None and not (self.elongation > 0
                                                and math.isfinite(self.elongation)):
            raise ParameterError(
                "ends.elongation", self.elongation,
                "must be > 0 (the tension EA*elongation must be positive)")
        if self.tension_N is not None:
            _positive("ends", self, "tension_N")
        if not (-90.0 <= self.elevation_deg <= 90.0):
            raise ParameterError("ends.elevation_deg", self.elevation_deg, "must lie in [-90, 90]")
        _non_negative("ends", self, "circle_radius_m", "circle_frequency_Hz")

    @property
    def resolved(self) -> bool:
        """The elongation is known (given, or found for ``tension_N``)."""
        return self.elongation is not None


#: what a scene must say about its ends' stretch (the scene loader's one-line refusal)
ONE_OF_ENDS = ("give exactly one of ends.elongation (eps0 > 0) and ends.tension_N "
               "(the mean stationary tension [N] > 0)")


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


GAMMA_TREATMENTS = ("regularised", "off")
#: forms/paper.py (Eqs. 30-33), forms/extensible.py, forms/shearable.py (Simo-Reissner)
KINEMATICS = ("paper", "extensible", "shearable")


def check_kinematics_name(name: str) -> None:
    """Refuse a kinematics name that is none of :data:`KINEMATICS` (the scene's
    ``model.kinematics``, the kinematics registry models/kinematics.py)."""
    if name not in KINEMATICS:
        raise ParameterError("model.kinematics", name, f"must be one of {KINEMATICS}")


def check_kinematics(params) -> None:
    """What the extensible kinematics cannot run with (``params`` a whole scene)."""
    disc = params.discretisation
    if params.model.kinematics == "extensible" and (disc.continuum_scheme != "fe" or disc.bending != "ip"):
        raise ParameterError("model.kinematics", "extensible",
                             "is implemented by the FE scheme with discretisation.bending "
                             "= 'ip' only (forms/extensible.py)")


@dataclass(frozen=True)
@components.holds("model")
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
    # the shearable rod's sections' rotary inertia about a diameter (parameters/shear.py);
    # the unshearable rods have none (their sections turn with the tangent)
    rotary_inertia: bool = True
    # then the components' tables it holds (parameters/components.py::holds), which
    # studies/scene.py fills from the scene's sections: damping (the [damping]
    # section, Damping), torsion_hysteresis ([torsion_hysteresis], TorsionHysteresis)

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
        sections = (getattr(self, key) for key in components.nested("model"))  # [damping], ...
        extras = [x.describe() for x in sections if x.active]
        return "; ".join([text, *extras])

    def __post_init__(self):
        if self.gamma not in GAMMA_TREATMENTS:
            raise ParameterError("model.gamma", self.gamma, f"must be one of {GAMMA_TREATMENTS}")
        if self.reduction not in ("auto", "off"):
            raise ParameterError("model.reduction", self.reduction, "must be one of ('auto', 'off')")
        check_kinematics_name(self.kinematics)
        _positive("model", self, "gamma_eps")
