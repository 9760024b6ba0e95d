"""Helpers for the tests (not a test module)."""

import tomllib

from rawehelix.studies import scene


def _toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return f'"{v}"'
    return repr(v)


def write_scene(path, changes: dict, base: dict | None = None, name="stationary_table2"):
    """Write the shipped scene ``name`` (or ``base``) with ``changes`` applied."""
    data = base if base is not None else tomllib.loads(scene.resolve(name).read_text())
    for section, values in changes.items():
        data.setdefault(section, {}).update(values)
    lines = []
    for key, value in data.items():
        if not isinstance(value, dict):
            lines.append(f"{key} = {_toml_value(value)}")
    for section, values in data.items():
        if isinstance(values, dict):
            lines.append(f"[{section}]")
            lines += [f"{k} = {_toml_value(v)}" for k, v in values.items()]
    path.write_text("\n".join(lines) + "\n")
    return path
