"""The scene's ``[lifter]`` section: what holds the top end up.  ``top = "fixed"``
(the default) is the paper's: the top end's position prescribed by [ends] (Eqs. 35-36,
66; on Eq. 70's circle when ends.circle_radius_m > 0, as mobile_end has it)."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from rawehelix.parameters.checks import ParameterError

#: "fixed": [ends]' position (the paper's); "lifted": a point mass (rotor and hub)
#: under its weight, the rotor's thrust, the lifter's force and the helix's end force;
#: "circle": Eq. (70)'s circle of [ends] (ends.circle_radius_m > 0)
TOPS = ("fixed", "lifted", "circle")
LIFTED_KEYS = ("force_N", "elevation_deg", "azimuth_deg")  # read by top = "lifted" only


@dataclass(frozen=True)
class Lifter:
    """The top end's support (module docstring)."""

    top: str = "fixed"  # "fixed" (the paper's: the ends section's), "lifted" (the lifter's force) or "circle" (Eq. 70)
    force_N: float = 0.0  # top = "lifted": the lifter's pull on the top end [N]
    elevation_deg: float = 90.0  # top = "lifted": its direction's angle above the horizontal [deg]
    # top = "lifted": its direction's horizontal angle from downwind (-i_E, the way the
    # chord leans) toward j_E [deg]
    azimuth_deg: float = 0.0

    def __post_init__(self):
        if self.top not in TOPS:
            raise ParameterError("lifter.top", self.top, f"must be one of {TOPS}")
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if f.name in LIFTED_KEYS and not (isinstance(value, (int, float)) and math.isfinite(value)):
                raise ParameterError(f"lifter.{f.name}", value, "must be a finite number")
            if self.top != "lifted" and f.name in LIFTED_KEYS and value != f.default:
                raise ParameterError(f"lifter.{f.name}", value,
                                     "is read only with lifter.top = 'lifted'")
        if self.top == "lifted":
            if not 0 < self.elevation_deg <= 90:
                raise ParameterError("lifter.elevation_deg", self.elevation_deg,
                                     "must lie in (0, 90]: the lifter holds the top end up")
            if not -360 <= self.azimuth_deg <= 360:
                raise ParameterError("lifter.azimuth_deg", self.azimuth_deg,
                                     "must lie in [-360, 360]")
            if not self.force_N > 0:
                raise ParameterError("lifter.force_N", self.force_N,
                                     "must be > 0 with lifter.top = 'lifted' (the lifter's pull)")

    @property
    def active(self) -> bool:
        """The top end is held by the lifter's force (not a prescribed position)."""
        return self.top == "lifted"

    def direction(self) -> tuple[float, float, float]:
        """The unit vector of the lifter's force in the paper's (i_E, j_E, k_E), whose
        k_E points down (gravity is +k_E) and whose wind blows along -i_E:
        cos(e) (cos(a) (-i_E) + sin(a) j_E) - sin(e) k_E."""
        e, a = math.radians(self.elevation_deg), math.radians(self.azimuth_deg)
        return (-math.cos(e) * math.cos(a), math.cos(e) * math.sin(a), -math.sin(e))

    def describe(self) -> str:
        if not self.active:
            return f"top: {self.top}"
        return (f"top: lifted by {self.force_N:g} N at {self.elevation_deg:g} deg elevation, "
                f"{self.azimuth_deg:g} deg azimuth")


def check(params) -> None:
    """What the top's support cannot run with: the circle of [ends] with the lifter's
    force, or top = "circle" without one."""
    top, radius = params.lifter.top, params.ends.circle_radius_m
    if top == "circle" and not (radius > 0 and params.ends.circle_frequency_Hz > 0):
        raise ParameterError("lifter.top", top, "needs ends.circle_radius_m > 0 and "
                             "ends.circle_frequency_Hz > 0 (Eq. 70's circle)")
    if top == "lifted" and radius > 0:
        raise ParameterError("lifter.top", top, "holds the top end by a force: set "
                             "ends.circle_radius_m = 0 (the circle prescribes its position)")
