"""The end components: the conditions the ends impose, registered once (the
counterpart, at the ends, of parameters/components.py's physics components).

An end component is an :class:`EndComponent`: its name, its scene section (``KEY``
and its dataclass), the end it acts on (the ground, s = 0; the top, s = L0), what it
prescribes there (a position or a torque), its equation in the paper, and its null
object: the values of its section that switch it off (``off``, as a scene says them)
and ``active(params)``, False at the null object.  Today's:

* ``fixed``: both ends' positions, Eqs. (35), (36), (66): always on (no null object);
* ``circle``: the top's circle of Eq. (70), off at ``ends.circle_radius_m = 0``;
* ``torque_ramp``: the rotor's torque ramp of Eq. (69) at the top, off at
  ``torque.top_Nm = 0``;
* ``controller``: the ground torque's PD controller of Eq. (40), off at
  ``controller.k1 = controller.k2 = 0``.

* ``rotor``: the rotor's torque at the top (``[rotor]``, parameters/rotor.py), off
  without a table;
* ``generator``: the generator's torque at the ground (``[generator]``), off at
  ``law = "paper"`` (Eq. 40: the ``controller``'s);
* ``lifter``: the lifter's force on a free top end (``[lifter]``), off at
  ``top = "fixed"``.

The wind is a physics component (parameters/wind.py, parameters/components.py): it
acts along the helix, not at an end.  A new end condition is an entry appended to
:data:`END_COMPONENTS` with its section and its ``check``; the checks that ask which
ends carry a torque (:func:`torques`) then see it.  :func:`get` refuses an unknown
name once, with the list of names.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from rawehelix.parameters import generator, lifter, rotor
from rawehelix.parameters.checks import ParameterError
from rawehelix.parameters.generator import Generator
from rawehelix.parameters.lifter import Lifter
from rawehelix.parameters.rotor import Rotor
from rawehelix.parameters.sections import Controller, Ends, Torque

ENDS = ("ground", "top", "both")  # s = 0, s = L0, both
LOADS = ("position", "torque", "force")  # what a component prescribes at its end


@dataclass(frozen=True)
class EndComponent:
    """One condition at the ends (module docstring)."""

    name: str
    KEY: str  # its scene section: Parameters.<KEY>
    SECTION: type  # the section's dataclass
    end: str  # one of ENDS
    load: str  # one of LOADS
    equation: str  # the paper's equation(s)
    off: str  # its null object, as a scene spells it ("" : none, always on)
    active: Callable  # params -> bool: False at its null object
    check: Callable = lambda p: None  # params -> None: ParameterError for what it cannot run with
    # (values, the scene's folder) -> its section, for a section that reads files beside
    # the scene (a table); None: SECTION(**values)
    read: Callable | None = None

    def __post_init__(self):
        if self.end not in ENDS or self.load not in LOADS:
            raise ValueError(f"end component {self.name!r}: end must be one of {ENDS} and "
                             f"load one of {LOADS}")


#: the end components, in the order of the paper's equations
END_COMPONENTS = (
    EndComponent("fixed", "ends", Ends, "both", "position", "Eqs. (35), (36), (66)", "",
                 lambda p: True),
    EndComponent("circle", "ends", Ends, "top", "position", "Eq. (70)",
                 "ends.circle_radius_m = 0", lambda p: p.ends.circle_radius_m > 0),
    EndComponent("torque_ramp", "torque", Torque, "top", "torque", "Eq. (69)",
                 "torque.top_Nm = 0", lambda p: p.torque.top_Nm != 0),
    EndComponent("controller", "controller", Controller, "ground", "torque", "Eq. (40)",
                 "controller off", lambda p: p.controller.active),
    # issue 43: the machine in operation (operation/ has their laws)
    EndComponent("rotor", "rotor", Rotor, "top", "torque",
                 "Q = 1/2 rho pi R^2 V_n^3 Cp / Omega (its table)", "no rotor.table",
                 lambda p: p.rotor.active, rotor.check, Rotor.from_scene),
    EndComponent("generator", "generator", Generator, "ground", "torque",
                 "mppt k Omega^2, a torque table, or Eq. (40)", "generator.law = 'paper'",
                 lambda p: p.generator.active, generator.check, Generator.from_scene),
    EndComponent("lifter", "lifter", Lifter, "top", "force",
                 "the lifted top end's balance of forces", "lifter.top = 'fixed'",
                 lambda p: p.lifter.active, lifter.check),
)
#: every end component by name
REGISTRY = {c.name: c for c in END_COMPONENTS}


def get(name: str) -> EndComponent:
    """The end component of a name; any other name is refused once, with the list."""
    try:
        return REGISTRY[name]
    except KeyError:
        raise ParameterError("end component", name, f"must be one of {tuple(REGISTRY)}") from None


def check(params) -> None:
    """Every end component's refusals of what it cannot run with (Parameters calls it)."""
    for c in END_COMPONENTS:
        c.check(params)


def scene_sections() -> dict:
    """The end components' tables of a scene, ``[KEY]`` -> its dataclass (studies/scene.py)."""
    return {c.KEY: c.SECTION for c in END_COMPONENTS}


def scene_readers() -> dict:
    """``[KEY]`` -> how the scene loader builds a section that reads files beside the
    scene (studies/scene.py): ``read(values, folder)``."""
    return {c.KEY: c.read for c in END_COMPONENTS if c.read is not None}


def active(params) -> tuple[EndComponent, ...]:
    """The end components ``params`` switches on."""
    return tuple(c for c in END_COMPONENTS if c.active(params))


def torques(params) -> tuple[EndComponent, ...]:
    """The active components that put a torque on an end (Eqs. 38-39)."""
    return tuple(c for c in active(params) if c.load == "torque")


def torque_free() -> str:
    """How a scene switches every torque component off: "torque.top_Nm = 0, controller off"."""
    return ", ".join(c.off for c in END_COMPONENTS if c.load == "torque")


__all__ = ["END_COMPONENTS", "ENDS", "EndComponent", "LOADS", "REGISTRY", "active", "check",
           "get", "scene_readers", "scene_sections", "torque_free", "torques"]
