"""The scene's ``[damping]`` section: Kelvin-Voigt structural damping (forms/damping.py)."""

from __future__ import annotations

from dataclasses import dataclass

from rawehelix.parameters.checks import ParameterError, _non_negative


@dataclass(frozen=True)
class Damping:
    """Structural damping, Kelvin-Voigt on the strain rates (forms/damping.py): each
    viscous stress is the elastic modulus x the retardation time x the strain rate.
    A scene's ``[damping]`` section; all zero (the default) is the paper's model."""

    axial_s: float = 0.0  # tau_a: N_v = EA tau_a d|r'|/dt [s]
    bending_s: float = 0.0  # tau_b: m_v = EI tau_b (objective rate of the curvature) [s]
    torsion_s: float = 0.0  # tau_t: M_v = GJ tau_t d(tau)/dt [s]

    def __post_init__(self):
        _non_negative("damping", self, "axial_s", "bending_s", "torsion_s")

    @property
    def active(self) -> bool:
        return self.axial_s > 0 or self.bending_s > 0 or self.torsion_s > 0

    def describe(self) -> str:
        return (f"damping: Kelvin-Voigt tau_a = {self.axial_s:g} s, tau_b = {self.bending_s:g} s, "
                f"tau_t = {self.torsion_s:g} s")


#: its normalised groups (parameters/scene.py::GROUP_KEYS): retardation time / t_scale, Eq. 25
_T = ("helix.length_m", "environment.g_m_s2")  # t_scale = sqrt(L0/g)
GROUP_KEYS = {
    "tau_axial": ("tau_a/sqrt(L0/g)", "Eq. 25", ("damping.axial_s",), _T),
    "tau_bending": ("tau_b/sqrt(L0/g)", "Eq. 25", ("damping.bending_s",), _T),
    "tau_torsion": ("tau_t/sqrt(L0/g)", "Eq. 25", ("damping.torsion_s",), _T),
}


#: where the section lives in a scene: Parameters.model.damping (the file's [damping])
HOLDER, KEY, SECTION = "model", "damping", Damping

#: its fields of Normalised, off: the retardation times / t_scale (0: off), forms/damping.py
NORMALISED = {"tau_axial": 0.0, "tau_bending": 0.0, "tau_torsion": 0.0}


def normalise(p, scales: dict) -> dict:
    """The retardation times / t_scale (Eq. 25): Normalised's tau_axial, tau_bending,
    tau_torsion; ``scales`` the numpy L0, M, g, t_scale (parameters/normalised.py)."""
    section, t_scale = p.model.damping, scales["t_scale"]
    return {"tau_axial": section.axial_s / t_scale, "tau_bending": section.bending_s / t_scale,
            "tau_torsion": section.torsion_s / t_scale}


def check(params) -> None:
    """What the damping cannot run with (``params`` a whole scene): the spline scheme and
    the mixed bending form (forms/damping.py is written on the FE scheme's IP form)."""
    disc = params.discretisation
    if params.model.damping.active and (disc.continuum_scheme != "fe" or disc.bending != "ip"):
        raise ParameterError("damping", params.model.damping,
                             "structural damping is implemented by the FE scheme with "
                             "discretisation.bending = 'ip' only (forms/damping.py)")
