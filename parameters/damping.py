"""The scene's ``[damping]`` section: Kelvin-Voigt structural damping (forms/damping.py)."""

from __future__ import annotations

from dataclasses import dataclass

from rawehelix.parameters.checks import _non_negative


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
