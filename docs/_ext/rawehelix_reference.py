"""Reference pages generated from the code at build time, so they cannot drift.

A page carries a marker line ``<!-- rawehelix-reference: NAME -->``; when Sphinx
reads it, the marker is replaced by the Markdown of :data:`GENERATORS` [NAME]:

- ``commands``: every ``rawehelix`` command with its ``--help``, rendered from
  the argparse parser of ``rawehelix.cli.main`` (nothing else is imported);
- ``scene-keys``: every scene section and key with its type, unit, default and
  allowed values, walked from the parameter dataclasses
  (``rawehelix.studies.scene.SECTIONS``): the description and unit from the
  comment on the field in ``parameters.py``, the allowed values from the
  messages the dataclass's own validation gives for values outside them.

The functions return Markdown text and import neither FEniCSx nor PETSc:
``python docs/_ext/rawehelix_reference.py commands`` prints a page.
"""

from __future__ import annotations

import ast
import dataclasses
import inspect
import io
import math
import os
import re
import sys
import textwrap
import tokenize

MARKER = re.compile(r"^<!-- rawehelix-reference: ([a-z-]+) -->$", re.M)


# -- the command line ---------------------------------------------------------

def _subparsers(parser):
    """(name, help, subparser) of every subcommand, in the parser's order."""
    import argparse
    for action in parser._actions:  # argparse keeps its subparsers here, and nowhere public
        if isinstance(action, argparse._SubParsersAction):
            helps = {c.dest: c.help for c in action._choices_actions}
            return [(name, helps.get(name, ""), sub) for name, sub in action.choices.items()]
    return []


def commands() -> str:
    """One section a command: its one-line purpose and its ``--help`` verbatim."""
    from rawehelix.cli import main as cli
    old = os.environ.get("COLUMNS")
    os.environ["COLUMNS"] = "100"  # argparse wraps to the terminal: fix the width
    try:
        parser = cli._parser()
        out = ["The commands, in the order `rawehelix --help` lists them:", ""]
        subs = _subparsers(parser)
        out += [f"- [`rawehelix {name}`](#rawehelix-{name}): {text}" for name, text, _ in subs]
        out.append("")
        for name, text, sub in subs:
            out += [f"## rawehelix {name}", "", f"{text[:1].upper()}{text[1:]}.", "",
                    "```text", sub.format_help().rstrip(), "```", ""]
    finally:
        if old is None:
            os.environ.pop("COLUMNS", None)
        else:
            os.environ["COLUMNS"] = old
    return "\n".join(out)


# -- the scene keys -----------------------------------------------------------

#: the unit a key's name ends with, when its comment gives none in brackets
SUFFIX_UNITS = {"_m": "m", "_kg": "kg", "_N": "N", "_Nm": "N m", "_Nm2": "N m^2", "_s": "s",
                "_Hz": "Hz", "_deg": "deg", "_rpm": "rpm", "_m_s": "m/s", "_m_s2": "m/s^2",
                "_kg_m3": "kg/m^3", "_m_n": "(m/rad)^n"}
_TYPE_WORDS = {"float": "number", "int": "integer", "str": "string", "bool": "true/false",
               "EILaw | None": "inline table", "int | None": "integer", "str | None": "string", "float | None": "number",
               "tuple[float, ...] | None": "array of numbers"}


def field_comments(cls) -> dict[str, str]:
    """The comment of each field of a dataclass in its source: the one on the
    field's line, else the block of comment-only lines just above it."""
    source = textwrap.dedent(inspect.getsource(cls))
    trailing, alone = {}, {}
    for tok in tokenize.generate_tokens(io.StringIO(source).readline):
        if tok.type == tokenize.COMMENT:
            text = tok.string.lstrip("#").strip()
            (alone if tok.line.strip().startswith("#") else trailing)[tok.start[0]] = text
    out = {}
    for node in ast.parse(source).body[0].body:
        if isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            above, k = [], node.lineno - 1
            while k in alone:
                above.insert(0, alone[k])
                k -= 1
            out[node.target.id] = trailing.get(node.lineno) or " ".join(above)
    return out


_UNIT = re.compile(r"\s*\[([^\[\]]+)\]")


def unit_of(name: str, comment: str) -> str:
    """The unit in the comment's last ``[...]``, else the name's suffix, else '-'."""
    found = _UNIT.findall(comment)
    if found:
        return found[-1]
    for suffix, unit in sorted(SUFFIX_UNITS.items(), key=lambda kv: -len(kv[0])):
        if name.endswith(suffix):
            return unit
    return "-"


def _without_unit(comment: str) -> str:
    found = list(_UNIT.finditer(comment))
    if found:
        comment = comment[:found[-1].start()] + comment[found[-1].end():]
    return comment.strip()


