"""The rigid shaft's operating points (issue 43): the rotor's torque Q(Omega, V_n) =
the generator's tau(Omega) (+ a loss(Omega)), every root in the table's range.

Without the helix's own spin-drag loss the twist moment is constant along s at a
relative equilibrium (Eq. 31 with no distributed torque), so these roots are the
helix's operating points exactly.  A root is ``stable`` when
d(Q - tau - loss)/dOmega < 0 there (a faster rotor meets a net braking torque).  The
paper's law (Eq. 40 with k1 > 0) holds Omega at its target: one point, stable when its
speed gain K2 exceeds dQ/dOmega - dloss/dOmega.  Stable here is the rigid shaft's: the
helix's torsional compliance adds a mode that only the linearisation about the helix's
relative equilibrium sees.

The roots are bracketed on a grid in Omega (:data:`SAMPLES` intervals between
adjacent table rows) and refined by bisection to :data:`XTOL` relative: a root of even
multiplicity (a tangency, no sign change) is not reported.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from rawehelix.operation.rotor import RPM

SAMPLES = 64  # grid intervals between two adjacent table rows
XTOL = 4e-16  # relative width of a bisected bracket (a few ulps)


@dataclass(frozen=True)
class OperatingPoint:
    """One root of Q = tau (+ loss) at a wind speed (SI)."""

    omega_rad_s: float  # Omega [rad/s]
    wind_m_s: float  # V_n, the wind along the rotor's axis [m/s]
    tsr: float  # Omega R / V_n [-]
    rotor_torque_Nm: float  # Q [N m]
    generator_torque_Nm: float  # tau [N m]
    thrust_N: float  # F [N]
    rotor_power_W: float  # Q Omega [W]
    power_W: float  # tau Omega, at the generator [W]
    slope_Nms: float  # d(Q - tau - loss)/dOmega [N m s]
    stable: bool

    @property
    def rotor_rpm(self) -> float:
        return self.omega_rad_s / RPM


def _bisect(f: Callable, a: float, b: float, fa: float) -> float:
    while b - a > XTOL * max(abs(a), abs(b)):
        m = 0.5 * (a + b)
        if m <= a or m >= b:
            break
        fm = f(m)
        if fm == 0:
            return m
        if (fm > 0) == (fa > 0):
            a, fa = m, fm
        else:
            b = m
    return 0.5 * (a + b)


def operating_points(rotor, generator, v, rho, loss=None) -> list[OperatingPoint]:
    """Every operating point at the wind ``v`` [m/s] along the rotor's axis (V_n) and air
    density ``rho`` [kg/m^3], in increasing Omega; ``generator`` None: no ground torque;
    ``loss``: an object with ``torque(omega)`` and ``dtorque_domega(omega)`` [N m] (the
    helix's spin drag), or None."""
    v = float(v)
    if not v > 0:
        raise ValueError(f"the wind along the rotor's axis must be > 0 m/s, got {v!r}")
    if generator is not None and generator.holds_speed is not None:
        omegas = [generator.holds_speed]
    else:  # the table's rows, its ends a hair inside (round-off in Omega R / V_n)
        rows = rotor.inner_tsr()
        rows = np.unique(np.maximum(rows, 1e-12 * rows[-1]))  # Q = A Cp / Omega: Omega > 0
        omegas = _roots(lambda w: _net(rotor, generator, loss, w, v, rho),
                        rows * v / rotor.radius_m)
    return [_point(rotor, generator, loss, w, v, rho) for w in omegas]


def _net(rotor, generator, loss, omega, v, rho):
    """Q - tau - loss [N m]."""
    out = rotor.torque(omega, v, rho)
    if generator is not None:
        out = out - generator.torque(omega)
    if loss is not None:
        out = out - loss.torque(omega)
    return out


def _roots(f: Callable, rows: np.ndarray) -> list[float]:
    grid = np.unique(np.concatenate([np.linspace(a, b, SAMPLES + 1)
                                     for a, b in zip(rows[:-1], rows[1:])]))
    grid = np.clip(grid, rows[0], rows[-1])
    values = np.asarray(f(grid), float)
    roots = []
    for i in range(len(grid) - 1):
        a, b, fa, fb = grid[i], grid[i + 1], values[i], values[i + 1]
        if fa == 0:
            roots.append(float(a))
        elif fa * fb < 0:
            roots.append(_bisect(lambda w: float(f(w)), float(a), float(b), float(fa)))
    if values[-1] == 0:
        roots.append(float(grid[-1]))
    return roots


def _point(rotor, generator, loss, omega, v, rho) -> OperatingPoint:
    Q = float(rotor.torque(omega, v, rho))
    dQ = float(rotor.dtorque_domega(omega, v, rho))
    dloss = 0.0 if loss is None else float(loss.dtorque_domega(omega))
    if generator is None:
        tau, slope = 0.0, dQ - dloss
    elif generator.holds_speed is not None:  # Eq. (40): tau balances Q; K2 damps
        tau, slope = Q - (0.0 if loss is None else float(loss.torque(omega))), dQ - dloss - generator.K2
    else:
        tau = float(generator.torque(omega))
        slope = dQ - float(generator.dtorque_domega(omega)) - dloss
    return OperatingPoint(omega_rad_s=float(omega), wind_m_s=v, tsr=float(rotor.tsr_of(omega, v)),
                          rotor_torque_Nm=Q, generator_torque_Nm=tau,
                          thrust_N=float(rotor.thrust(omega, v, rho)),
                          rotor_power_W=Q * float(omega), power_W=tau * float(omega),
                          slope_Nms=slope, stable=bool(slope < 0))
