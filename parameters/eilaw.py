"""The EI law's scene value, ``helix.EI_law`` (tension-dependent bending, Eq. 64)."""

from __future__ import annotations

from dataclasses import dataclass

from rawehelix.parameters.checks import ParameterError, _non_negative, _positive


@dataclass(frozen=True)
class EILaw:
    """Tension-dependent bending stiffness, EI = a T + b at the local tension
    T = EA eps (Eq. 64 and Fig. 4 of the paper: a = 52.4 Nm^2/N, b = 2290 Nm^2
    from the lab's bending tests at T_e = 90, 181, 259 N); forms/extensible.py.
    a >= 0 and b > 0, so EI > 0 at every tension T > -b/a."""

    a_Nm2_per_N: float  # a = dEI/dT [N m^2 / N]
    b_Nm2: float  # b = EI at zero tension [N m^2]

    def __post_init__(self):
        _non_negative("helix.EI_law", self, "a_Nm2_per_N")
        _positive("helix.EI_law", self, "b_Nm2")

    def EI_Nm2(self, tension_N):
        """EI = a T + b [N m^2] at the tension T [N]."""
        return self.a_Nm2_per_N * tension_N + self.b_Nm2

    def describe(self) -> str:
        return f"EI law: EI = {self.a_Nm2_per_N:g} Nm^2/N x T + {self.b_Nm2:g} Nm^2"

    def failure_hint(self, EA_N: float) -> str:
        """What a failed solve with the law should be told: its stored energy
        1/2 EA eps^2 + 1/2 (a EA eps + b) kappa^2 is convex only while kappa^2 <
        EI / (a^2 EA) (forms/extensible.py), and a driven or loaded rod may pass it."""
        if self.a_Nm2_per_N == 0:
            return ""
        limit = (self.b_Nm2 / (self.a_Nm2_per_N**2 * EA_N)) ** 0.5
        return (f" With helix.EI_law the rod's stored energy is convex only while the "
                f"curvature kappa < sqrt(EI / EA) / a ({limit:.3g} 1/m at zero tension, "
                f"growing with sqrt(EI(T))); where the rod's curvature passes it the model "
                f"has no stable state and a smaller step will not help: try smaller loads or "
                f"amplitudes, or a smaller a.")


#: the law the paper measured, Eq. (64) and Fig. 4: EI = 52.4 T + 2290
PAPER_EI_LAW = EILaw(a_Nm2_per_N=52.4, b_Nm2=2290.0)


#: its normalised groups (parameters/scene.py::GROUP_KEYS), Eq. (64) over Eq. (26)
GROUP_KEYS = {
    "mu_per_tension": ("a/L0^2", "Eq. 64", ("helix.EI_law.a_Nm2_per_N",), ("helix.length_m",)),
    "mu_at_zero_tension": ("b/(M g L0^2)", "Eq. 64", ("helix.EI_law.b_Nm2",),
                           ("helix.mass_kg", "environment.g_m_s2", "helix.length_m")),
}


#: where the law lives in a scene: Parameters.helix.EI_law, a value Helix declares
#: itself (an inline table, or None), not a table of its own
HOLDER, KEY, SECTION = "helix", "EI_law", None

#: its fields of Normalised, off: mu = mu_per_tension T~ + mu_at_zero_tension at the
#: local normalised tension T~ = sigma eps, i.e. a / L0^2 and b / (M g L0^2)
NORMALISED = {"bending_law": False, "mu_per_tension": 0.0, "mu_at_zero_tension": 0.0}


def normalise(p, scales: dict) -> dict:
    """Normalised's bending_law, mu_per_tension = a / L0^2, mu_at_zero_tension = b / (M g L0^2)."""
    law, L0, M, g = p.helix.EI_law, scales["L0"], scales["M"], scales["g"]
    return {"bending_law": law is not None,
            "mu_per_tension": 0.0 if law is None else law.a_Nm2_per_N / L0**2,
            "mu_at_zero_tension": 0.0 if law is None else law.b_Nm2 / (M * g * L0**2)}


def check(params) -> None:
    """What the law cannot run with (``params`` a whole scene): the paper's kinematics."""
    if params.helix.EI_law is not None and params.model.kinematics != "extensible":
        raise ParameterError(
            "helix.EI_law", params.helix.EI_law,
            "needs model.kinematics = 'extensible': the law is built from the stored "
            "energy 1/2 EI(eps) kappa^2, whose variation gives the axial force its "
            "1/2 EI'(eps) kappa^2; the paper's forces (Eqs. 32-33) are not the "
            "variation of an energy and act with EI on axial motion (forms/extensible.py)")
