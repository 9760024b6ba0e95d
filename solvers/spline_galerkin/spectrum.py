"""Linear stability of a stationary state: eigenvalues of df/dx and mode families.

The Jacobian of f = M^-1 g (Eq. 61) is taken by complex step
(:meth:`SplineGalerkin.jacobian`): g is analytic in x away from r' = 0 and
v_A = 0, so df/dx = Im f(x + i h e_k) / h is exact to rounding with h = 1e-30,
with no step-size trade-off.

Families come from the kinetic-energy fractions of the eigenvector's position
part q (for lambda != 0 the velocity part is lambda q, with the same fractions):

* centre line, with the consistent mass P0 (Eq. 50): displacement along the
  chord (``longitudinal``), normal to it in the x-z plane (``lateral_in_plane``),
  along y (``lateral_out_of_plane``);
* twist, (beta/delta) alpha^H Q0 alpha (Eq. 53): ``torsional``.  beta/delta is
  the rotational inertia per unit length 2 rho I / (rho A L0^2) of Eq. (27).

|lambda| < ``zero_tol`` is ``rigid``: the free rigid rotation alpha_j = const
(and its Jordan partner, uniform spin) and the controller state m0 when k1 = k2 = 0.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .system import SplineGalerkin

FAMILIES = ("longitudinal", "lateral_in_plane", "lateral_out_of_plane", "torsional", "rigid")


@dataclass
class Mode:
    eigenvalue: complex  # normalised; one of each conjugate pair (Im >= 0)
    family: str
    fractions: dict  # energy fraction per family (without "rigid")
    dominant: list  # names of the state components with |v_k| >= 0.5 max |v|


def jacobian(system: SplineGalerkin, x: np.ndarray, t: float = 0.0) -> np.ndarray:
    """df/dx of Eq. (61) at (x, t) by complex step."""
    return system.jacobian(x, t)


def energy_fractions(system: SplineGalerkin, x: np.ndarray, v: np.ndarray) -> dict:
    """Kinetic-energy fractions of the position part of eigenvector v."""
    nd, mat = system.nd, system.mat
    top = system.nodes(system.split(x)[0], 0.0)[-1].real
    e_c = top / np.linalg.norm(top)  # chord
    j_E = np.array([0.0, 1.0, 0.0])
    n_c = np.cross(j_E, e_c)  # in-plane normal to the chord
    d = v[:system.n_r].reshape(-1, 3)
    alpha = v[system.n_r:system.n_q]

    def quad(P, a):
        return float(np.real(np.conj(a) @ P @ a))

    E = {
        "longitudinal": quad(mat.P0, d @ e_c),
        "lateral_in_plane": quad(mat.P0, d @ n_c),
        "lateral_out_of_plane": quad(mat.P0, d @ j_E),
        "torsional": nd.beta / nd.delta * quad(mat.Q0, alpha),
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
