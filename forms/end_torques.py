"""The operating machine's end torques in pure UFL: the rotor's aerodynamic torque at
the top and the generator's torque at the ground, as functions of the end's spin
alpha_t (normalised: torques by GJ / L0, spins by 1 / t_scale, Eqs. 25, 38-39).

    Q(Omega)   = 1/2 rho pi R^2 V_n^3 Cp(lambda) / Omega,  lambda = Omega R / V_n
    tau(Omega) = k Omega |Omega| (MPPT) + tau_c(Omega) (constant or tabulated),
                 P_rated / Omega where tau Omega > P_rated (the rated-power cap)

The tables are piecewise polynomials in UFL (:func:`piecewise_polynomial`): a chain
of ``ufl.conditional`` over the rows, each piece in Horner form, so that a
piecewise-linear table is numpy's ``interp`` to round-off and a cubic one is
scipy's ``PPoly``.  Past the table the end pieces extend (Newton may step there);
the solvers refuse such a state after each step (never a silent extrapolation).

No solver code: the numbers come from :mod:`rawehelix.solvers.end_torques`."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import ufl


@dataclass(frozen=True)
class PiecewisePolynomial:
    """sum_k coeffs[k, i] (x - breaks[i])^(m - 1 - k) on [breaks[i], breaks[i + 1]]
    (scipy's PPoly layout: coeffs has shape (m, len(breaks) - 1))."""

    breaks: tuple
    coeffs: tuple  # m rows of len(breaks) - 1

    def __post_init__(self):
        c = np.asarray(self.coeffs, dtype=float)
        if c.ndim != 2 or c.shape[1] != len(self.breaks) - 1 or len(self.breaks) < 2:
            raise ValueError(f"PiecewisePolynomial: {c.shape} coefficients for "
                             f"{len(self.breaks)} breaks")
        if np.any(np.diff(self.breaks) <= 0):
            raise ValueError("PiecewisePolynomial: the breaks must increase")

    @classmethod
    def linear(cls, xs, ys) -> "PiecewisePolynomial":
        """The piecewise-linear interpolant of (xs, ys): numpy's ``interp`` inside."""
        xs, ys = np.asarray(xs, float), np.asarray(ys, float)
        slope = (ys[1:] - ys[:-1]) / (xs[1:] - xs[:-1])
        return cls(tuple(xs), (tuple(slope), tuple(ys[:-1])))

    @classmethod
    def fit(cls, f, breaks, degree: int = 3) -> "PiecewisePolynomial":
        """The piecewise polynomial of ``degree`` through ``f`` (numpy, vectorised) at
        degree + 1 points of each interval between the ``breaks``: exactly ``f``, to
        round-off, where ``f`` is such a polynomial on each (a PCHIP table, a linear one)."""
        b = np.asarray(breaks, float)
        rows = []
        for lo, hi in zip(b[:-1], b[1:]):
            dx = np.linspace(0.0, hi - lo, degree + 1)
            rows.append(np.linalg.solve(np.vander(dx, degree + 1), f(lo + dx)))
        return cls(tuple(b), tuple(map(tuple, np.array(rows).T)))

    def scaled(self, x_scale: float, y_scale: float) -> "PiecewisePolynomial":
        """p'(x) = y_scale p(x / x_scale): the same law in other units."""
        m = len(self.coeffs)
        c = [tuple(y_scale * np.asarray(row) / x_scale ** (m - 1 - k))
             for k, row in enumerate(self.coeffs)]
        return PiecewisePolynomial(tuple(x_scale * np.asarray(self.breaks)), tuple(c))

    def _piece(self, i, x):
        dx = x - self.breaks[i]
        out = self.coeffs[0][i]
        for row in self.coeffs[1:]:  # Horner
            out = out * dx + row[i]
        return out

    def _chain(self, x, piece):
        b = self.breaks
        expr = piece(len(b) - 2)
        for i in reversed(range(len(b) - 2)):
            expr = ufl.conditional(ufl.lt(x, b[i + 1]), piece(i), expr)
        return expr

    def __call__(self, x):
        """The UFL expression at ``x`` (a UFL scalar)."""
        return self._chain(x, lambda i: self._piece(i, x))

    @property
    def through_origin(self) -> bool:
        """Its first piece starts at x = 0 with the value 0: p(x) / x is a polynomial there."""
        return self.breaks[0] == 0 and self.coeffs[-1][0] == 0

    def over_x(self, x):
        """p(x) / x in UFL: on a first piece through the origin the polynomial of one
        degree less (finite at x = 0: a rotor at rest), elsewhere the quotient."""
        if not self.through_origin:
            return self(x) / x

        def piece(i):
            if i:
                return self._piece(i, x) / x
            out = self.coeffs[0][0]
            for row in self.coeffs[1:-1]:  # Horner without the zero constant
                out = out * x + row[0]
            return out
        return self._chain(x, piece)


@dataclass(frozen=True)
class RotorTorque:
    """Q(omega) of the rotor, normalised: power_n Cp(lam_per_omega omega) / omega, written
    power_n lam_per_omega Cp(lambda) / lambda (finite at rest: PiecewisePolynomial.over_x);
    ``power_n`` = 1/2 rho pi R^2 V_n^3 t_scale / (GJ / L0), ``lam_per_omega`` =
    R / (V_n t_scale), each a number or a Constant (the wind may change)."""

    cp: PiecewisePolynomial  # Cp(lambda)
    power_n: Any
    lam_per_omega: Any
    ct: PiecewisePolynomial | None = None  # CT(lambda): the thrust's (None: not asked)
    # (GJ / L0) / (R M g): power_n lam_per_omega times it is 1/2 rho pi R^2 V_n^2 / (M g)
    thrust_scale: float = 0.0
    given_in_time = False  # a law of the spin: Eq. (40)'s feedforward cannot know it

    def __call__(self, omega, time=None):
        # Q = P Cp / Omega = P (R / V_n) Cp(lambda) / lambda: finite at rest through a
        # table from tsr 0 (Cq = Cp / lambda, the torque coefficient)
        return self.power_n * self.lam_per_omega * self.cp.over_x(self.lam_per_omega * omega)

    def thrust(self, omega):
        """F = 1/2 rho pi R^2 V_n^2 CT(lambda) [M g] at the spin ``omega``: the same two
        numbers as the torque (so a moving wind sets both)."""
        return (self.power_n * self.lam_per_omega * self.thrust_scale
                * self.ct(self.lam_per_omega * omega))


@dataclass(frozen=True)
class RampTorque:
    """A rotor whose torque is prescribed in time: the paper's ramp (69),
    m_N0 (1 - exp(-t / t0)), whatever its spin (normalised; t0 > 0)."""

    mN0: float
    t0: float
    given_in_time = True  # the paper's m_N(t): Eq. (40) feeds it forward

    def __post_init__(self):
        if not self.t0 > 0:
            raise ValueError(f"RampTorque: the rise time t0 = {self.t0!r} must be > 0")

    def __call__(self, omega, time):
        return self.mN0 * (1 - ufl.exp(-time / self.t0))  # (69)


@dataclass(frozen=True)
class GeneratorTorque:
    """tau(omega) of the generator, normalised: gain omega |omega| + the constant or the
    table's torque, capped at rated / omega (rated = P_rated t_scale / (GJ / L0);
    None: no cap)."""

    gain: float = 0.0  # k t_scale^-2 / (GJ / L0): MPPT
    constant: float = 0.0
    table: PiecewisePolynomial | None = None  # torque against omega
    rated: float | None = None
    engaged: Any = None  # 0..1, a start-up's release (a Constant); None: always on

    def __post_init__(self):
        if self.rated is not None and not self.rated > 0:
            raise ValueError(f"GeneratorTorque: the rated power {self.rated!r} must be > 0")

    def __call__(self, omega):
        tau = self.gain * omega * abs(omega) + self.constant
        if self.table is not None:
            tau = tau + self.table(omega)
        if self.rated is not None:  # hold the power above it
            tau = ufl.conditional(ufl.gt(tau * omega, self.rated), self.rated / omega, tau)
        return tau if self.engaged is None else self.engaged * tau


def lumped_inertia(j, alpha_tt):
    """The torque -J alpha_tt of a rigid body spinning with the end (normalised:
    j = J L0 / (GJ t_scale^2))."""
    return -j * alpha_tt