def _probes(type_name: str):
    """Values to offer a field to learn, from its validation, what it refuses."""
    if type_name in ("float", "float | None"):
        return [0.5, 2.0, 1.0, 0.0, -1.0, 1e-300, 1e300, -1e300, math.nan, math.inf, -math.inf]
    if type_name in ("int", "int | None"):
        return [-10**6, -1, 0, 1, 2, 10**6]
    if type_name in ("str", "str | None"):
        return ["?"]
    if type_name == "tuple[float, ...] | None":  # a table's column, 4 rows (Rotor.reference_example)
        return [(4.0, 3.0, 2.0, 1.0), (-1.0, 0.5, 0.6, 0.7), (0.1, 0.7, 0.2, 0.3)]
    if type_name == "EILaw | None":
        return [{}, {"a_Nm2_per_N": -1.0, "b_Nm2": 1.0}, {"a_Nm2_per_N": 1.0, "b_Nm2": 0.0}]
    return []


def _refusals(base, section: str, name: str, type_name: str, other=None) -> list[str]:
    """The distinct messages the dataclass gives for bad values of one field,
    with another field of the section changed (``other``: a dict) or not."""
    from rawehelix.parameters import ParameterError
    seen = []
    for value in _probes(type_name):
        try:
            dataclasses.replace(base, **(other or {}), **{name: value})
        except ParameterError as err:
            key = f"{section}.{name}"
            if err.key == key or err.key.startswith(key + "."):
                text = err.allowed if err.key == key else f"{err.key[len(key) + 1:]} {err.allowed}"
                if text not in seen:
                    seen.append(text)
    return seen


def _valid(base, section: str, name: str, value) -> bool:
    """Does the field itself accept ``value`` (another field may then refuse)?"""
    from rawehelix.parameters import ParameterError
    try:
        dataclasses.replace(base, **{name: value})
    except ParameterError as err:
        return err.key != f"{section}.{name}"
    return True


def _choices(messages: list[str]) -> tuple:
    """The values a 'must be one of (...)' message allows."""
    for text in messages:
        found = re.search(r"one of (\(.*?\))", text)
        if found:
            return ast.literal_eval(found.group(1))
    return ()


#: a number a message quotes (a bound computed from the scene's other keys)
_NUMBER = r"-?(?:\d+\.?\d*(?:e[+-]?\d+)?|inf|nan)"
_QUOTED_VALUE = re.compile(r" = " + _NUMBER + r"(?=[\s),;]|$)")


def _allowed(base, section: str, name: str, type_name: str, variants) -> str:
    """The field's rules, each once.  A rule whose message quotes values of
    other keys (a bound computed from them) is stated without the values: the
    probes met it with several, and no one of them is the rule."""
    if type_name == "bool":
        return "true or false"
    messages = {text: "" for text in _refusals(base, section, name, type_name)}
    for other, value in variants:  # ranges that depend on another key of the section
        for text in _refusals(base, section, name, type_name, {other: value}):
            messages.setdefault(text, f" (when {other} = {value!r})")
    shapes: dict[str, list[str]] = {}
    for text in messages:
        shapes.setdefault(re.sub(_NUMBER, "#", text), []).append(text)
    rules = []
    for texts in shapes.values():
        if len(texts) > 1:  # one rule met at several values of other keys
            rules.append(_QUOTED_VALUE.sub("", texts[0]))
        else:
            rules.append(texts[0] + messages[texts[0]])
    return "; ".join(rules) or "not checked"


def _default(f) -> str:
    if f.default is not dataclasses.MISSING:
        value = f.default
    elif f.default_factory is not dataclasses.MISSING:
        value = f.default_factory()
    else:
        return "required"
    if value is None:
        return "absent"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f'"{value}"'
    return repr(value)


def scene_key_rows(sections=None, base=None):
    """One dict a scene key: section, key, type, unit, default, allowed, meaning.

    ``base`` is a valid :class:`Parameters` whose sections the probes start from
    (default: the shipped ``stationary_table2``, which has every required key)."""
    from rawehelix.studies import scene
    sections = sections or scene.SECTIONS
    base = base or scene.load("stationary_table2")
    rows = []
    for section, cls in sections.items():
        holder = scene.NESTED.get(section)
        start = getattr(getattr(base, holder), section) if holder else getattr(base, section)
        # a section whose ranges are checked only when it is on (the rotor: with a table)
        # gives an instance that is on to start the probes from
        if hasattr(cls, "reference_example"):
            start = cls.reference_example()
        fields = [f for f in dataclasses.fields(cls) if f.name not in scene.NESTED]
        notes = field_comments(cls)
        str_fields = [f.name for f in fields if f.type == "str"]
        variants = [(other, value) for other in str_fields
                    for value in _choices(_refusals(start, section, other, "str"))
                    if value != getattr(start, other)]
        variants += [(f.name, value) for f in fields if f.type in ("float", "int")
                     for value in _probes(f.type)
                     if value != getattr(start, f.name) and _valid(start, section, f.name, value)]
        for f in fields:
            comment = notes.get(f.name, "")
            rows.append({
                "section": section, "key": f.name, "type": _TYPE_WORDS.get(f.type, f.type),
                "unit": unit_of(f.name, comment), "default": _default(f),
                "allowed": _allowed(start, section, f.name, f.type,
                                    [v for v in variants if v[0] != f.name]),
                "meaning": _without_unit(comment)})
    return rows


