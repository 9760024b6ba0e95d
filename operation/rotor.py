"""The rotor at the top end: its table Cp(tsr), CT(tsr) and the torque and thrust
they give (issue 43).

With lambda = Omega R / V_n the tip-speed ratio (V_n the wind's component along the
rotor's axis):

    Q = 1/2 rho pi R^2 V_n^3 Cp(lambda) / Omega    [N m]   (aerodynamic torque)
    F = 1/2 rho pi R^2 V_n^2 CT(lambda)             [N]     (thrust along the axis)

Cp and CT are the monotone cubic interpolants of the table (interpolation.py: C1, so
dQ/dOmega is continuous; no overshoot, so the largest Cp is a row's).  A tip-speed
ratio outside the table is :class:`OutOfTable`, naming the wind and rotor speeds that
asked for it: never an extrapolation.
"""

from __future__ import annotations

import math
import numpy as np

from rawehelix.operation.interpolation import Pchip

BETZ = 16.0 / 27.0  # the largest Cp of an ideal rotor (Betz)
MIN_ROWS = 3  # the interpolant's end slopes take three rows
RPM = 2.0 * math.pi / 60.0  # rad/s per rpm
#: the rotor's axis -> V_n / V: "tangent", the helix's end tangent t (V_n = V |t . i_E|:
#: about V cos 45 deg at the paper's elevation); "wind", facing the wind (V_n = V)
NORMAL = {"tangent": lambda t: abs(float(t[0])), "wind": lambda t: 1.0}
AXES = tuple(NORMAL)
#: the rotor's axis -> its thrust's direction (x, y, z): None, along the helix's end
#: tangent (a follower force on a lifted top); "wind", along the wind (-i_E, downwind)
THRUST_ALONG = {"tangent": None, "wind": (-1.0, 0.0, 0.0)}
#: the share of a table's end ratio by which the spins searched stay inside it, so that
#: the round-off of Omega R / V_n does not step outside the table
ROUND_OFF = 1e-12


class OutOfTable(ValueError):
    """A tip-speed ratio outside the rotor's table: the wind and rotor speeds that
    asked for it."""

    def __init__(self, tsr: float, lo: float, hi: float, wind_m_s: float, omega_rad_s: float):
        self.tsr, self.lo, self.hi = tsr, lo, hi
        self.wind_m_s, self.rotor_rpm = wind_m_s, omega_rad_s / RPM
        super().__init__(
            f"the rotor's tip-speed ratio {tsr:.4g} at wind {wind_m_s:.4g} m/s and rotor speed "
            f"{self.rotor_rpm:.4g} rpm is outside its table [{lo:.4g}, {hi:.4g}]: extend "
            f"the rotor's table (rotor.table or rotor.tsr, cp, ct) or choose wind speeds "
            f"whose operating points it covers")


def table_fault(tsr, cp, ct) -> tuple[int, str, str] | None:
    """The first fault of a rotor table as (row, column, what), row 1-based (0: the table
    as a whole), or None: equal lengths, at least :data:`MIN_ROWS` rows, finite values,
    tsr strictly increasing and >= 0, 0 <= Cp <= 16/27 (Betz), CT >= 0."""
    if not len(tsr) == len(cp) == len(ct):
        return 0, "tsr", (f"tsr, cp and ct must have equal lengths (got {len(tsr)}, "
                          f"{len(cp)}, {len(ct)})")
    if len(tsr) < MIN_ROWS:
        return 0, "tsr", (f"has {len(tsr)} rows: at least {MIN_ROWS} are needed (the "
                          f"monotone cubic interpolant's end slopes)")
    for i, (x, p, t) in enumerate(zip(tsr, cp, ct), start=1):
        values = {"tsr": x, "cp": p, "ct": t}
        bad = [k for k, v in values.items() if not math.isfinite(v)]
        if bad:
            return i, bad[0], f"{bad[0]} = {values[bad[0]]!r} is not a finite number"
        if x < 0:
            return i, "tsr", f"tsr = {x!r} is negative"
        if i > 1 and not x > tsr[i - 2]:
            return i, "tsr", f"tsr = {x!r} does not increase: the table must be sorted in tsr"
        if p > BETZ:
            return i, "cp", f"cp = {p!r} is above the Betz limit 16/27 = {BETZ:.6f}"
        if p < 0:
            return i, "cp", f"cp = {p!r} is negative (a rotor that drives the air is not modelled)"
        if t < 0:
            return i, "ct", f"ct = {t!r} is negative"
    return None


