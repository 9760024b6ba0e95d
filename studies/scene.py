"""Scene files: TOML in SI units -> validated :class:`Parameters`.

A scene has the sections of :class:`rawehelix.parameters.Parameters`
(``[helix]``, ``[ends]``, ``[environment]``, ``[torque]``, ``[controller]``,
``[model]``, ``[discretisation]``, ``[time]``, ``[sweep]``), the physics components'
sections (``[damping]``, ``[torsion_hysteresis]``, ``[wind]``: parameters/components.py,
which names them and the section that holds them), the end components' (``[rotor]``,
``[generator]``, ``[lifter]``: parameters/end_components.py; a table file they name
is read relative to the scene file) and an optional top-level ``title``.  ``studies/scenes/example.toml`` documents every key.

Any problem raises :class:`SceneError`, whose message names the file, the key
and what is allowed; the command line turns it into exit status 2 before any
output is written.
"""

from __future__ import annotations

import dataclasses
import json
import re
import sys
import tomllib
from pathlib import Path

from rawehelix.errors import SceneError  # noqa: F401  (re-exported)
from rawehelix.parameters import (Controller, Discretisation, Ends, Environment, Helix, Model,
                                  ParameterError, Parameters, Sweep, Time, Torque, components,
                                  end_components)
from rawehelix.parameters.sections import ONE_OF_ENDS, STIFFNESS_KEYS

SECTIONS = {
    "helix": Helix, "ends": Ends, "environment": Environment, "torque": Torque,
    "controller": Controller, "model": Model, "discretisation": Discretisation,
    "time": Time, "sweep": Sweep,
    **components.scene_sections(),  # [damping], [torsion_hysteresis], [wind]
    **end_components.scene_sections(),  # and [rotor], [generator], [lifter]
}
NESTED = components.scene_holders()  # sections held by another section's dataclass
# sections that read a file beside the scene
READERS = {**end_components.scene_readers(), **components.scene_readers()}
REQUIRED = ("helix", "ends")
TOP_LEVEL = {"title": str}
SCENE_DIR = Path(__file__).parent / "scenes"


_TYPE_NAMES = {"float": "a number", "int": "an integer", "str": "a string", "bool": "true or false",
               "EILaw | None": "an inline table {a_Nm2_per_N = .., b_Nm2 = ..}",
               "tuple[float, ...]": "an array of numbers [1.0, 2.5, ..]"}


def value_type(type_name: str) -> str:
    """The type a scene value of a field of this annotation has: an optional number,
    string or array (``float | None``, ``str | None``: absent is None, as TOML has no
    null) is one when a scene sets it.  The one place that reads an optional key's annotation."""
    base, _, none = type_name.partition(" | ")
    return base if none == "None" and base in ("float", "int", "str", "tuple[float, ...]") \
        else type_name


def key_type(key: str) -> str:
    """The dotted scene key's value type ('float', 'int', 'str', ...; an optional
    number's too, :func:`value_type`), or 'float' if unknown (the loader then names
    the key)."""
    section, _, name = key.partition(".")
    cls = SECTIONS.get(section)
    types = {f.name: f.type for f in dataclasses.fields(cls)} if cls else {}
    return value_type(types.get(name, "float"))


