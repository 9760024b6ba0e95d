"""The drag along the rod as the references take it (references/shooting.py): the wind
profile's factor on the uniform wind's drag of Eq. (28), and which references take a
uniform load only.  numpy and the parameters only, as every reference."""

from __future__ import annotations

from rawehelix.operation import wind
from rawehelix.parameters import Normalised


def drag_factor(normalised: Normalised):
    """The wind profile's (V(z)/V_ref)^2 as a function of the state's z (the height above
    the ground end is -z L0: k_E points down), which scales the drag of
    shooting.load_vector along the rod; None for the uniform wind (the paper's: the
    drag is the same everywhere).  The profile is operation/wind.py's numpy law, the
    FE path's is forms/wind.py's UFL."""
    q = normalised
    if q.wind_profile == wind.UNIFORM:
        return None
    profile = wind.WindProfile(1.0, q.wind_reference * q.L0, q.wind_profile, q.wind_exponent,
                               q.wind_roughness * q.L0)
    return lambda z: profile.factor(-z * q.L0) ** 2


def uniform_load_only(params) -> str | None:
    """Why a reference that integrates a uniform load (the elastica's resultant
    N = N(0) - q s) does not model the scene's wind, or None."""
    if params.wind.uniform:
        return None
    return (f"wind.profile = {params.wind.profile!r}: the elastica's reference integrates "
            "a uniform load (the drag of a uniform wind)")
