"""A scene's tables of numbers: a CSV file beside the scene, or inline arrays
(the rotor's Cp/CT table, the generator's torque table)."""

from __future__ import annotations

import csv
import math
import sys
from pathlib import Path

from rawehelix.parameters.checks import ParameterError


def numbers(key: str, values) -> tuple[float, ...]:
    """An inline array of a scene as floats; ParameterError naming the key otherwise."""
    if isinstance(values, (str, bytes, dict)) or not hasattr(values, "__iter__"):
        raise ParameterError(key, values, "must be an array of numbers")
    out = []
    for i, v in enumerate(values, start=1):
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise ParameterError(key, values, f"must be an array of numbers (row {i} is {v!r})")
        if isinstance(v, int) and abs(v) > sys.float_info.max:
            raise ParameterError(key, f"row {i}", "must be a finite number")
        out.append(float(v))
    return tuple(out)


def read_csv(key: str, folder: Path, name: str, columns: tuple[str, ...]) -> tuple[dict, list[int]]:
    """``columns`` of the CSV file ``name`` in ``folder`` (the scene's; an absolute name
    is itself), with a header line naming them (any order, other columns
    ignored; lines starting with '#' and blank lines skipped) as {column: tuple of
    floats}, and each row's line number.  ParameterError naming ``key``, the file and
    the line otherwise."""
    path = folder / name
    try:
        text = path.read_text(encoding="utf-8")
    except (FileNotFoundError, NotADirectoryError, IsADirectoryError):
        raise ParameterError(key, name, f"no such file in {folder.resolve()} (a table's path "
                             "is relative to the scene file's folder)") from None
    except (OSError, UnicodeDecodeError, ValueError) as err:
        raise ParameterError(key, name, f"cannot be read as UTF-8 text ({err})") from None
    lines = [(n, line) for n, line in enumerate(text.splitlines(), start=1)
             if line.strip() and not line.lstrip().startswith("#")]
    if not lines:
        raise ParameterError(key, name, f"has no header line: it must name the columns "
                             f"{', '.join(columns)}")
    rows = list(csv.reader([line for _, line in lines]))
    header = [h.strip() for h in rows[0]]
    missing = [c for c in columns if c not in header]
    if missing:
        raise ParameterError(key, name, f"line {lines[0][0]}: the header {header} lacks "
                             f"the column {missing[0]!r} (it must name {', '.join(columns)})")
    where = {c: header.index(c) for c in columns}
    out = {c: [] for c in columns}
    for (n, _), row in zip(lines[1:], rows[1:]):
        if len(row) != len(header):
            raise ParameterError(key, name, f"line {n} has {len(row)} cells, the header "
                                 f"{len(header)}")
        for c in columns:
            try:
                value = float(row[where[c]])
            except ValueError:
                raise ParameterError(key, name, f"line {n}: {c} = {row[where[c]].strip()!r} "
                                     "is not a number") from None
            if not math.isfinite(value):
                raise ParameterError(key, name, f"line {n}: {c} = {value!r} is not a "
                                     "finite number")
            out[c].append(value)
    return {c: tuple(v) for c, v in out.items()}, [n for n, _ in lines[1:]]


def read_beside(section: str, values: dict, folder: Path, inline: tuple[str, ...], read) -> dict:
    """A section's ``values`` as a scene gives them, with the CSV its ``table`` names read
    relative to the scene's ``folder`` by ``read(table, folder)`` into the ``inline``
    keys; a scene that gives both the file and an inline column is refused."""
    table = values.get("table")
    if not (isinstance(table, str) and table.lower().endswith(".csv")):
        return values  # no file: the dataclass checks the name and the inline columns
    given = [f"{section}.{name}" for name in inline if name in values]
    if given:
        raise ParameterError(given[0], None, f"and {section}.table both give the table: keep one")
    return {**values, **read(table, folder)}
