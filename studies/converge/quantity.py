"""What a named quantity of interest is: the registry of them is studies/quantities.py
(a driver that imports this room); here, below it, so that the refinement study
(:mod:`.study`) takes one without importing the registry."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from rawehelix.studies.converge.methods import Refinement


@dataclass(frozen=True)
class Quantity:
    name: str
    unit: str
    stage: str | None  # at a point: a key of STAGES, or "sweep@F1"; None: refined only
    pick: Callable | None  # stage result -> float (raises QuantityError if the result has none)
    doc: str
    refinement: Refinement | None = None  # refined (converge); None: at a point only

    def __post_init__(self):
        if (self.stage is None) != (self.pick is None) or (self.stage is None
                                                          and self.refinement is None):
            raise ValueError(f"quantity {self.name}: a stage with its pick, or a refinement")
