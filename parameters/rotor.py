"""The scene's ``[rotor]`` section: the rotor at the top end, a rigid body with a
Cp/CT table (operation/rotor.py has its law).  No table: no rotor (the paper's)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

from rawehelix.operation.rotor import AXES, table_fault
from rawehelix.parameters.checks import ParameterError, _non_negative, _positive
from rawehelix.parameters.tables import numbers, read_beside, read_csv

COLUMNS = ("tsr", "cp", "ct")


@dataclass(frozen=True)
class Rotor:
    """The rotor: R, its inertia, mass and blades, and its table (a CSV file or inline
    arrays).  Q = 1/2 rho pi R^2 V_n^3 Cp(lambda) / Omega, F = 1/2 rho pi R^2 V_n^2
    CT(lambda), lambda = Omega R / V_n (operation/rotor.py).

    The table is ``tsr``, ``cp`` and ``ct``: a scene's ``table`` file is read into them
    by the scene loader (relative to the scene's folder), and ``table`` then records
    where they came from.  In code, change the table through them
    (``params.replace(rotor={"tsr": .., "cp": .., "ct": ..})``): a ``replace`` of
    ``table`` alone keeps the arrays it already has; ``Rotor(table=FILE)`` without
    arrays reads FILE relative to the working folder."""

    radius_m: float | None = None  # R, the rotor's radius; required with a table [m]
    spin_inertia_kgm2: float = 0.0  # J, the rotor's moment of inertia about its axis [kg m^2]
    mass_kg: float = 0.0  # the rotor and hub's mass [kg]
    blades: int = 3  # the blades: the nP excitation lines of the Campbell diagram
    # the Cp/CT table: a CSV file with the columns tsr, cp, ct (its path relative to the
    # scene file; '#' lines are comments); absent: none (or give tsr, cp and ct inline)
    table: str | None = None
    tsr: tuple[float, ...] | None = None  # lambda = Omega R / V_n of each row, increasing (inline table) [-]
    cp: tuple[float, ...] | None = None  # Cp at each tsr, 0 <= Cp <= 16/27 (inline table) [-]
    ct: tuple[float, ...] | None = None  # CT at each tsr, >= 0 (inline table) [-]
    # the rotor's axis: "tangent", the helix's end tangent (V_n = V cos 45 deg at the
    # paper's elevation); "wind", facing the wind (V_n = V at the hub)
    axis: str = "tangent"

    def __post_init__(self):
        for name in COLUMNS:
            if getattr(self, name) is not None:
                object.__setattr__(self, name, numbers(f"rotor.{name}", getattr(self, name)))
        if self.table is not None and not (isinstance(self.table, str)
                                           and self.table.lower().endswith(".csv")):
            raise ParameterError("rotor.table", self.table, "must be a CSV file's name (*.csv)")
        if self.axis not in AXES:
            raise ParameterError("rotor.axis", self.axis, f"must be one of {AXES}")
        if self.table and not self.tsr:  # the API: relative to the working folder
            for name, col in read_table(self.table, Path(".")).items():
                object.__setattr__(self, name, col)
        if not self.active:
            given = [f.name for f in dataclasses.fields(self) if getattr(self, f.name) != f.default]
            if given:
                raise ParameterError("rotor.table", None, f"is required: [rotor] gives "
                                     f"rotor.{given[0]} but no table (rotor.table = 'FILE.csv' "
                                     "with the columns tsr, cp, ct, or rotor.tsr, rotor.cp "
                                     "and rotor.ct inline)")
            return
        missing = [name for name in COLUMNS if getattr(self, name) is None]
        if missing:
            given = next(name for name in COLUMNS if name not in missing)
            raise ParameterError(f"rotor.{missing[0]}", None,
                                 f"is required with rotor.{given} (the inline table: rotor.tsr, "
                                 "rotor.cp and rotor.ct), or give rotor.table")
        if self.radius_m is None:
            raise ParameterError("rotor.radius_m", None, "is required with the rotor's table "
                                 f"(rotor.{'table' if self.table else 'tsr, cp, ct'})")
        _positive("rotor", self, "radius_m")
        _non_negative("rotor", self, "spin_inertia_kgm2", "mass_kg")
        if isinstance(self.blades, bool) or not isinstance(self.blades, int) or self.blades < 1:
            raise ParameterError("rotor.blades", self.blades, "must be an integer >= 1")
        fault = table_fault(self.tsr, self.cp, self.ct)
        if fault:
            row, column, what = fault
            key = "rotor.table" if self.table else f"rotor.{column}"
            raise ParameterError(key, self.table or None, f"{f'row {row}: ' if row else ''}{what}")

    @classmethod
    def from_scene(cls, values: dict, folder: Path) -> "Rotor":
        """The section as a scene gives it: ``table`` read relative to the scene's
        ``folder``, its faults named by the file's line (studies/scene.py)."""
        return cls(**read_beside("rotor", values, folder, COLUMNS, read_table))

    @classmethod
    def reference_example(cls) -> "Rotor":
        """A rotor that is on, for the scene-key reference's probes
        (docs/_ext/rawehelix_reference.py): its ranges are met only when a table is given."""
        return cls(radius_m=2.0, tsr=(1.0, 3.0, 5.0, 7.0), cp=(0.1, 0.3, 0.4, 0.2),
                   ct=(0.2, 0.5, 0.7, 0.8))

    @property
    def active(self) -> bool:
        """A table is given: the rotor is on."""
        return any(getattr(self, name) is not None for name in COLUMNS)

    def describe(self) -> str:
        if not self.active:
            return "rotor: none"
        return (f"rotor: R = {self.radius_m:g} m, {len(self.tsr)} rows of Cp/CT, "
                f"Cp_max = {max(self.cp):.4g}, axis {self.axis}")


def read_table(table: str, folder: Path) -> dict:
    """{tsr, cp, ct} of the CSV ``table`` (relative to ``folder``), its faults named by
    line: ParameterError("rotor.table", ...)."""
    columns, lines = read_csv("rotor.table", folder, table, COLUMNS)
    fault = table_fault(*(columns[c] for c in COLUMNS))
    if fault:
        row, _, what = fault
        where = f"line {lines[row - 1]} (row {row}): " if row else ""
        raise ParameterError("rotor.table", table, f"{where}{what}")
    return columns


def check(params) -> None:
    """What the rotor cannot run with (``params`` a whole scene): the torque ramp of
    Eq. (69), a second torque at the top end."""
    if params.rotor.active and params.torque.top_Nm != 0:
        raise ParameterError("torque.top_Nm", params.torque.top_Nm,
                             "and [rotor] both put a torque on the top end: set "
                             "torque.top_Nm = 0 with a rotor (its torque is the table's)")
