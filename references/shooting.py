"""Independent reference for the stationary state with fixed ends: Sec. 5.1.

The planar ansatz r~(s~) = x i_E + z k_E, alpha = 0 turns the stationary form of
Eq. (30),

    mu r'''' = [(T - mu kappa^2) r']' + k_E + F_A,   T = sigma (|r'| - 1)   (29)-(33)

with F_A = -nu v_w0^2 i_E (drag on the full relative velocity v_A = v_w0 i_E,
Eq. 28; with a wind profile, [wind], -nu v(z)^2 i_E at each point's height) into the
first-order system (67)-(68) for the state

    y = (x, z, x_s, z_s, x_ss, z_ss, x_sss, z_sss).

It is solved by (multiple) shooting: the state at s~ = 0 is
(0, 0, x_s0, z_s0, 0, 0, x_sss0, z_sss0) (Eqs. 35, 37) and the conditions at
s~ = 1 are x, z = the top end of Eq. (66) and x_ss = z_ss = 0 (Eq. 37).

The axial mode of (67) grows like exp(sqrt(sigma/mu) s~) (exp(27) for the
scene of Table 2), so one shooting interval would need a Jacobian with a
condition number ~1e11.  The interval [0, 1] is therefore cut into segments of
length ~4 sqrt(mu/sigma); the unknowns are the four free values at s~ = 0 and
the full state at every interior breakpoint, the conditions are continuity at
the breakpoints and the four conditions at s~ = 1.  With one segment this is
the plain shooting of the paper.

With ``model.kinematics = "extensible"`` (forms/extensible.py) the rod is
Antman's extensible elastica instead; :func:`solve_extensible` shoots its
planar equilibrium (see there), with the tension-dependent bending stiffness
of ``helix.EI_law`` (EI = a T + b, Eq. 64) when the scene has one.

This module deliberately shares no code with the finite-element path: it uses
numpy, scipy and the (numpy-only) parameter module, nothing else.  Everything
is normalised as in Eqs. (25)-(29): lengths by L0, forces by M g.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import root

from rawehelix.parameters import Normalised
from rawehelix.references.drag import drag_factor
from rawehelix.references.budget import OverBudget, budget, watched

__all__ = ["OverBudget", "budget", "MAX_SEGMENTS", "ShootingSolution", "solve", "rhs", "load_vector", "default_segments",
           "ExtensibleSolution", "solve_extensible", "bending_law"]


def load_vector(normalised: Normalised) -> np.ndarray:
    """Distributed load (x, z) per unit normalised length: k_E + F_A.

    Gravity is +k_E (k_E points down, Eq. 30); the stationary drag is
    F_A = -nu v_w0^2 i_E (Eq. 28 with v_A = v_w0 i_E, since the wind is
    -v_w0 i_E and the rod is at rest).  Both are scaled by the model switches.
    """
    q = normalised
    return np.array([-q.drag * q.nu * q.v_w0**2, q.gravity])


def _bending_modulus(normalised: Normalised) -> float:
    mu = normalised.mu * normalised.bending
    if not mu > 0:
        raise ValueError("the shooting reference needs bending (mu > 0): "
                         "System (67) is singular for mu = 0")
    return mu


def rhs(normalised: Normalised):
    """The right-hand side of System (67)-(68) as f(s, y) for solve_ivp.

    ``y`` may be (8,) or (8, n) (vectorised evaluation)."""
    sigma = normalised.sigma
    mu = _bending_modulus(normalised)
    qx, qz = load_vector(normalised)
    profile = drag_factor(normalised)  # None: the uniform wind's drag qx everywhere

    def f(s, y):
        x_s, z_s, x_ss, z_ss, x_sss, z_sss = y[2:8]
        q_x = qx if profile is None else qx * profile(y[1])  # the drag at this height
        stretch = np.sqrt(x_s**2 + z_s**2)  # |r'|
        tension = sigma * (stretch - 1.0)  # T, Eq. (29)
        kappa2 = x_ss**2 + z_ss**2  # kappa^2, Eq. (34)
        # f_s = d/ds (T - mu kappa^2), Eq. (68)
        f_s = sigma / stretch * (x_s * x_ss + z_s * z_ss) - 2.0 * mu * (x_ss * x_sss + z_ss * z_sss)
        x_4 = (f_s * x_s + (tension - mu * kappa2) * x_ss + q_x) / mu  # (67), drag -nu v(z)^2
        z_4 = (f_s * z_s + (tension - mu * kappa2) * z_ss + qz) / mu  # (67), gravity +1
        return np.array([x_s, z_s, x_ss, z_ss, x_sss, z_sss, x_4, z_4])

    return f


#: the most segments a shooting is run with where it serves as a check or a first guess:
#: its cost grows faster than their square (hybr's finite-difference Jacobian): on
#: Table 2's helix 7 (EI = 12800 N m^2) take 2.5 s, 9 (8000) 9.6 s, 14 (3000) and 25
#: (1000) ran past 20 s
MAX_SEGMENTS = 10


def default_segments(normalised: Normalised) -> int:
    """Number of shooting segments: each no longer than 4 sqrt(mu/sigma), so the
    axial mode grows at most by e^4 over a segment."""
    k = math.sqrt(normalised.sigma / _bending_modulus(normalised))
    return max(1, math.ceil(k / 4.0))


def not_applicable(normalised: Normalised) -> str | None:
    """Why the planar shooting reference does not apply to a scene, or None."""
    top = normalised.top_position(0.0)  # Eq. (66)
    if abs(top[1]) > 0:
        return ("the scene is not planar (the upper end is off the x-z plane, y = "
                f"{top[1]:.3g} L0: the circle of Eq. (70), r1 > 0); the shooting "
                "reference needs y = 0")
    return None


def _top_conditions(normalised: Normalised) -> np.ndarray:
    why = not_applicable(normalised)
    if why:
        raise ValueError(f"the shooting reference is planar: {why}")
    top = normalised.top_position(0.0)  # Eq. (66)
    return np.array([top[0], top[2]])


@dataclass
class ShootingSolution:
    """Stationary centre line from shooting; all quantities normalised."""

    normalised: Normalised
    initial_state: np.ndarray  # the 8 values of y at s~ = 0
    boundary_residual: float  # max |mismatch| at s~ = 1 (and at the breakpoints)
    breakpoints: np.ndarray = field(repr=False, default=None)  # segment ends, [0, ..., 1]
    _dense: list = field(repr=False, default_factory=list)  # OdeSolution per segment

    def _state(self, s) -> np.ndarray:
        """y(s) of shape (8, n)."""
        s = np.atleast_1d(np.asarray(s, dtype=float))
        if np.any(s < -1e-12) or np.any(s > 1 + 1e-12):
            raise ValueError("s must lie in [0, 1]")
        seg = np.clip(np.searchsorted(self.breakpoints, s, side="right") - 1,
                      0, len(self._dense) - 1)
        y = np.empty((8, s.size))
        for k in np.unique(seg):
            sel = seg == k
            y[:, sel] = self._dense[k](s[sel])
        return y

    def derivatives(self, s, order: int) -> np.ndarray:
        """r~^(order)(s~) as (n, 3) with y = 0; order 0..4 (4 from Eq. 67)."""
        if order not in (0, 1, 2, 3, 4):
            raise ValueError("order must be 0, 1, 2, 3 or 4")
        y = self._state(s)
        if order == 4:
            xz = rhs(self.normalised)(0.0, y)[6:8]
        else:
            xz = y[2 * order:2 * order + 2]
        out = np.zeros((y.shape[1], 3))
        out[:, 0], out[:, 2] = xz[0], xz[1]
        return out

    def centre_line(self, s) -> np.ndarray:
        """Normalised positions [x, 0, z], shape (n, 3)."""
        return self.derivatives(s, 0)

    def tension(self, s) -> np.ndarray:
        """Normalised tension T~ = sigma (|r~'| - 1), Eq. (29); times M g gives N."""
        d1 = self.derivatives(s, 1)
        return self.normalised.sigma * (np.linalg.norm(d1, axis=1) - 1.0)


def _integrate(f, s0, s1, y0, rtol, atol, dense=False):
    f = watched(f)
    sol = solve_ivp(f, (s0, s1), y0, method="DOP853", rtol=rtol, atol=atol,
                    dense_output=dense)
    if not sol.success:
        raise RuntimeError(f"shooting: integration on [{s0}, {s1}] failed: {sol.message}")
    return sol


def solve(normalised: Normalised, rtol: float = 1e-11, atol: float = 1e-13,
          segments: int | None = None, tol: float = 1e-10) -> ShootingSolution:
    """Solve System (67)-(68) with the boundary conditions (35)-(37), (66).

    Parameters
    ----------
    normalised : Normalised
        The dimensionless groups; the top end comes from ``top_position()``.
    rtol, atol : float
        Tolerances of the DOP853 integration.
    segments : int, optional
        Number of shooting segments (1 = simple shooting as in the paper);
        by default :func:`default_segments`.
    tol : float
        Largest accepted boundary (and continuity) mismatch.

    Raises
    ------
    RuntimeError
        If the root finder does not meet the boundary conditions; the message
        gives the mismatch.
    """
    f = rhs(normalised)
    target = _top_conditions(normalised)
    m = default_segments(normalised) if segments is None else int(segments)
    if m < 1:
        raise ValueError("segments must be >= 1")
    nodes = np.linspace(0.0, 1.0, m + 1)

    # First guess: the straight chord, r' = (1 + eps0) * chord direction (Eq. 66).
    slope = target  # r(1) - r(0) with r(0) = 0: already (1 + eps0) times the direction
    def chord_state(s):
        return np.array([slope[0] * s, slope[1] * s, slope[0], slope[1], 0, 0, 0, 0], float)
    guess = [np.array([slope[0], slope[1], 0.0, 0.0])]
    guess += [chord_state(s) for s in nodes[1:-1]]
    u0 = np.concatenate(guess)

    def unpack(u):
        xs0, zs0, xsss0, zsss0 = u[:4]
        starts = [np.array([0.0, 0.0, xs0, zs0, 0.0, 0.0, xsss0, zsss0])]
        starts += list(u[4:].reshape(m - 1, 8))
        return starts

    last = {"mismatch": math.inf}

    def residual(u):
        starts = unpack(u)
        res = []
        for k in range(m):
            end = _integrate(f, nodes[k], nodes[k + 1], starts[k], rtol, atol).y[:, -1]
            if k < m - 1:
                res.append(end - starts[k + 1])  # continuity at the breakpoint
            else:
                res.append([end[0] - target[0], end[1] - target[1], end[4], end[5]])
        res = np.concatenate(res)
        last["mismatch"] = float(np.max(np.abs(res)))
        return res

    try:
        sol = root(residual, u0, method="hybr", options={"xtol": 1e-14})
    except RuntimeError as err:  # an iterate made the integration blow up
        raise RuntimeError(f"shooting did not converge: boundary mismatch "
                           f"{last['mismatch']:.3e} at the last complete iterate ({err}); "
                           f"try more segments") from None
    mismatch = float(np.max(np.abs(residual(sol.x))))
    if not np.isfinite(mismatch) or mismatch > tol:
        raise RuntimeError(
            f"shooting did not converge: boundary mismatch {mismatch:.3e} > {tol:.1e} "
            f"({sol.message})")
    starts = unpack(sol.x)
    dense = [_integrate(f, nodes[k], nodes[k + 1], starts[k], rtol, atol, dense=True).sol
             for k in range(m)]
    return ShootingSolution(normalised=normalised, initial_state=starts[0],
                            boundary_residual=mismatch, breakpoints=nodes, _dense=dense)


# -- extensible kinematics (model.kinematics = "extensible") -----------------------

@dataclass
class ExtensibleSolution:
    """Stationary centre line of the extensible elastica; all quantities normalised."""

    normalised: Normalised
    resultant0: np.ndarray  # N(0), the (x, z) force at s~ = 0
    boundary_residual: float
    _dense: object = field(repr=False, default=None)  # OdeSolution of (x, z, theta, kappa)

    def centre_line(self, s) -> np.ndarray:
        """Normalised positions [x, 0, z], shape (n, 3)."""
        y = self._dense(np.atleast_1d(np.asarray(s, dtype=float)))
        return np.column_stack([y[0], 0 * y[0], y[1]])

    def curvature(self, s) -> np.ndarray:
        """kappa = theta' (per unstretched length), normalised."""
        return self._dense(np.atleast_1d(np.asarray(s, dtype=float)))[3]

    def axial_force(self, s) -> np.ndarray:
        """N.t, the force along the tangent: the tension T plus the EI law's 1/2 mu' kappa^2."""
        s = np.atleast_1d(np.asarray(s, dtype=float))
        return resultant_in_frame(self.resultant0, load_vector(self.normalised), s,
                                  self._dense(s)[2])[2]

    def tension(self, s) -> np.ndarray:
        """T = sigma (|r'| - 1) = N.t - 1/2 mu' kappa^2, normalised (= N.t without the EI law)."""
        a, _ = bending_law(self.normalised)
        return self.axial_force(s) - 0.5 * a * self.normalised.sigma * self.curvature(s)**2


def resultant_in_frame(resultant0, load, s, theta):
    """(cos theta, sin theta, N.t, N.n) of the resultant N = N(0) - q s at s in the frame
    t = (cos theta, sin theta), n = (-sin theta, cos theta) of a planar rod."""
    c, sn = np.cos(theta), np.sin(theta)
    Nx, Nz = resultant0[0] - load[0] * s, resultant0[1] - load[1] * s
    return c, sn, Nx * c + Nz * sn, -Nx * sn + Nz * c


def bending_law(normalised: Normalised) -> tuple[float, float]:
    """(a, b) of the normalised bending modulus mu(T) = a T + b at the tension T:
    the EI law (helix.EI_law, a = a_SI / L0^2, b = b_SI / (M g L0^2)) or (0, mu)."""
    q = normalised
    mu = _bending_modulus(q)  # (raises without bending)
    if q.bending_law:
        return q.mu_per_tension, q.mu_at_zero_tension
    return 0.0, mu


def extensible_rhs(normalised: Normalised, resultant0):
    """The planar extensible elastica as f(s, y), y = (x, z, theta, kappa).

    With r' = lambda (cos theta, sin theta) = lambda t, eps = lambda - 1, the
    stored energy W = sigma/2 eps^2 + mu(eps)/2 kappa^2 per unstretched length
    (kappa = theta' = |t'|, forms/extensible.py), mu(eps) = a sigma eps + b
    (:func:`bending_law`; a = 0 and b = mu without the EI law) and the load q
    (:func:`load_vector`), the stationarity of int [W - q.r + N.(r' - lambda t)]
    in r, lambda and theta gives

        N' = -q                                   (so N = N(0) - q s)
        dW/d eps = sigma eps + a sigma kappa^2/2 = N.t   (the axial force)
        (mu kappa)' = -lambda N.n,  n = (-sin theta, cos theta)   (moment balance)

    The second is explicit in eps.  Written out with mu' = a sigma eps' and
    eps' = (N.t)'/sigma - a kappa kappa', (N.t)' = -q.t + kappa N.n, the third is

        kappa' (mu - a^2 sigma kappa^2) = -lambda N.n - a kappa (-q.t + kappa N.n),

    regular while W is convex (mu > a^2 sigma kappa^2).  The natural end
    conditions are the zero moment mu kappa = 0, i.e. kappa = 0, at s = 0, 1."""
    sigma = normalised.sigma
    a, b = bending_law(normalised)
    q = load_vector(normalised)
    N0 = np.asarray(resultant0, dtype=float)

    def f(s, y):
        theta, kappa = y[2], y[3]
        c, sn, Nt, Nn = resultant_in_frame(N0, q, s, theta)
        eps = Nt / sigma - 0.5 * a * kappa**2
        lam, mu = 1.0 + eps, a * sigma * eps + b
        qt = q[0] * c + q[1] * sn
        dkappa = (-lam * Nn - a * kappa * (-qt + kappa * Nn)) / (mu - a**2 * sigma * kappa**2)
        return np.array([lam * c, lam * sn, kappa, dkappa])

    return f


def solve_extensible(normalised: Normalised, rtol: float = 1e-11, atol: float = 1e-13,
                     tol: float = 1e-10) -> ExtensibleSolution:
    """Shoot the planar extensible elastica (:func:`extensible_rhs`, with the EI
    law if the scene has one) from s~ = 0, where r = 0 (35) and kappa = 0, for
    the unknowns (N(0), theta(0)), to r(1) = the top of Eq. (66) and kappa(1) =
    0.  One segment suffices: with the stretch algebraic there is no axial mode,
    and the bending boundary layers grow only like exp(sqrt(T/mu) s~) (e^2 for
    Table 2).

    Raises RuntimeError if the conditions at s~ = 1 are not met to ``tol``."""
    resultant0, mismatch, dense = shoot_planar_rod(normalised, extensible_rhs, "extensible",
                                                   rtol, atol, tol)
    return ExtensibleSolution(normalised=normalised, resultant0=resultant0,
                              boundary_residual=mismatch, _dense=dense)


def shoot_planar_rod(normalised: Normalised, rhs_of, name: str, rtol: float, atol: float,
                     tol: float):
    """Shoot a planar rod y = (x, z, theta, theta') with the right side ``rhs_of(q, N(0))``
    from s~ = 0, where r = 0 (35) and theta' = 0, for the unknowns (N(0), theta(0)), to
    r(1) = the top of Eq. (66) and theta'(1) = 0: (N(0), boundary mismatch, the dense
    solution).  Raises RuntimeError (naming the rod ``name``) past ``tol``."""
    q = normalised
    target = _top_conditions(q)
    chord = math.hypot(*target)
    t0 = target / chord
    u0 = np.array([*(q.sigma * (chord - 1) * t0 + 0.5 * load_vector(q)),
                   math.atan2(t0[1], t0[0])])

    def end_state(u, dense=False):
        f = rhs_of(q, u[:2])
        return _integrate(f, 0.0, 1.0, np.array([0.0, 0.0, u[2], 0.0]), rtol, atol, dense)

    def residual(u):
        y1 = end_state(u).y[:, -1]
        return np.array([y1[0] - target[0], y1[1] - target[1], y1[3]])

    sol = root(residual, u0, method="hybr", options={"xtol": 1e-14})
    mismatch = float(np.max(np.abs(residual(sol.x))))
    if not np.isfinite(mismatch) or mismatch > tol:
        raise RuntimeError(f"{name} shooting did not converge: boundary mismatch "
                           f"{mismatch:.3e} > {tol:.1e} ({sol.message})")
    return sol.x[:2], mismatch, end_state(sol.x, dense=True).sol
