"""The scene values' one error and the range checks every section uses."""

from __future__ import annotations

import math


class ParameterError(ValueError):
    """A parameter is outside its allowed range.

    ``key`` is the dotted scene key (``helix.EA_N``) and ``allowed`` says what
    would be accepted, so that a scene loader can name file, key and range.
    """

    def __init__(self, key: str, value, allowed: str):
        self.key, self.value, self.allowed = key, value, allowed
        super().__init__(f"{key} = {value!r}: {allowed}")


def _positive(section: str, obj, *names: str) -> None:
    for name in names:
        value = getattr(obj, name)
        if not (value > 0 and math.isfinite(value)):
            raise ParameterError(f"{section}.{name}", value, "must be a finite number > 0")


def _non_negative(section: str, obj, *names: str) -> None:
    for name in names:
        value = getattr(obj, name)
        if not (value >= 0 and math.isfinite(value)):
            raise ParameterError(f"{section}.{name}", value, "must be a finite number >= 0")