def _cell(text: str) -> str:
    return str(text).replace("|", "\\|")


def scene_keys() -> str:
    """A table a scene section, in the order of ``studies/scene.py``."""
    from rawehelix.studies import scene
    rows = scene_key_rows()
    docs = {name: inspect.getdoc(cls) or "" for name, cls in scene.SECTIONS.items()}
    out = []
    top = ", ".join(f"`{k}` ({_TYPE_WORDS.get(t.__name__, t.__name__)})"
                    for k, t in scene.TOP_LEVEL.items())
    out += [f"Top-level keys: {top}.  Required sections: "
            + ", ".join(f"`[{s}]`" for s in scene.REQUIRED) + ".", ""]
    for section in scene.SECTIONS:
        out += [f"## [{section}]", ""]
        doc = docs[section].split("\n\n")[0].replace("\n", " ")
        if doc and not doc.startswith(scene.SECTIONS[section].__name__ + "("):
            out += [doc, ""]
        # in a container: docs/_static/custom.css wraps its long cells to the page's width
        out += [":::{container} scene-keys", "",
                "| key | type | unit | default | allowed | meaning |",
                "| --- | --- | --- | --- | --- | --- |"]
        for r in (r for r in rows if r["section"] == section):
            out.append("| " + " | ".join(_cell(x) for x in (
                f"`{section}.{r['key']}`", r["type"], r["unit"], r["default"], r["allowed"],
                r["meaning"])) + " |")
        out += ["", ":::", ""]
    out += ["## Rules between sections", "",
            "Checked when the whole scene is built (`Parameters`), whatever the sections' "
            "own ranges allow:", ""]
    out += [f"- `{key}` {text}" for key, text in _cross_section_rules()]
    return "\n".join(out + [""])


def _cross_section_rules() -> list[tuple[str, str]]:
    """(key, allowed) of each refusal of :class:`Parameters`' own validation,
    found by switching on the options that depend on other sections, one at a
    time, on the shipped Sec. 5.2 scene (torque and controller on)."""
    from rawehelix.parameters import PAPER_EI_LAW, ParameterError
    from rawehelix.studies import scene
    base = scene.load("nominal_operation")
    ip_only = {"discretisation": {"bending": "mixed"}}
    trials = [{"model": {"twist": False}},
              {"model": {"kinematics": "extensible"}, **ip_only},
              {"helix": {"EI_law": PAPER_EI_LAW}},
              {"damping": {"axial_s": 1e-3}, **ip_only},
              {"torsion_hysteresis": {"rho": 0.5, "beta_m_n": 1.0}, **ip_only},
              {"helix": {"stiffness": "from_section"}},
              {"helix": {"stiffness": "from_section"}, "section": {"tether_EA_N": 6e3}},
              # the machine's sections against the paper's ends, wind and scheme
              {"generator": {"law": "mppt", "mppt_gain_Nms2": 0.1}},
              {"rotor": {"radius_m": 2.0, "tsr": (1.0, 3.0, 5.0), "cp": (0.1, 0.3, 0.4),
                         "ct": (0.2, 0.5, 0.7)}},
              {"wind": {"speed_m_s": 5.0}},
              {"wind": {"speed_m_s": 10.0, "air_density_kg_m3": 1.2},
               "environment": {"air_density_kg_m3": 1.1}},
              {"wind": {"speed_m_s": 10.0, "profile": "power"}, "environment": {"wind_speed_m_s": 0.0},
               "discretisation": {"scheme": "spline"}},
              {"lifter": {"top": "circle"}},
              {"lifter": {"top": "lifted", "force_N": 300.0},
               "ends": {"circle_radius_m": 0.1, "circle_frequency_Hz": 1.0}}]
    found = []
    for trial in trials:
        try:
            base.replace(**trial)
        except ParameterError as err:
            # a switch's rule names the value it is about: `model.twist = false` needs ...
            key = (f"{err.key} = {scene.toml_value(err.value)}"
                   if isinstance(err.value, (bool, str, int, float)) else err.key)
            if (key, err.allowed) not in found:
                found.append((key, err.allowed))
    return found


GENERATORS = {"commands": commands, "scene-keys": scene_keys}


def _fill(app, docname, source):
    """source-read: replace each marker by its generated Markdown."""
    source[0] = MARKER.sub(lambda m: GENERATORS[m.group(1)](), source[0])


def _plain_bars(app, what, name, obj, options, lines):
    """autodoc-process-docstring: the docstrings are plain text, where |x| is an
    absolute value, not a reST substitution; escape the bars (tables aside)."""
    for i, line in enumerate(lines):
        if not line.lstrip().startswith(("|", "+")):
            lines[i] = line.replace("|", "\\|")


def setup(app):
    app.connect("source-read", _fill)
    app.connect("autodoc-process-docstring", _plain_bars)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}


if __name__ == "__main__":
    print(GENERATORS[sys.argv[1]]())
