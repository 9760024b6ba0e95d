"""Linear stability of a stationary state: eigenvalues of df/dx and mode families.

The Jacobian of f = M^-1 g (Eq. 61) is taken by complex step
(:meth:`SplineGalerkin.jacobian`): g is analytic in x away from r' = 0 and
v_A = 0, so df/dx = Im f(x + i h e_k) / h is exact to rounding with h = 1e-30,
with no step-size trade-off.

Families come from the kinetic-energy fractions of the eigenvector's position
part q (for lambda != 0 the velocity part is lambda q, with the same fractions):

* centre line: the kinetic energy int |u.e|^2 ds (the Gauss rule of the
  consistent mass P0, Eq. 50) of the displacement u(s) along the local tangent
  t(s) of the stationary centre line (``longitudinal``), along n = j_E x t
  (in the x-z plane, ``lateral_in_plane``) and along j_E
  (``lateral_out_of_plane``): the frame of the FE scheme (solvers.linearise);
* twist, (beta/delta) alpha^H Q0 alpha (Eq. 53): ``torsional``.  beta/delta is
  the rotational inertia per unit length 2 rho I / (rho A L0^2) of Eq. (27).

|lambda| < ``zero_tol`` is ``rigid``: the free rigid rotation alpha_j = const
(and its Jordan partner, uniform spin) and the controller state m0 when k1 = k2 = 0.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .system import SplineGalerkin


@dataclass
class Mode:
    eigenvalue: complex  # normalised; one of each conjugate pair (Im >= 0)
    family: str  # one of rawehelix.families.FAMILIES
    fractions: dict  # energy fraction per family (without "rigid")
    dominant: list  # names of the state components with |v_k| >= 0.5 max |v|


def jacobian(system: SplineGalerkin, x: np.ndarray, t: float = 0.0) -> np.ndarray:
    """df/dx of Eq. (61) at (x, t) by complex step."""
    return system.jacobian(x, t)


def energy_fractions(system: SplineGalerkin, x: np.ndarray, v: np.ndarray) -> dict:
    """Kinetic-energy fractions of the position part of eigenvector v, at the
    Gauss points (exact for P0 where the frame is constant)."""
    nd, mat, B = system.nd, system.mat, system.basis
    R = system.nodes(system.split(x)[0], 0.0).real
    t = B.D[1] @ R
    t /= np.linalg.norm(t, axis=1)[:, None]  # local tangent of the stationary state
    j_E = np.array([0.0, 1.0, 0.0])
    n = np.cross(j_E, t)
    n /= np.linalg.norm(n, axis=1)[:, None]  # in-plane normal
    u = B.D[0][:, 1:system.N] @ v[:system.n_r].reshape(-1, 3)  # displacement at the Gauss points
    alpha = v[system.n_r:system.n_q]

    def quad(a):
        return float(B.w @ np.abs(a)**2)

    E = {
        "longitudinal": quad(np.sum(u * t, axis=1)),
        "lateral_in_plane": quad(np.sum(u * n, axis=1)),
        "lateral_out_of_plane": quad(u @ j_E),
        "torsional": nd.beta / nd.delta * float(np.real(np.conj(alpha) @ mat.Q0 @ alpha)),
    }
    total = sum(E.values()) or 1.0
    return {k: e / total for k, e in E.items()}


def modes(system: SplineGalerkin, x: np.ndarray, t: float = 0.0,
          zero_tol: float = 1e-4) -> list[Mode]:
    """Eigenvalues of df/dx at x with family and dominant components.

    One entry per conjugate pair (Im > 0) and per real eigenvalue, sorted by
    decreasing |Im lambda| then decreasing |lambda| (the order of Table 3).
    """
    J = jacobian(system, x, t)
    lam, vecs = np.linalg.eig(J)
    names = system.names()
    out = []
    for k in np.argsort(-np.abs(lam.imag) - 1e-9 * np.abs(lam)):
        ev, v = lam[k], vecs[:, k]
        if ev.imag < 0 and abs(ev) >= zero_tol:
            continue  # the conjugate of an entry already kept
        if abs(ev) < zero_tol:
            ev = complex(ev.real, abs(ev.imag))
        frac = energy_fractions(system, x, v)
        family = "rigid" if abs(ev) < zero_tol else max(frac, key=frac.get)
        a = np.abs(v)
        dominant = [names[i] for i in np.flatnonzero(a >= 0.5 * a.max())]
        out.append(Mode(eigenvalue=complex(ev), family=family, fractions=frac,
                        dominant=dominant))
    return out
