"""Fingerprint compatibility: switches added after results were stored."""

from __future__ import annotations

import dataclasses

from rawehelix.parameters import components
from rawehelix.parameters.generator import Generator
from rawehelix.parameters.lifter import Lifter
from rawehelix.parameters.rotor import Rotor
from rawehelix.parameters.sections import Helix, Model
from rawehelix.parameters.wind import Wind

#: model switches added after results were stored (sweep checkpoints, the
#: convergence cache): left out of :meth:`Parameters.as_dict` at their
#: defaults, so that those results keep their fingerprints: the kinematics and
#: every component's section (parameters/components.py)
LATER_MODEL_SWITCHES = {"kinematics": "paper", "rotary_inertia": True,
                        **components.later_switches("model", Model)}
#: the same for the helix section (the EI law, where its stiffness comes from)
LATER_HELIX_SWITCHES = {**components.later_switches("helix", Helix), "stiffness": "given"}
#: keys of the model's [section] added after results with a [section] were stored
LATER_SECTION_KEYS = {"rings": None}
#: the same for the ends (ends.tension_N)
LATER_ENDS_SWITCHES = {"tension_N": None}


#: the scene's sections added after results were stored (issue 43), at their defaults
LATER_SECTIONS = {cls.__name__.lower(): dataclasses.asdict(cls())
                  for cls in (Rotor, Generator, Lifter, Wind)}


def drop_later_switches(data: dict) -> dict:
    """``data`` (Parameters as a dict) without the later switches at their defaults."""
    for key, default in LATER_SECTIONS.items():
        if data.get(key) == default:
            data.pop(key)
    for section, switches in (("model", LATER_MODEL_SWITCHES),
                              ("helix", LATER_HELIX_SWITCHES), ("ends", LATER_ENDS_SWITCHES)):
        for key, default in switches.items():  # fingerprints stored before them
            if data[section][key] == default:
                data[section].pop(key)
    stored = data["model"].get("section")  # absent: dropped above at its default
    for key, default in LATER_SECTION_KEYS.items():
        if stored is not None and stored.get(key, default) == default:
            stored.pop(key, None)
    return data
