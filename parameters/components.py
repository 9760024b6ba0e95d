"""The physics components' scene sections, registered once.

A component's scene section is a module here (its section dataclass, validated
in __post_init__) that also gives:

* ``HOLDER, KEY``: where the section lives in a scene (``Parameters.model.damping``:
  ("model", "damping"));
* ``GROUP_KEYS``: its normalised groups (merged into parameters/scene.py's);
* ``normalise(p, scales)``: its fields of :class:`~rawehelix.parameters.Normalised`;
* ``check(p)``: what it cannot run with, a :class:`ParameterError` (Parameters calls it).

Its UFL half, the component itself with its null object, is in forms/ (forms/damping.py,
forms/eilaw.py, forms/hysteresis.py), and the rod model (models/unshearable.py) asks it.
"""

from __future__ import annotations

import dataclasses

from rawehelix.parameters import damping, eilaw, hysteresis

#: the sections, in the order of their checks
SECTIONS = (eilaw, damping, hysteresis)


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
