"""The scene's ``[section]`` section: the section law, a solid or the tensegrity's
members (members.py; forms/ holds its UFL energy).

``law = "solid"`` (the default) is the paper's section, EA, EI and GJ of ``[helix]``;
its members' keys still describe the tensegrity that the ``limits`` block of every
result measures the solid's resultants against (members.py: what a tensegrity
would feel).  ``law = "tensegrity"`` makes the section's resultants those of the
members, ``law = "saturating"`` the solid's EA and EI inside the cone |M| <= c N R
(forms/section_law.py: their stored energies in the extensible rod).  The twist keeps
helix.GJ_Nm2 unless ``torsion = "members"``: the tensegrity's members then carry it
too (the lay's and the tension's torque, members.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from rawehelix import section_laws
from rawehelix.members import Members, critical_twist
from rawehelix.parameters.checks import ParameterError, _non_negative, _positive
from rawehelix.parameters.numerics import BESIDE_CONTINUUM

#: the section laws' names, the registry's (section_laws.py): "saturating" is the fallback
#: law of issue 29 (members.py::ConeSection), the solid's EA and EI inside the cone
#: |M| <= c N R of a tension-only section, convex
LAWS = section_laws.NAMES
#: who carries the twist: the scene's GJ ("helix") or the members ("members", tensegrity only)
TORSIONS = ("helix", "members")
#: the ring's phase against the bending plane (members.py): "worst", a member on the
#: bending plane (the envelope of every phase); "turning", the phase the directors give
RINGS = ("worst", "turning")
#: the continuum's twist inertia: Eq. 27's solid, or the section's mass distribution
TWIST_INERTIAS = ("solid", "members")


@dataclass(frozen=True)
class Section:
    """The cross-section of the helix: a ring of ``tethers`` evenly spaced tension-only
    members at radius R laid at the angle beta to the axis, with bars on the axis that
    carry the self-stress (members.py has the law and every symbol)."""

    law: str = "solid"  # "solid": the helix's EA, EI, GJ; "tensegrity": the members; "saturating": |M| <= c N R
    tethers: int = 6  # n, tethers around the section [-] (an assumption: the paper gives none)
    radius_m: float | None = None  # R, the tethers' radius [m]; None: helix.radius_m (Table 1)
    lay_angle_deg: float = 0.0  # beta, the tethers' angle to the axis, one hand [deg]
    tether_EA_N: float | None = None  # k, one tether's axial stiffness; None: taut EA = helix.EA_N [N]
    self_stress_N: float = 0.0  # P0, each tether's tension at zero rod strain [N]
    bar_EA_N: float = 0.0  # EA_b, the bars' axial stiffness, on the axis [N]; > 0 with P0 > 0
    breaking_force_N: float | None = None  # F_b, a tether's breaking force [N]; None: not set
    ring_spacing_m: float | None = None  # l, between adjacent rings (torsional collapse); None: off [m]
    # the number of rings along the helix, both end rings included: l = helix.length_m /
    # (rings - 1), the unstretched spacing; instead of ring_spacing_m (one of them, or
    # neither), it switches on the torsional collapse check as that does; None: off
    rings: int | None = None
    slack_width: float = 1.0e-5  # w, the strain over which a tether goes slack (regularisation) [-]
    torsion: str = "helix"  # the twist's moment: "helix" (GJ_Nm2) or "members" (their torque)
    ring: str = "worst"  # the ring's phase: "worst" (a member on the bending plane) or "turning" (with alpha)
    # the mass of one ring of the network reference (--scheme network) [kg]; None: the
    # helix's mass lumped at the rings, helix.mass_kg / (rings - 1) each (the end rings,
    # fixed, half that); the network's tethers are massless
    ring_mass_kg: float | None = None
    # a ring's moment of inertia about its own axis (network reference) [kg m^2]; None:
    # a hoop's, ring mass x R^2 (its mass at the tethers' radius)
    ring_polar_inertia_kgm2: float | None = None
    # a ring's moment of inertia about a diameter (network reference) [kg m^2]; None: a
    # hoop's, ring mass x R^2 / 2
    ring_diametral_inertia_kgm2: float | None = None
    # the continuum's twist inertia (and the shearable rod's rotary inertia): "solid",
    # the paper's homogeneous solid, 2 rho I = 2 (M / L0) EI / EA (Eq. 27's delta); or
    # "members", from the section's mass distribution: each ring's inertia (the ring_*
    # keys) per unit length and the rest of helix.mass_kg at the tethers' radius R
    twist_inertia: str = "solid"

    def __post_init__(self):
        if section_laws.refusal(self.law):
            raise ParameterError("section.law", self.law, section_laws.refusal(self.law))
        if isinstance(self.tethers, bool) or not isinstance(self.tethers, int) or self.tethers < 3:
            raise ParameterError("section.tethers", self.tethers,
                                 "must be an integer >= 3 (a ring of tethers)")
        if self.torsion not in TORSIONS:
            raise ParameterError("section.torsion", self.torsion, f"must be one of {list(TORSIONS)}")
        if self.twist_inertia not in TWIST_INERTIAS:
            raise ParameterError("section.twist_inertia", self.twist_inertia,
                                 f"must be one of {list(TWIST_INERTIAS)}")
        if self.ring not in RINGS:
            raise ParameterError("section.ring", self.ring, f"must be one of {list(RINGS)}")
        members = section_laws.get(self.law).members  # the law's resultants are its members'
        if self.ring == "turning" and not members:
            raise ParameterError("section.ring", self.ring,
                                 "only the tensegrity's members have a phase: set section.law = "
                                 "'tensegrity' or ring = 'worst'")
        if self.torsion == "members" and not members:
            raise ParameterError("section.torsion", self.torsion,
                                 "the members carry the twist only with section.law = 'tensegrity'")
        if not (0 <= self.lay_angle_deg < 60):
            raise ParameterError("section.lay_angle_deg", self.lay_angle_deg,
                                 "must lie in [0, 60) degrees")
        _non_negative("section", self, "self_stress_N", "bar_EA_N")
        _positive("section", self, "slack_width")
        for name in ("radius_m", "tether_EA_N", "breaking_force_N", "ring_spacing_m",
                     "ring_mass_kg", "ring_polar_inertia_kgm2", "ring_diametral_inertia_kgm2"):
            if getattr(self, name) is not None:
                _positive("section", self, name)
        if self.rings is not None:
            if isinstance(self.rings, bool) or not isinstance(self.rings, int) or self.rings < 2:
                raise ParameterError("section.rings", self.rings,
                                     "must be an integer >= 2 (the rings along the helix, both "
                                     "end rings included)")
            if self.ring_spacing_m is not None:
                raise ParameterError("section.rings", self.rings,
                                     f"and section.ring_spacing_m = {self.ring_spacing_m!r} "
                                     "both set the rings' spacing: give one of them")
        if self.self_stress_N > 0 and self.bar_EA_N <= 0:
            raise ParameterError("section.self_stress_N", self.self_stress_N,
                                 "a self-stress needs bars to balance it: set section.bar_EA_N > 0")
        if self.slack_width >= 1e-2:
            raise ParameterError("section.slack_width", self.slack_width,
                                 "must be below 1e-2 (a strain; the tethers' strains are ~1e-3)")

    @property
    def active(self) -> bool:
        """A law other than the solid (the paper's model) is on: the section's energy is
        the law's own (section_laws.py)."""
        return section_laws.get(self.law).nonlinear

    def members(self, helix, width: float | None = None) -> Members:
        """The :class:`~rawehelix.members.Members` of this section on ``helix`` (SI);
        ``width`` overrides the slack width (0: the unregularised law)."""
        beta = math.radians(self.lay_angle_deg)
        n, P0, EA_b = self.tethers, self.self_stress_N, self.bar_EA_N
        k = self.tether_EA_N
        if k is None:  # n (k cos^3 beta + P0 cos beta sin^2 beta) + EA_b = helix.EA_N
            k = ((helix.EA_N - EA_b) / n - P0 * math.cos(beta) * math.sin(beta) ** 2) \
                / math.cos(beta) ** 3
            if k <= 0:
                raise ParameterError("section.bar_EA_N", EA_b,
                                     f"leaves the tethers no stiffness: it must be below "
                                     f"helix.EA_N = {helix.EA_N:g} N, or set section.tether_EA_N")
        return Members(n=n, R=self.radius_m or helix.radius_m, beta=beta, k=k, P0=P0, EA_b=EA_b,
                       breaking_N=self.breaking_force_N, ring_spacing_m=self.spacing(helix),
                       width=self.slack_width if width is None else width)

    def spacing(self, helix) -> float | None:
        """l [m], between adjacent rings: ring_spacing_m, or L0 / (rings - 1) (rings
        counts both end rings); None: neither given (no torsional collapse check)."""
        if self.rings is not None:
            return helix.length_m / (self.rings - 1)
        return self.ring_spacing_m

    def ring_count(self, length_m: float) -> int:
        """The rings along a helix of length L0 [m], both ends included: ``rings``, or
        L0 / ring_spacing_m + 1 rounded (at least 2); ParameterError when neither is
        given (the network reference, --scheme network, needs them)."""
        if self.rings is not None:
            return self.rings
        if self.ring_spacing_m is not None:
            return max(2, round(length_m / self.ring_spacing_m) + 1)
        raise ParameterError("section.rings", None,
                             "--scheme network needs the rings: set section.rings (>= 3, both "
                             "end rings included) or section.ring_spacing_m")

    def inertia_per_length(self, helix) -> tuple[float, float] | None:
        """(polar, diametral) inertia of the section per unit length [kg m] from its mass
        distribution (twist_inertia = "members"): the rings' ring_polar_inertia_kgm2 and
        ring_diametral_inertia_kgm2 (default a hoop's, m R^2 and m R^2 / 2) over the
        spacing, and the helix's mass the rings do not carry at the tethers' radius R
        (a thin tube: (M' R^2, M' R^2 / 2)); None: the solid's (Eq. 27)."""
        if self.twist_inertia == "solid":
            return None
        R, mu = self.radius_m or helix.radius_m, helix.mass_kg / helix.length_m  # [m], [kg/m]
        l = self.spacing(helix)
        if l is None:  # no rings given: all the mass at the tethers' radius
            if self.ring_mass_kg is not None or self.ring_polar_inertia_kgm2 is not None \
                    or self.ring_diametral_inertia_kgm2 is not None:
                raise ParameterError("section.twist_inertia", self.twist_inertia,
                                     "with ring masses or inertias needs their spacing: set "
                                     "section.rings or section.ring_spacing_m")
            return mu * R * R, mu * R * R / 2
        m = self.ring_mass_kg if self.ring_mass_kg is not None else mu * l
        rest = mu - m / l  # the tethers' mass per unit length [kg/m]
        if rest < -1e-12 * mu:
            raise ParameterError("section.ring_mass_kg", self.ring_mass_kg,
                                 f"weighs more than helix.mass_kg per ring spacing ({mu * l:.4g} "
                                 "kg) for section.twist_inertia = 'members': lower it")
        rest = max(rest, 0.0)
        Jp = self.ring_polar_inertia_kgm2 or m * R * R
        Jd = self.ring_diametral_inertia_kgm2 or m * R * R / 2
        return Jp / l + rest * R * R, Jd / l + rest * R * R / 2

    def describe(self) -> str:
        return (f"section: {self.law}, torsion by the {self.torsion}, {self.tethers} tethers, "
                f"lay {self.lay_angle_deg:g} deg, ring {self.ring}, "
                f"self-stress {self.self_stress_N:g} N, slack width {self.slack_width:g}")


def helix_stiffness(section: Section, helix) -> dict:
    """helix.stiffness = "from_section": {EA_N, EI_Nm2, GJ_Nm2} of the members' taut
    moduli at zero strain (members.py's closed forms: K = n (k cos^3 beta + P0 cos beta
    sin^2 beta), EA = K + EA_b, EI = K R^2 / 2, GJ = n cos beta R^2 (k sin^2 beta + P0
    cos^2 beta)).  ParameterError naming what the section lacks to give them."""
    if section.tether_EA_N is None:
        raise ParameterError("section.tether_EA_N", None,
                             "is required by helix.stiffness = 'from_section' (one tether's "
                             "axial stiffness [N]: the section's EA, EI and GJ follow from it)")
    if section.lay_angle_deg == 0 and section.self_stress_N == 0:
        raise ParameterError("section.lay_angle_deg", section.lay_angle_deg,
                             "gives no torsional stiffness with section.self_stress_N = 0, so "
                             "helix.stiffness = 'from_section' has no GJ: set "
                             "section.lay_angle_deg > 0, or section.self_stress_N > 0 with "
                             "section.bar_EA_N > 0 (tethers at the tension P0 give GJ = "
                             "n P0 R^2)")
    try:
        taut = section.members(helix, width=0.0).taut_moduli()
    except OverflowError:  # R^2 past a float
        taut = {"EA": math.inf, "EI": math.inf, "GJ": math.inf}
    out = {"EA_N": taut["EA"], "EI_Nm2": taut["EI"], "GJ_Nm2": taut["GJ"]}
    if not all(math.isfinite(v) and v > 0 for v in out.values()):
        # out of a float's range: named, the input of the most extreme size
        inputs = {"section.tether_EA_N": section.tether_EA_N,
                  "section.radius_m" if section.radius_m else "helix.radius_m":
                      section.radius_m or helix.radius_m,
                  "section.lay_angle_deg": section.lay_angle_deg,
                  "section.self_stress_N": section.self_stress_N,
                  "section.bar_EA_N": section.bar_EA_N}
        key = max((k for k, v in inputs.items() if v), key=lambda k: abs(math.log10(inputs[k])))
        raise ParameterError(key, inputs[key],
                             "makes helix.stiffness = 'from_section''s EA, EI or GJ "
                             f"{', '.join(f'{k} = {v:.3g}' for k, v in out.items())}: out of "
                             "a float's range (1e-308 to 1e308)")
    return out


#: no groups for parameters/scene.py's range check: the members' groups are 0 while the
#: law is the solid whatever the keys say (normalise), which that check would refuse
GROUP_KEYS: dict = {}

#: where the section lives in a scene: Parameters.model.section (the file's [section])
HOLDER, KEY, SECTION = "model", "section", Section

#: its fields of Normalised, off (the solid: forms/section_law.py::SolidSection).  The
#: members normalised: R~ = R / L0, k~ = k / (M g), EA_b~ = EA_b / (M g); the
#: prestrains e0 = P0 / k and e_b0, the lay angle [rad], the slack width w and the
#: saturation c = max(-cos phi_m) (members.py) as they are
NORMALISED = {"section_tensegrity": False, "section_law": "solid", "section_tethers": 0,
              "section_radius": 0.0, "section_lay_angle": 0.0, "section_stiffness": 0.0,
              "section_prestrain": 0.0, "section_bar_stiffness": 0.0,
              "section_bar_prestrain": 0.0, "section_width": 0.0, "section_saturation": 0.0,
              "section_torsion": False, "section_ring_turns": False}


def normalise(p, scales: dict) -> dict:
    """Normalised's section fields: the members of :meth:`Section.members` in the
    units of Eqs. (25)-(27) (their values when off for the solid)."""
    section = p.model.section
    if not section.active:
        return {**NORMALISED}
    m = section.members(p.helix)
    force = scales["M"] * scales["g"]  # [N]
    return {"section_tensegrity": True, "section_law": section.law, "section_tethers": m.n,
            "section_radius": m.R / scales["L0"], "section_lay_angle": m.beta,
            "section_stiffness": m.k / force, "section_prestrain": m.e0,
            "section_bar_stiffness": m.EA_b / force, "section_bar_prestrain": m.e_b0,
            "section_width": m.width, "section_saturation": m.saturation,
            "section_torsion": section.torsion == "members",
            "section_ring_turns": section.ring == "turning"}


#: the most rings of the network reference: its modes are a dense eigenproblem of
#: 6 (rings - 2) dofs (1000 rings: 6e3 dofs, ~1.4 GB and a minute for scipy's eigh)
NETWORK_MAX_RINGS = 1000


def check_network_rings(section: Section, helix, rings: int) -> None:
    """Refuse a network (--scheme network) of fewer than 3 rings (none free) or more
    than NETWORK_MAX_RINGS, bars too soft to hold the self-stress, or rings so far
    apart that the lay alone turns a bay past Tulloch's collapse angle
    (members.py::critical_twist of the bay's chord): such a network has no state near
    its straight chord.  delta_0 = l tan(beta) / R, l = L0 / (rings - 1)."""
    if not 3 <= rings <= NETWORK_MAX_RINGS:
        raise ParameterError("section.rings", rings,
                             f"--scheme network needs 3 to {NETWORK_MAX_RINGS} rings (one free "
                             "between the held end rings; its modes are a dense eigenproblem "
                             "of 6 (rings - 2) dofs): set section.rings or "
                             "section.ring_spacing_m")
    m = section.members(helix)
    if m.P0 > 0 and m.n * m.P0 >= m.EA_b:
        raise ParameterError("section.bar_EA_N", m.EA_b,
                             f"must exceed n P0 = {m.n * m.P0:g} N for the network's bars: "
                             "they would shorten by more than their length to hold the "
                             "self-stress (section.self_stress_N)")
    l = helix.length_m / (rings - 1)
    lay = l * math.tan(m.beta) / m.R
    if lay <= 0:
        return
    crit = critical_twist(m.R, math.hypot(l, 2 * m.R * math.sin(lay / 2))) \
        if math.isfinite(lay) else 0.0
    if lay >= crit:
        raise ParameterError("section.rings", rings,
                             f"turns each bay of the network by its lay, l tan(beta) / R = "
                             f"{lay:.3g} rad, past Tulloch's collapse angle {crit:.3g} rad of "
                             "its tethers: give more rings (section.rings)")


def check(params) -> None:
    """What the tensegrity law cannot run with (``params`` a whole scene): its resultants
    are the variation of the members' energy, so it needs the extensible kinematics
    (model.kinematics = "extensible") of the FE scheme with the IP bending form."""
    section, disc = params.model.section, params.discretisation
    if disc.scheme in BESIDE_CONTINUUM:  # the network's rings, before any work
        check_network_rings(section, params.helix, section.ring_count(params.helix.length_m))
    if section.active and (params.model.kinematics not in ("extensible", "shearable")
                           or disc.continuum_scheme != "fe" or disc.bending != "ip"):
        raise ParameterError("section.law", section.law,
                             f"'{section.law}' needs model.kinematics = 'extensible' (or "
                             "'shearable') on the FE scheme with discretisation.bending = 'ip' "
                             "(its forces are the variation of the section's energy, "
                             "forms/section_law.py)")
    if section.active and params.helix.EI_law is not None:
        raise ParameterError("section.law", section.law,
                             f"'{section.law}' sets EI itself: remove helix.EI_law "
                             "(one bending law at a time)")
    if section.torsion == "members" and params.model.torsion_hysteresis.active:
        raise ParameterError("section.torsion", section.torsion,
                             "the members' torque and [torsion_hysteresis] are two torsion laws: "
                             "keep one")
    members = section.members(params.helix)  # the derived tether stiffness is positive
    # the members' torque needs a twist stiffness at zero strain: a lay or a self-stress
    if section.torsion == "members" and members.taut_moduli()["GJ"] <= 0:
        raise ParameterError("section.torsion", section.torsion,
                             "the members have no torsional stiffness at zero strain "
                             "(lay_angle_deg = 0 and self_stress_N = 0): set one of them")
