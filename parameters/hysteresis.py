"""The scene's ``[torsion_hysteresis]`` section: Bouc-Wen torsion (forms/hysteresis.py)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from rawehelix.parameters.checks import ParameterError, _positive


@dataclass(frozen=True)
class TorsionHysteresis:
    """Hysteretic torsion (forms/hysteresis.py): a Bouc-Wen internal twist z in the
    torsional moment.  A scene's ``[torsion_hysteresis]`` section; ``rho`` = 1 (the
    default) is the paper's elastic moment GJ tau (Eq. 65) and leaves z out.

        M = GJ (rho tau + (1 - rho) z),
        dz/dt = A dtau/dt - beta |dtau/dt| |z|^(n-1) z - gamma dtau/dt |z|^n

    (Bouc 1967 in Wen's 1976 form; tau and z in rad/m, t in s).  Its loop is bounded
    (|z| <= z_u = (A / (beta + gamma))^(1/n)) and dissipates (Wen's condition) when
    beta > 0 and -beta <= gamma <= beta."""

    rho: float = 1.0  # the elastic share of GJ, in (0, 1]; 1: off [-]
    A: float = 1.0  # the slope dz/dtau at z = 0: virgin tangent GJ (rho + (1 - rho) A) [-]
    beta_m_n: float = 0.0  # beta, units (m/rad)^n: the loop's width [(m/rad)^n]
    gamma_m_n: float = 0.0  # gamma, units (m/rad)^n: its shape (> 0 softens on loading) [(m/rad)^n]
    n: float = 1.0  # exponent: the sharpness of the yield, >= 1 [-]

    def __post_init__(self):
        if not (0 < self.rho <= 1):
            raise ParameterError("torsion_hysteresis.rho", self.rho, "must lie in (0, 1]")
        _positive("torsion_hysteresis", self, "A")
        if not (self.n >= 1 and math.isfinite(self.n)):
            raise ParameterError("torsion_hysteresis.n", self.n, "must be a finite number >= 1")
        for name in ("beta_m_n", "gamma_m_n"):
            if not math.isfinite(getattr(self, name)):
                raise ParameterError(f"torsion_hysteresis.{name}", getattr(self, name),
                                     "must be finite")
        if self.active and not (self.beta_m_n > 0 and abs(self.gamma_m_n) <= self.beta_m_n):
            raise ParameterError(
                "torsion_hysteresis.gamma_m_n", self.gamma_m_n,
                f"with torsion_hysteresis.rho = {self.rho!r} < 1 (hysteresis on) needs "
                f"beta_m_n = {self.beta_m_n!r} > 0 and -beta_m_n <= gamma_m_n <= beta_m_n "
                "(Wen 1976: a bounded, dissipative loop)")

    @property
    def active(self) -> bool:
        return self.rho < 1

    def describe(self) -> str:
        return (f"torsion hysteresis: Bouc-Wen rho = {self.rho:g}, A = {self.A:g}, "
                f"beta = {self.beta_m_n:g}, gamma = {self.gamma_m_n:g} (m/rad)^n, n = {self.n:g}")


#: its normalised groups (parameters/scene.py::GROUP_KEYS): tau~ = L0 tau, so beta~ = beta / L0^n
GROUP_KEYS = {
    "bw_beta": ("beta/L0^n", "Eq. 25", ("torsion_hysteresis.beta_m_n",),
                ("helix.length_m", "torsion_hysteresis.n")),
    "bw_gamma": ("gamma/L0^n", "Eq. 25", ("torsion_hysteresis.gamma_m_n",),
                 ("helix.length_m", "torsion_hysteresis.n")),
}


#: where the section lives in a scene: Parameters.model.torsion_hysteresis
HOLDER, KEY, SECTION = "model", "torsion_hysteresis", TorsionHysteresis

#: its fields of Normalised, off (forms/hysteresis.py): tau~ = tau L0 and z~ = z L0,
#: so beta~ = beta / L0^n and gamma~ = gamma / L0^n; rho = 1: off
NORMALISED = {"bw_rho": 1.0, "bw_A": 1.0, "bw_beta": 0.0, "bw_gamma": 0.0, "bw_n": 1.0}


def normalise(p, scales: dict) -> dict:
    """Normalised's bw_rho, bw_A, bw_beta, bw_gamma, bw_n (twist in units of 1/L0)."""
    section, L0 = p.model.torsion_hysteresis, scales["L0"]
    return {"bw_rho": section.rho, "bw_A": section.A, "bw_beta": section.beta_m_n / L0**section.n,
            "bw_gamma": section.gamma_m_n / L0**section.n, "bw_n": section.n}


def check(params) -> None:
    """What the hysteresis cannot run with (``params`` a whole scene): the spline
    scheme, the mixed bending form (its third field is z's place) and model.twist = false."""
    disc, section = params.discretisation, params.model.torsion_hysteresis
    if section.active and (disc.continuum_scheme != "fe" or disc.bending != "ip" or not params.model.twist):
        raise ParameterError("torsion_hysteresis", section,
                             "hysteretic torsion is implemented by the FE scheme with "
                             "discretisation.bending = 'ip' and model.twist = true only "
                             "(forms/hysteresis.py)")
