"""The shear stiffness's scene value, ``helix.GA_N``, and the shearable rod's refusals
(``model.kinematics = "shearable"``, forms/shearable.py, models/shearable.py)."""

from __future__ import annotations

from rawehelix import section_laws
from rawehelix.parameters.checks import ParameterError

#: its normalised group (parameters/scene.py::GROUP_KEYS), as sigma = EA / (M g), Eq. (27)
GROUP_KEYS = {
    "shear_stiffness": ("GA/(M g)", "Eq. 27 for GA", ("helix.GA_N",),
                        ("helix.mass_kg", "environment.g_m_s2")),
}

#: where it lives in a scene: Parameters.helix.GA_N, a value Helix declares itself
HOLDER, KEY, SECTION = "helix", "GA_N", None

#: its fields of Normalised, off: GA~ = GA / (M g) and the sections' rotary inertia
#: about a diameter per unit mass and L0^2, j~ = EI / (EA L0^2) (see :func:`normalise`)
NORMALISED = {"shear_stiffness": 0.0, "rotary_inertia": 0.0}


def thin_tube_GA(helix) -> float:
    """A thin tube's GA = GJ / (2 R^2) [N] (shear coefficient 1/2 of a thin-walled
    tube, G A R^2 = GJ): the estimate a scene without GA_N is pointed to."""
    return helix.GJ_Nm2 / (2 * helix.radius_m ** 2)


def normalise(p, scales: dict) -> dict:  # (the members' GA is a field: forms/section_law.py)
    """GA~ = GA / (M g) (0 without GA_N) and, with the shearable kinematics and
    ``model.rotary_inertia``, the rotary inertia of a section about a diameter,
    rho I_d / (rho A L0^2) = EI / (EA L0^2): half the polar inertia of Eq. (27)
    (2 rho I / (rho A) = 2 EI / EA, so beta / delta = 2 EI / (EA L0^2)) by the
    perpendicular-axis theorem of a planar section, I_d = J / 2."""
    h, M, g, L0 = p.helix, scales["M"], scales["g"], scales["L0"]
    rotary = (p.model.kinematics == "shearable" and p.model.rotary_inertia)
    J = p.model.section.inertia_per_length(h)  # section.twist_inertia = "members"
    # its diametral inertia per unit length [kg m] over (M / L0) L0^2
    Jd = h.EI_Nm2 / (h.EA_N * L0 ** 2) if J is None else J[1] / (M * L0)
    return {"shear_stiffness": 0.0 if h.GA_N is None else h.GA_N / (M * g),
            "rotary_inertia": Jd if rotary else 0.0}


#: what the shearable rod is not built with (models/shearable.py): key -> why
_REFUSED = {
    "helix.EI_law": "the EI law is written on the extensible rod's stored energy",
    "damping": "the Kelvin-Voigt potential is written on the unshearable rod's strains",
    "torsion_hysteresis": "the Bouc-Wen twist is not coupled to the shearable rod",
    "section.torsion": "the members' torque is written on the unshearable rod's twist "
                       "(keep torsion = 'helix')",
    "section.ring": "the turning ring's phase is written on the unshearable rod's frame "
                    "(keep ring = 'worst')",
    "model.gamma": "the shearable rod's twist is alpha' (gamma = 'off')",
}


def check(params) -> None:
    """What the shearable rod needs (``params`` a whole scene): the FE scheme, GA_N, and
    none of the components it is not built with; GA_N is refused by the other rods."""
    model, helix, disc = params.model, params.helix, params.discretisation
    if model.kinematics != "shearable":
        if helix.GA_N is not None:
            raise ParameterError("helix.GA_N", helix.GA_N,
                                 "is read by the shearable rod only: set model.kinematics = "
                                 "'shearable', or remove it")
        return
    if disc.continuum_scheme != "fe" or disc.bending != "ip":
        raise ParameterError("model.kinematics", "shearable",
                             "is implemented by the FE scheme (discretisation.scheme = 'fe', "
                             "bending = 'ip', its default) only")
    members = section_laws.get(model.section.law).members  # the members' own GA
    if helix.GA_N is None and not members:
        raise ParameterError("helix.GA_N", None,
                             f"the shearable rod needs the shear stiffness GA [N] (or "
                             f"section.law = 'tensegrity': the members' GA); a thin tube of "
                             f"this helix's GJ and radius has GJ / (2 R^2) = "
                             f"{thin_tube_GA(helix):.4g} N")
    if members and model.section.members(helix).shear_stiffness() <= 0:
        raise ParameterError("section.law", "tensegrity",
                             "with model.kinematics = 'shearable' the members need a shear "
                             "stiffness of their own: without a lay or a self-stress their GA is "
                             "the rod's tension, the lateral stiffness GA - T is zero and the "
                             "sections turn freely (docs/explanation/shearable.md); set "
                             "section.lay_angle_deg or section.self_stress_N")
    if helix.GA_N is not None and members:
        raise ParameterError("helix.GA_N", helix.GA_N,
                             "with section.law = 'tensegrity' GA is the members' (members.py::"
                             "Members.shear_stiffness, at their force): remove helix.GA_N")
    active = {"helix.EI_law": helix.EI_law is not None, "damping": model.damping.active,
              "torsion_hysteresis": model.torsion_hysteresis.active,
              "section.torsion": model.section.torsion != "helix",
              "section.ring": model.section.ring != "worst", "model.gamma": model.gamma != "off"}
    for key, on in active.items():
        if on:
            raise ParameterError(key, "set", f"with model.kinematics = 'shearable': {_REFUSED[key]}")
