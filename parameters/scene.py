"""A whole scene (:class:`Parameters`) and the cross-checks between its sections."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

from rawehelix.parameters import components, end_components, sections
from rawehelix.parameters.checks import ParameterError
from rawehelix.parameters.fingerprint import drop_later_switches
from rawehelix.parameters.normalised import Normalised
from rawehelix.parameters.section import helix_stiffness as section_stiffness
from rawehelix.parameters.numerics import Discretisation, Sweep, Time
from rawehelix.parameters.sections import Controller, Ends, Environment, Helix, Model, Torque
from rawehelix.parameters.generator import Generator
from rawehelix.parameters.lifter import Lifter
from rawehelix.parameters.rotor import Rotor


@dataclass(frozen=True)
@components.holds(None)
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
    # the machine in operation, issue 43 (end components, parameters/end_components.py):
    # each off by default, so the paper's scenes are unchanged
    rotor: Rotor = field(default_factory=Rotor)
    generator: Generator = field(default_factory=Generator)
    lifter: Lifter = field(default_factory=Lifter)
    # then the components' tables of the scene itself (components.holds(None)): wind

    def __post_init__(self):
        if self.helix.stiffness == "from_section":  # EA, EI, GJ of the section's members
            stiffness = section_stiffness(self.model.section, self.helix)
            object.__setattr__(self, "helix", dataclasses.replace(self.helix, **stiffness))
        if not self.model.twist:
            # model.twist = false removes the twist field: alpha = 0 everywhere
            if end_components.torques(self):
                raise ParameterError("model.twist", False,
                                     f"needs a torque-free scene ({end_components.torque_free()}): "
                                     "torque is carried by the twist, Eq. (31)")
            if self.discretisation.continuum_scheme != "fe":
                raise ParameterError("model.twist", False, "is implemented by the FE scheme only")
        # each component's refusals of what it cannot run with
        sections.check_kinematics(self)
        components.check(self)
        end_components.check(self)

        self._check_groups()

    def _check_groups(self):
        """The groups of Eqs. (25)-(29) a solve starts from must be floats: finite,
        and not 0 where the values they scale are not (:data:`GROUP_KEYS`)."""
        q = Normalised.from_parameters(self)
        for group, (formula, equation, numerators, others) in GROUP_KEYS.items():
            # an absent key (None: an absent EI law, [wind]'s density) scales nothing
            scaled = [self.value(k) for k in numerators if self.value(k) is not None]
            value = getattr(q, group)
            if not scaled or math.isfinite(value) and (value != 0 or 0 in scaled):
                continue
            keys = [k for k in (*numerators, *others) if self.value(k) is not None]
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
        ends = self._ends_after(sections)
        if ends is not None:
            sections["ends"] = ends
        for nested in components.nested("model"):  # held by Model
            if nested in sections:
                value = dataclasses.replace(getattr(self.model, nested), **sections.pop(nested))
                sections["model"] = {**sections.get("model", {}), nested: value}
        changed = {name: values if isinstance(values, str)
                   else dataclasses.replace(getattr(self, name), **values)
                   for name, values in sections.items()}
        return dataclasses.replace(self, **changed)

    def _ends_after(self, sections: dict) -> dict | None:
        """The ``ends`` changes of :meth:`replace`, completed so that the elongation
        found for ``ends.tension_N`` (solvers/tension_target.py) never outlives what it
        was found for: a given elongation drops the tension, a given tension the
        elongation, and a change of any section that moves the stationary state
        (:data:`KEEP_FOUND_ELONGATION` lists those that do not) drops it, to be found
        again.  None: ``ends`` unchanged."""
        ends = dict(sections.get("ends", {}))
        if "elongation" in ends and "tension_N" not in ends:
            ends["tension_N"] = None
        elif "tension_N" in ends and "elongation" not in ends:
            ends["elongation"] = None
        elif self.ends.tension_N is not None and (
                set(sections) - KEEP_FOUND_ELONGATION - {"ends"}
                or set(ends) - {"circle_radius_m", "circle_frequency_Hz"}):
            ends["elongation"] = None
        return ends or None

    def as_dict(self) -> dict:
        """Every section as plain data, without the labels (name, title): what
        fingerprints of results hash."""
        data = dataclasses.asdict(self)
        if self.ends.tension_N is not None:  # the scene's input, not what a solve found
            data["ends"]["elongation"] = None
        data.pop("name")
        data.pop("title")
        return drop_later_switches(data)

    def normalised(self) -> "Normalised":
        """The groups of Eqs. (25)-(29); a scene with ``ends.tension_N`` needs its
        elongation found first (rawehelix.solvers.tension_target.resolve, which every
        command runs)."""
        if not self.ends.resolved:
            raise ParameterError(
                "ends.tension_N", self.ends.tension_N,
                "the elongation that gives this tension is not found yet: "
                "rawehelix.solvers.tension_target.resolve(params) finds it (every command "
                "and API function does)")
        return Normalised.from_parameters(self)

    def describe_model(self, planar: bool = False) -> str:
        """:meth:`Model.describe` and the helix's EI law when it has one: summary.json's "model"."""
        text = self.model.describe(planar)
        return text if self.helix.EI_law is None else f"{text}; {self.helix.EI_law.describe()}"


#: the sections whose change keeps the elongation found for ``ends.tension_N``: they do
#: not move the torque-free stationary state it is found on (the ends' circle keys do
#: not either: it is found with the upper end at the circle's centre)
KEEP_FOUND_ELONGATION = {"discretisation", "time", "sweep", "torque", "controller", "damping",
                         "rotor", "generator",
                         "torsion_hysteresis", "name", "title"}

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
    **components.group_keys(),
}
