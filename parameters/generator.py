"""The scene's ``[generator]`` section: the generator at the ground end
(operation/generator.py has its law).  ``law = "paper"`` (the default) is Eq. (40),
the [controller]'s ground torque, as the paper's scenes have it."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path

from rawehelix.operation.generator import LAWS
from rawehelix.parameters.checks import ParameterError, _non_negative, _positive
from rawehelix.parameters.tables import numbers, read_beside, read_csv

COLUMNS = ("rpm", "torque_Nm")  # the torque table's CSV columns
#: the keys each law reads (any other given is refused)
READS = {"paper": (), "mppt": ("mppt_gain_Nms2", "rated_power_W", "release_rpm"),
         "torque": ("torque_Nm", "table", "speeds_rpm", "torques_Nm", "rated_power_W",
                    "release_rpm")}


@dataclass(frozen=True)
class Generator:
    """The ground end's torque tau(Omega) (operation/generator.py)."""

    # "paper": Eq. (40), the controller section's ground torque; "mppt": tau = k Omega^2;
    # "torque": a constant torque or a table tau(rpm)
    law: str = "paper"
    mppt_gain_Nms2: float = 0.0  # k of law "mppt": tau = k Omega^2 [N m s^2]
    torque_Nm: float = 0.0  # law "torque": its constant torque [N m]
    # law "torque": a CSV file with the columns rpm, torque_Nm (its path relative to the
    # scene file); "": none
    table: str | None = None
    speeds_rpm: tuple[float, ...] | None = None  # law "torque": the table's speeds, from 0, increasing (inline) [rpm]
    torques_Nm: tuple[float, ...] | None = None  # law "torque": the torque at each speed, >= 0 (inline) [N m]
    # above it the generator holds the power: tau = P_rated / Omega; absent: no cap [W]
    rated_power_W: float | None = None
    # a start-up from rest (issue 44): the run starts from the untwisted helix at rest in
    # the wind, the generator's torque zero until the ground end first spins at this
    # speed, then ramped in over operation/generator.RELEASE_RAMP_S; absent: the run
    # starts at the operating point with the generator on [rpm]
    release_rpm: float | None = None

    def __post_init__(self):
        if self.law not in LAWS:
            raise ParameterError("generator.law", self.law, f"must be one of {LAWS}")
        for name in ("speeds_rpm", "torques_Nm"):
            if getattr(self, name) is not None:
                object.__setattr__(self, name, numbers(f"generator.{name}", getattr(self, name)))
        if self.table is not None and not (isinstance(self.table, str)
                                           and self.table.lower().endswith(".csv")):
            raise ParameterError("generator.table", self.table, "must be a CSV file's name (*.csv)")
        if self.table and not self.speeds_rpm:  # the API: relative to the working folder
            for name, col in read_table(self.table, Path(".")).items():
                object.__setattr__(self, name, col)
        for f in dataclasses.fields(self):
            if f.name != "law" and f.name not in READS[self.law] and getattr(self, f.name) != f.default:
                readers = " or ".join(repr(k) for k, v in READS.items() if f.name in v)
                raise ParameterError(f"generator.{f.name}", getattr(self, f.name),
                                     f"is read only with generator.law = {readers}")
        if self.law == "mppt" and not (self.mppt_gain_Nms2 > 0 and math.isfinite(self.mppt_gain_Nms2)):
            raise ParameterError("generator.mppt_gain_Nms2", self.mppt_gain_Nms2,
                                 "must be a finite number > 0 with generator.law = 'mppt' "
                                 "(tau = k Omega^2)")
        _non_negative("generator", self, "torque_Nm")
        if self.rated_power_W is not None:
            _positive("generator", self, "rated_power_W")
        if self.release_rpm is not None and not (isinstance(self.release_rpm, (int, float))
                                                 and 0 <= self.release_rpm < math.inf):
            raise ParameterError("generator.release_rpm", self.release_rpm,
                                 "must be a finite number of rpm >= 0 (absent: no start-up)")
        if self.law == "torque":
            self._check_torque()

    def _check_torque(self):
        tabulated = self.speeds_rpm is not None or self.torques_Nm is not None
        if not tabulated and not self.torque_Nm > 0:
            raise ParameterError("generator.torque_Nm", self.torque_Nm,
                                 "must be > 0 with generator.law = 'torque', or give its table")
        if tabulated and self.torque_Nm > 0:
            raise ParameterError("generator.torque_Nm", self.torque_Nm,
                                 "and the torque table both give generator.law = 'torque' its "
                                 "torque: keep one")
        if tabulated:
            fault = table_fault(self.speeds_rpm or (), self.torques_Nm or ())
            if fault:
                row, what = fault
                key = "generator.table" if self.table else "generator.speeds_rpm"
                raise ParameterError(key, self.table or None, f"{f'row {row}: ' if row else ''}{what}")

    @classmethod
    def from_scene(cls, values: dict, folder: Path) -> "Generator":
        """The section as a scene gives it: ``table`` read relative to the scene's
        ``folder`` (studies/scene.py)."""
        return cls(**read_beside("generator", values, folder, ("speeds_rpm", "torques_Nm"),
                                 read_table))

    @property
    def active(self) -> bool:
        """A law of its own (not the [controller]'s Eq. 40)."""
        return self.law != "paper"

    def describe(self) -> str:
        cap = "" if self.rated_power_W is None else f", rated {self.rated_power_W:g} W"
        return f"generator: {self.law}{cap}"


def table_fault(rpm, torque) -> tuple[int, str] | None:
    """The first fault of a torque table as (row, what) (row 0: the whole table), or
    None: equal lengths, at least 2 rows, finite, rpm from 0 and increasing, torque >= 0."""
    if len(rpm) != len(torque):
        return 0, f"speeds and torques must have equal lengths (got {len(rpm)}, {len(torque)})"
    if len(rpm) < 2:
        return 0, f"has {len(rpm)} rows: at least 2 are needed"
    for i, (w, t) in enumerate(zip(rpm, torque), start=1):
        if not (math.isfinite(w) and math.isfinite(t)):
            return i, f"rpm = {w!r}, torque = {t!r}: not finite numbers"
        if i == 1 and w != 0:
            return i, f"rpm = {w!r}: the table starts at 0 rpm"
        if i > 1 and not w > rpm[i - 2]:
            return i, f"rpm = {w!r} does not increase: the table must be sorted in rpm"
        if t < 0:
            return i, f"torque = {t!r} is negative"
    return None


def read_table(table: str, folder: Path) -> dict:
    """{speeds_rpm, torques_Nm} of the CSV ``table`` (relative to ``folder``)."""
    columns, lines = read_csv("generator.table", folder, table, COLUMNS)
    fault = table_fault(columns["rpm"], columns["torque_Nm"])
    if fault:
        row, what = fault
        raise ParameterError("generator.table", table,
                             f"{f'line {lines[row - 1]} (row {row}): ' if row else ''}{what}")
    return {"speeds_rpm": columns["rpm"], "torques_Nm": columns["torque_Nm"]}


def check(params) -> None:
    """What the generator cannot run with: a law of its own beside the [controller]'s."""
    if params.generator.active and params.controller.active:
        raise ParameterError("generator.law", params.generator.law,
                             "and [controller] (Eq. 40) both set the ground torque: set "
                             "controller.k1 = controller.k2 = 0, or generator.law = 'paper'")