class RotorLaw:
    """The rotor's aerodynamics from its table (module docstring), SI units.

    ``RotorLaw(tsr, cp, ct, radius_m, spin_inertia_kgm2, mass_kg, blades)``: the table's
    columns (tsr strictly increasing), R [m], J about its axis [kg m^2], the rotor and
    hub's mass [kg] and the blades (the nP lines).  The table is kept as
    :attr:`table_tsr`, :attr:`table_cp`, :attr:`table_ct` (numpy arrays); ``cp(tsr)``
    and ``ct(tsr)`` are its interpolants."""

    def __init__(self, tsr, cp, ct, radius_m: float, spin_inertia_kgm2: float = 0.0,
                 mass_kg: float = 0.0, blades: int = 3, axis: str = "tangent"):
        tsr, cp, ct = (tuple(float(v) for v in col) for col in (tsr, cp, ct))
        if axis not in AXES:
            raise ValueError(f"rotor axis {axis!r} must be one of {AXES}")
        fault = table_fault(tsr, cp, ct)
        if fault:
            row, _, what = fault
            raise ValueError(f"rotor table{f' row {row}' if row else ''}: {what}")
        for name, value in (("radius_m", radius_m), ("spin_inertia_kgm2", spin_inertia_kgm2),
                            ("mass_kg", mass_kg)):
            if not (value >= 0 and math.isfinite(value)) or (name == "radius_m" and value == 0):
                raise ValueError(f"rotor {name} = {value!r} must be a finite number "
                                 f"{'> 0' if name == 'radius_m' else '>= 0'}")
        self.table_tsr, self.table_cp, self.table_ct = (np.array(c) for c in (tsr, cp, ct))
        self.radius_m, self.spin_inertia_kgm2 = float(radius_m), float(spin_inertia_kgm2)
        self.mass_kg, self.blades, self.axis = float(mass_kg), int(blades), axis
        self._cp, self._ct = Pchip(tsr, cp), Pchip(tsr, ct)

    def __repr__(self):
        return (f"RotorLaw(R = {self.radius_m:g} m, {len(self.table_tsr)} rows, tsr "
                f"{self.tsr_range[0]:g}-{self.tsr_range[1]:g}, Cp_max {self.cp_max:.4g} at "
                f"tsr {self.tsr_opt:g})")

    # -- the table ---------------------------------------------------------------
    @property
    def area_m2(self) -> float:
        return math.pi * self.radius_m ** 2

    @property
    def cp_max(self) -> float:
        """The largest Cp: a row's (the interpolant has no overshoot)."""
        return float(np.max(self.table_cp))

    @property
    def tsr_opt(self) -> float:
        """The tip-speed ratio of :attr:`cp_max` (the first row that has it)."""
        return float(self.table_tsr[int(np.argmax(self.table_cp))])

    @property
    def tsr_range(self) -> tuple[float, float]:
        return float(self.table_tsr[0]), float(self.table_tsr[-1])

    def _inside(self, tsr, v_n=math.nan, omega=math.nan):
        lam = np.asarray(tsr, float)
        lo, hi = self.tsr_range
        outside = ~((lam >= lo) & (lam <= hi))
        if np.any(outside):
            k = int(np.argmax(outside.ravel()))
            raise OutOfTable(float(lam.ravel()[k]), lo, hi,
                             float(np.broadcast_to(v_n, lam.shape).ravel()[k]),
                             float(np.broadcast_to(omega, lam.shape).ravel()[k]))
        return lam

    def cp(self, tsr):
        """Cp(lambda), lambda inside the table (else :class:`OutOfTable`)."""
        return self._cp(self._inside(tsr))

    def ct(self, tsr):
        """CT(lambda), lambda inside the table (else :class:`OutOfTable`)."""
        return self._ct(self._inside(tsr))

    # -- at a wind and rotor speed -----------------------------------------------
    def inner_tsr(self) -> np.ndarray:
        """The table's tip-speed ratios with its two ends moved :data:`ROUND_OFF`
        inside: spins built on them (lambda V_n / R) give back ratios inside the table
        despite the round-off of Omega R / V_n."""
        lam = np.asarray(self.table_tsr, dtype=float)
        return np.clip(lam, lam[0] * (1 + ROUND_OFF), lam[-1] * (1 - ROUND_OFF))

    def tsr_of(self, omega, v_n):
        """lambda = Omega R / V_n [-] (Omega [rad/s], V_n [m/s] > 0)."""
        return np.asarray(omega, float) * self.radius_m / np.asarray(v_n, float)

    def _lam(self, omega, v_n):
        return self._inside(self.tsr_of(omega, v_n), v_n, omega)

    def torque(self, omega, v_n, rho):
        """Q = 1/2 rho pi R^2 V_n^3 Cp(lambda) / Omega [N m]; written as
        1/2 rho pi R^3 V_n^2 Cp(lambda) / lambda (the same at Omega > 0)."""
        lam = self._lam(omega, v_n)
        return 0.5 * rho * self.area_m2 * np.asarray(v_n, float) ** 3 * self._cp(lam) / omega

    def thrust(self, omega, v_n, rho):
        """F = 1/2 rho pi R^2 V_n^2 CT(lambda) [N], along the rotor's axis."""
        lam = self._lam(omega, v_n)
        return 0.5 * rho * self.area_m2 * np.asarray(v_n, float) ** 2 * self._ct(lam)

    def power(self, omega, v_n, rho):
        """Q Omega = 1/2 rho pi R^2 V_n^3 Cp(lambda) [W]."""
        lam = self._lam(omega, v_n)
        return 0.5 * rho * self.area_m2 * np.asarray(v_n, float) ** 3 * self._cp(lam)

    def thrust_direction(self):
        """The thrust's unit vector (x, y, z), or None where it follows the helix's end
        tangent (:data:`THRUST_ALONG`)."""
        return THRUST_ALONG[self.axis]

    def normal_speed(self, v_hub, tangent=None):
        """V_n [m/s]: the wind's component along the rotor's axis, the wind V_hub along
        -i_E; ``tangent`` the helix's unit end tangent (x, y, z) for axis "tangent"."""
        return np.asarray(v_hub, float) * NORMAL[self.axis](tangent)

    def dtorque_domega(self, omega, v_n, rho):
        """dQ/dOmega at fixed V_n [N m s]: the rotor's aerodynamic damping is its
        negative.  Q = A Cp(lambda) / Omega with A = 1/2 rho pi R^2 V_n^3 and
        dlambda/dOmega = R / V_n."""
        lam = self._lam(omega, v_n)
        a = 0.5 * rho * self.area_m2 * np.asarray(v_n, float) ** 3
        omega = np.asarray(omega, float)
        return a * (self._cp.derivative(lam) * self.radius_m / np.asarray(v_n, float) / omega
                    - self._cp(lam) / omega ** 2)


def from_params(params) -> RotorLaw | None:
    """The rotor of a scene (its ``[rotor]``), or None when it has none."""
    r = params.rotor
    if not r.active:
        return None
    return RotorLaw(tsr=r.tsr, cp=r.cp, ct=r.ct, radius_m=r.radius_m,
                    spin_inertia_kgm2=r.spin_inertia_kgm2, mass_kg=r.mass_kg, blades=r.blades,
                    axis=r.axis)
