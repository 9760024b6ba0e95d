"""The physics components' scene sections, registered once.

A component's scene section is a module here (its section dataclass, validated
in __post_init__) that also gives:

* ``HOLDER, KEY``: where the section lives in a scene (``Parameters.model.damping``:
  ("model", "damping"); HOLDER None: a section of the scene itself, ``Parameters.wind``);
* ``SECTION``: its dataclass (with ``active`` and ``describe()``, for Model.describe)
  when it is a table of its own (the scene's ``[damping]``):
  :func:`holds` makes it a field of its holder and studies/scene.py a scene section;
  None for a value its holder declares itself (``helix.EI_law``);
* ``GROUP_KEYS``: its normalised groups (merged into parameters/scene.py's);
* ``NORMALISED``: its fields of :class:`~rawehelix.parameters.Normalised` and their
  values when it is off (:func:`normalised_fields` declares them);
* ``normalise(p, scales)``: those fields' values for a scene;
* ``check(p)``: what it cannot run with, a :class:`ParameterError` (Parameters calls it).

Its UFL half, the component itself with its null object, is in forms/ (forms/damping.py,
forms/eilaw.py, forms/hysteresis.py), and the rod model (models/unshearable.py) asks it.

A new component is its module here, appended to :data:`SECTIONS`, and its forms/
module appended to forms/coefficients.py; nothing else in parameters/ or studies/
names it (docs/explanation/model.md, "Adding a component").
"""

from __future__ import annotations

import dataclasses

from rawehelix.parameters import damping, eilaw, hysteresis, section, shear, spin_drag, wind

#: the sections, in the order of their checks
SECTIONS = (eilaw, damping, hysteresis, section, shear, wind, spin_drag)


def group_keys() -> dict:
    """Every section's GROUP_KEYS."""
    return {k: v for section in SECTIONS for k, v in section.GROUP_KEYS.items()}


def normalise(p, scales: dict) -> dict:
    """Every section's fields of Normalised."""
    return {k: v for section in SECTIONS for k, v in section.normalise(p, scales).items()}


def check(p) -> None:
    """Every section's refusals."""
    for section in SECTIONS:
        section.check(p)


def scene_sections() -> dict:
    """The components' tables of a scene, ``[KEY]`` -> its dataclass (studies/scene.py)."""
    return {s.KEY: s.SECTION for s in SECTIONS if s.SECTION is not None}


def scene_readers() -> dict:
    """``[KEY]`` -> ``read(values, folder)`` of the sections that read a file beside the
    scene (a module's ``read``: the wind's file)."""
    return {s.KEY: s.read for s in SECTIONS if getattr(s, "read", None) is not None}


def scene_holders() -> dict:
    """The section whose dataclass holds each component table: {"damping": "model", ...}."""
    return {s.KEY: s.HOLDER for s in SECTIONS if s.SECTION is not None and s.HOLDER is not None}


def holds(holder: str):
    """A class decorator, under ``@dataclass``: the component tables held by ``holder``
    become fields of the class, ``KEY: SECTION = field(default_factory=SECTION)``,
    in the order of :data:`SECTIONS` (Model: damping, torsion_hysteresis; ``holder``
    None: the scene's own sections, Parameters: wind)."""
    def add(cls):
        for s in SECTIONS:
            if s.HOLDER == holder and s.SECTION is not None:
                cls.__annotations__[s.KEY] = s.SECTION.__name__
                setattr(cls, s.KEY, dataclasses.field(default_factory=s.SECTION))
        return cls
    return add


def normalised_fields(cls):
    """A class decorator, under ``@dataclass``: every component's ``NORMALISED``
    groups become fields of :class:`Normalised`, defaulting to their value when off."""
    for s in SECTIONS:
        for name, default in s.NORMALISED.items():
            cls.__annotations__[name] = type(default).__name__
            setattr(cls, name, default)
    return cls


def nested(holder: str) -> tuple[str, ...]:
    """The sections held by the section ``holder`` ("model": damping, torsion_hysteresis)."""
    return tuple(s.KEY for s in SECTIONS if s.HOLDER == holder)


def later_switches(holder: str, cls) -> dict:
    """The sections of ``holder`` added after results were stored, at their defaults
    (parameters/fingerprint.py): the default of each field of ``cls`` they fill."""
    defaults = {f.name: f for f in dataclasses.fields(cls)}
    out = {}
    for key in nested(holder):
        f = defaults[key]
        value = f.default_factory() if f.default_factory is not dataclasses.MISSING else f.default
        out[key] = dataclasses.asdict(value) if dataclasses.is_dataclass(value) else value
    return out
