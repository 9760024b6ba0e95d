"""The forcing a frequency study needs: the upper end's circle of Eq. (70) with a
radius R1 > 0.  Without it nothing forces the helix (its response is the
stationary state at every f1): a sweep integrates to max_periods for nothing,
harmonic balance's Newton has nothing to scale and shooting finds "peaks" on a
flat branch.  ``sweep``, ``response``, ``orbits`` and ``envelope`` refuse such a
scene before any work (bad input, exit 2)."""

from __future__ import annotations

from rawehelix.errors import SceneError
from rawehelix.parameters import Parameters


#: the smallest radius of the circle, relative to L0, that forces more than the
#: round-off of the positions (normalised by L0, their round-off is ~1e-16)
MIN_RADIUS = 1.0e-12


def require(params: Parameters, command: str, where: str | None = None) -> None:
    """SceneError unless the scene's upper end moves on a circle of radius above
    MIN_RADIUS x L0 (``where``: what the message names instead of the scene, e.g. a
    --vary value)."""
    if params.normalised().r1 > MIN_RADIUS:
        return
    way = ("start the --vary range above 0" if where else
           "set circle_radius_m > 0 in the scene's [ends] (the shipped mobile_end has 0.1), "
           "or run with --set ends.circle_radius_m=0.1")
    raise SceneError(where or params.name, "ends.circle_radius_m",
                     f"{params.ends.circle_radius_m:g}: '{command}' needs the upper end's "
                     f"circle (Eq. 70) to force the helix, and a radius of at most "
                     f"{MIN_RADIUS:g} x helix.length_m forces nothing: "
                     f"{way}")