def toml_value(value) -> str:
    """A value as a scene file spells it (``false``, ``"ip"``, ``1e-05``), for messages."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return json.dumps(value)
    return repr(value)


def _check_type(path, key: str, value, type_name: str):
    type_name = value_type(type_name)
    ok = {
        "float": isinstance(value, (int, float)) and not isinstance(value, bool),
        "int": isinstance(value, int) and not isinstance(value, bool),
        "str": isinstance(value, str),
        "bool": isinstance(value, bool),
        "EILaw | None": isinstance(value, dict),  # helix.EI_law: Helix validates the keys
        "tuple[float, ...]": isinstance(value, list) and all(  # a table's column
            isinstance(v, (int, float)) and not isinstance(v, bool) for v in value),
    }[type_name]
    if not ok:
        raise SceneError(path, key, f"must be {_TYPE_NAMES[type_name]}, got {value!r}")
    if type_name == "tuple[float, ...]":
        if any(isinstance(v, int) and abs(v) > sys.float_info.max for v in value):
            raise SceneError(path, key, "must be an array of finite numbers (an integer is "
                             f"past {sys.float_info.max:.4g})")
        return tuple(float(v) for v in value)
    if type_name == "float" and isinstance(value, int) and abs(value) > sys.float_info.max:
        raise SceneError(path, key, f"must be a finite number (at most {sys.float_info.max:.4g} "
                         f"in size), got an integer of {len(str(abs(value)))} digits")
    return float(value) if type_name == "float" else value


def _section(path, name: str, table) -> object:
    cls = SECTIONS[name]
    if not isinstance(table, dict):
        raise SceneError(path, name, "must be a table [" + name + "]")
    fields = {f.name: f for f in dataclasses.fields(cls) if f.name not in NESTED}
    values = {}
    for key, value in table.items():
        if key not in fields:
            raise SceneError(path, f"{name}.{key}",
                             f"unknown key; allowed keys are {', '.join(fields)}")
        values[key] = _check_type(path, f"{name}.{key}", value, fields[key].type)
    missing = [k for k, f in fields.items()
               if k not in values and f.default is dataclasses.MISSING
               and f.default_factory is dataclasses.MISSING]
    if missing:
        raise SceneError(path, f"{name}.{missing[0]}", "is required")
    if cls is Ends and ("elongation" in values) == ("tension_N" in values):
        given = "both" if "elongation" in values else "neither"
        raise SceneError(path, "ends.elongation, ends.tension_N", f"{ONE_OF_ENDS}; the scene "
                         f"gives {given}")
    try:
        # a section with files beside the scene (the rotor's table) reads them itself
        read = READERS.get(name)
        return cls(**values) if read is None else read(values, Path(str(path)).parent)
    except ParameterError as err:
        raise _scene_error(path, err) from None


def _scene_error(path, err: ParameterError) -> SceneError:
    """A dataclass's refusal as the scene's: ``key: value what is allowed`` (an absent
    key, value None: ``key: what is allowed``)."""
    said = err.allowed if err.value is None else f"{toml_value(err.value)} {err.allowed}"
    return SceneError(path, err.key, said)


def _stiffness_given_twice(path, helix) -> None:
    """helix.stiffness = "from_section" takes EA_N, EI_Nm2 and GJ_Nm2 from [section]:
    a scene (or --set) that gives one of them too is refused, naming it."""
    if not isinstance(helix, dict) or helix.get("stiffness") != "from_section":
        return
    for name in STIFFNESS_KEYS:
        if name in helix:
            raise SceneError(path, f"helix.{name}",
                             "is given, but helix.stiffness = 'from_section' takes EA_N, "
                             "EI_Nm2 and GJ_Nm2 from the [section]'s members: remove it, or "
                             "set helix.stiffness = 'given'")


def parameters_from_dict(data: dict, path="<scene>", name: str | None = None) -> Parameters:
    """Validate a parsed scene (as from TOML) and build its parameters."""
    for key, value in data.items():
        if key in TOP_LEVEL:
            _check_type(path, key, value, TOP_LEVEL[key].__name__)
        elif key not in SECTIONS:
            raise SceneError(path, key, "unknown section; allowed are "
                             + ", ".join(["title", *SECTIONS]))
    for name_ in REQUIRED:
        if name_ not in data:
            raise SceneError(path, name_, f"the section [{name_}] is required")
    _stiffness_given_twice(path, data["helix"])
    sections = {s: _section(path, s, data[s]) for s in SECTIONS if s in data}
    for nested, holder in NESTED.items():  # [damping] -> Model.damping, ...
        if nested in sections:
            sections[holder] = dataclasses.replace(sections.get(holder, SECTIONS[holder]()),
                                                   **{nested: sections.pop(nested)})
    label = name if name is not None else Path(str(path)).stem
    try:
        return Parameters(**sections, name=label, title=data.get("title", label))
    except ParameterError as err:
        raise _scene_error(path, err) from None


def apply_overrides(data: dict, overrides: dict, path="<scene>") -> dict:
    """A copy of the parsed scene with dotted keys set: ``{"helix.EI_Nm2": 9000.0}``.

    The values are validated later, with the file's own (same messages)."""
    data = {k: (dict(v) if isinstance(v, dict) else v) for k, v in data.items()}
    for key, value in (overrides or {}).items():
        section, _, name = str(key).partition(".")
        if not name:
            if section in TOP_LEVEL:
                data[section] = value
                continue
            raise SceneError(path, key, "an override is a dotted key SECTION.KEY, e.g. "
                             "helix.EI_Nm2; sections are " + ", ".join(SECTIONS))
        if section not in SECTIONS:
            raise SceneError(path, key, "unknown section; allowed are " + ", ".join(SECTIONS))
        table = data.setdefault(section, {})
        if not isinstance(table, dict):
            raise SceneError(path, section, f"must be a table [{section}]")
        table[name] = value
    return data


def _long_integer(text: str) -> str:
    """Where a TOML text has an integer literal past Python's digit limit: "line N"."""
    for number, line in enumerate(text.splitlines(), 1):
        if re.search(r"\d(?:_?\d){%d}" % sys.get_int_max_str_digits(), line):
            return f"line {number}"
    return "a line"


def resolve(path) -> Path:
    """A scene path, or the name of a scene shipped in ``studies/scenes``, or the stem of
    a ``.toml`` file (``my_helix`` for ``my_helix.toml``: the name a run's advice prints,
    ``params.name``, runs as printed beside the file)."""
    p = Path(path)
    if not p.exists() and not p.suffix:
        for candidate in (SCENE_DIR / f"{p.name}.toml", p.with_suffix(".toml")):
            if candidate.is_file():
                return candidate
    return p


def load(path, elements: int | None = None, degree: int | None = None,
         scheme: str | None = None, overrides: dict | None = None) -> Parameters:
    """Read and validate a scene.

    ``elements``, ``degree`` and ``scheme`` set the discretisation;
    ``overrides`` sets any dotted scene key (``{"helix.EI_Nm2": 9000.0}``).
    Both are validated like the file's own values: a bad one raises
    :class:`SceneError` naming the file, the key and what is allowed."""
    p = resolve(path)
    if not p.is_file():
        raise SceneError(p, "file", "no such scene file (nor a shipped scene: "
                         + ", ".join(sorted(f.stem for f in SCENE_DIR.glob("*.toml"))) + ")")
    try:
        text = p.read_text(encoding="utf-8")
    except UnicodeDecodeError as err:
        raise SceneError(p, "file", f"is not UTF-8 text, as TOML must be ({err.reason} "
                         f"at byte {err.start})") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise SceneError(p, "file", f"is not valid TOML ({err})") from None
    except ValueError:  # Python's int <-> str limit, which tomllib meets unchecked
        raise SceneError(p, "file", f"{_long_integer(text)}: an integer literal has more than "
                         f"{sys.get_int_max_str_digits()} digits, more than any key allows "
                         "(floats reach 1.8e308)") from None
    disc = {f"discretisation.{k}": v for k, v in
            (("elements", elements), ("degree", degree), ("scheme", scheme)) if v is not None}
    data = apply_overrides(data, {**(overrides or {}), **disc}, p)
    return parameters_from_dict(data, p, name=p.stem)
