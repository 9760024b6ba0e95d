"""The network's potential energy, its gradient and its analytic sparse Hessian in the
chart of :mod:`.network` (each ring's dofs (dx, w): x <- x + dx, R <- exp([w]x) R).

A point p = R rho of a ring moves as a(w) = x + p + w x p + w x (w x p) / 2 + O(w^3),
so with g = dE/da:

    dE/dx = g,   dE/dw = p x g,
    d2E/d(x, w)^2 = G^T (d2E/da2) G + [[0, 0], [0, (g p^T + p g^T) / 2 - (g . p) I]],

G = [I, -[p]x].  A tether of rest length l_0 and chord d = a_(b+1) - a_b, L = |d|,
stores k (L - l_0)^2 / (2 l_0) when L > l_0 and nothing when slack; its force is
f = k (L - l_0) / l_0, dE/dd = f d/L, and d2E/dd2 = (k / l_0) d d^T / L^2 + (f / L)
(I - d d^T / L^2) (the elastic and the geometric stiffness).  A bar is the same
between centres, in compression too.  The loads are dead: -F . x, -M theta.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

DOFS = 6  # per ring: dx (3), w (3)


@dataclass
class State:
    """The rings' centres X (rings, 3) [m], rotations R (rings, 3, 3), and the top
    ring's accumulated turn theta about e3 [rad] (the end torque's work)."""

    X: np.ndarray
    R: np.ndarray
    theta: float = 0.0

    def copy(self) -> "State":
        return State(self.X.copy(), self.R.copy(), self.theta)


def _skew(p: np.ndarray) -> np.ndarray:
    """[p]x of (..., 3) as (..., 3, 3)."""
    out = np.zeros(p.shape + (3,))
    out[..., 0, 1], out[..., 0, 2] = -p[..., 2], p[..., 1]
    out[..., 1, 0], out[..., 1, 2] = p[..., 2], -p[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -p[..., 1], p[..., 0]
    return out


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a x b over the last axis (np.cross without its overhead)."""
    return np.stack([a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1],
                     a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
                     a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]], axis=-1)


def tether_chords(net, s: State):
    """(pa, pb, d): the attachment offsets R rho on the lower and upper ring of every
    bay and tether (bays, n, 3), and the chords d = x_(b+1) + pb - x_b - pa."""
    pa = np.einsum("bij,mj->bmi", s.R[:-1], net.attachments)
    pb = np.einsum("bij,mj->bmi", s.R[1:], net.attachments)
    return pa, pb, s.X[1:, None, :] + pb - s.X[:-1, None, :] - pa


def tether_forces(net, s: State) -> np.ndarray:
    """f (bays, n) [N]: k (L - l_0) / l_0 when taut, 0 when slack."""
    L = np.linalg.norm(tether_chords(net, s)[2], axis=-1)
    return net.k_N * np.maximum(L - net.l0_m, 0.0) / net.l0_m


def bar_forces(net, s: State) -> np.ndarray:
    """EA_b (L - l_b0) / l_b0 (bays,) [N], tension positive; zeros without bars."""
    if net.bar_EA_N <= 0:
        return np.zeros(net.count - 1)
    L = np.linalg.norm(s.X[1:] - s.X[:-1], axis=-1)
    return net.bar_EA_N * (L - net.bar_l0_m) / net.bar_l0_m


def energy(net, s: State) -> float:
    """The potential energy [J]: the tethers' and bars' strain energy less the loads' work."""
    L = np.linalg.norm(tether_chords(net, s)[2], axis=-1)
    stretch = np.maximum(L - net.l0_m, 0.0)
    E = net.k_N / (2 * net.l0_m) * float(np.sum(stretch * stretch))
    if net.bar_EA_N > 0:
        Lb = np.linalg.norm(s.X[1:] - s.X[:-1], axis=-1)
        E += net.bar_EA_N / (2 * net.bar_l0_m) * float(np.sum((Lb - net.bar_l0_m) ** 2))
    E -= float(np.sum(net.loads_N * s.X))
    if net.end_torque_Nm is not None:
        E -= net.end_torque_Nm * s.theta
    return E


def _line_terms(d: np.ndarray, EA: float, l0: float, tension_only: bool, hessian: bool = True):
    """(g = dE/dd (..., 3), H = d2E/dd2 (..., 3, 3), None without ``hessian``) of
    elastic lines of chords d."""
    L = np.linalg.norm(d, axis=-1)
    f = EA * (L - l0) / l0
    if tension_only:
        f = np.maximum(f, 0.0)
    u = d / L[..., None]
    if not hessian:
        return f[..., None] * u, None
    uu = u[..., :, None] * u[..., None, :]
    k_el = np.where(f > 0, EA / l0, 0.0) if tension_only else np.full(L.shape, EA / l0)
    H = k_el[..., None, None] * uu + (f / L)[..., None, None] * (np.eye(3) - uu)
    return f[..., None] * u, H


def _point_jacobian(p: np.ndarray) -> np.ndarray:
    """G = [I, -[p]x] (..., 3, 6): da/d(dx, w)."""
    eye = np.broadcast_to(np.eye(3), p.shape[:-1] + (3, 3))
    return np.concatenate([eye, -_skew(p)], axis=-1)


def _rotation_term(g: np.ndarray, p: np.ndarray) -> np.ndarray:
    """(g p^T + p g^T) / 2 - (g . p) I (..., 3, 3): the chart's second-order term."""
    gp = g[..., :, None] * p[..., None, :]
    return 0.5 * (gp + np.swapaxes(gp, -1, -2)) - np.einsum("...i,...i", g, p)[..., None, None] \
        * np.eye(3)


def _bay_terms(net, s: State, hessian: bool):
    """(dE/d(q_b, q_(b+1)) (bays, 12), its Hessian (bays, 12, 12) or None): each bay's
    tethers' and bar's share."""
    pa, pb, d = tether_chords(net, s)
    g, Hd = _line_terms(d, net.k_N, net.l0_m, tension_only=True, hessian=hessian)
    # G^T g with G = [I, -[p]x]: (g, p x g) on each end of a chord
    grad_e = np.concatenate([-g.sum(axis=1), -_cross(pa, g).sum(axis=1), g.sum(axis=1),
                             _cross(pb, g).sum(axis=1)], axis=-1)  # (bays, 12)
    K = None
    if hessian:
        Ga, Gb = _point_jacobian(pa), _point_jacobian(pb)
        G = np.concatenate([-Ga, Gb], axis=-1)  # dd/d(q_b, q_(b+1)) (bays, n, 3, 12)
        K = np.einsum("bmia,bmij,bmjc->bac", G, Hd, G)  # (bays, 12, 12)
        K[:, 3:6, 3:6] += _rotation_term(-g, pa).sum(axis=1)
        K[:, 9:12, 9:12] += _rotation_term(g, pb).sum(axis=1)
    if net.bar_EA_N > 0:
        gb, Hb = _line_terms(s.X[1:] - s.X[:-1], net.bar_EA_N, net.bar_l0_m,
                             tension_only=False, hessian=hessian)
        if hessian:
            for (i, si), (j, sj) in [((0, -1), (0, -1)), ((0, -1), (6, 1)), ((6, 1), (0, -1)),
                                     ((6, 1), (6, 1))]:
                K[:, i:i + 3, j:j + 3] += si * sj * Hb
        grad_e[:, 0:3] -= gb
        grad_e[:, 6:9] += gb
    return grad_e, K


def _assembled_gradient(net, s: State, grad_e: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(dE/dq (6 rings,), the bays' dof indices (bays, 12)) from the bays' shares,
    with the dead loads' and the end torque's work."""
    N = net.count
    grad = np.zeros(DOFS * N)
    idx = DOFS * np.arange(N - 1)[:, None] + np.arange(12)[None, :]  # (bays, 12)
    np.add.at(grad, idx, grad_e)
    grad[np.arange(DOFS * N).reshape(N, DOFS)[:, :3].ravel()] -= net.loads_N.ravel()
    if net.end_torque_Nm is not None:
        grad[DOFS * (N - 1) + 3:DOFS * N] -= net.end_torque_Nm * net.frame[:, 2]
    return grad, idx


def gradient(net, s: State) -> np.ndarray:
    """dE/dq (6 rings,) in the chart: minus each ring's force [N] and moment [N m]
    (the time integration's forces, without the Hessian's cost)."""
    return _assembled_gradient(net, s, _bay_terms(net, s, hessian=False)[0])[0]


def gradient_hessian(net, s: State) -> tuple[np.ndarray, sp.csr_matrix]:
    """(dE/dq (6 rings,), d2E/dq2 sparse (6 rings, 6 rings)) in the chart, every ring's
    dofs (dx, w) included (the ends' are removed by :func:`free_basis`)."""
    N = net.count
    grad_e, K = _bay_terms(net, s, hessian=True)
    grad, idx = _assembled_gradient(net, s, grad_e)
    rows = np.broadcast_to(idx[:, :, None], K.shape).ravel()
    cols = np.broadcast_to(idx[:, None, :], K.shape).ravel()
    H = sp.coo_matrix((K.ravel(), (rows, cols)), shape=(DOFS * N, DOFS * N)).tocsr()
    return grad, H


def free_basis(net) -> sp.csr_matrix:
    """P (6 rings, free): the free increments' embedding: every dof of the interior
    rings, and the top ring's turn about e3 when its torque is given (the ends are
    otherwise fixed, Eq. 66)."""
    N = net.count
    rows = list(range(DOFS, DOFS * (N - 1)))
    cols = list(range(len(rows)))
    vals = [1.0] * len(rows)
    if net.end_torque_Nm is not None:
        e3 = net.frame[:, 2]
        for i in range(3):
            rows.append(DOFS * (N - 1) + 3 + i)
            cols.append(DOFS * (N - 2))  # after the interior rings' dofs
            vals.append(e3[i])
    free = DOFS * (N - 2) + (net.end_torque_Nm is not None)
    return sp.csr_matrix((vals, (rows, cols)), shape=(DOFS * N, free))


def moved(net, s: State, dq: np.ndarray) -> State:
    """The state moved by the full increment dq (6 rings,): x + dx, exp([w]x) R, and
    the top's turn theta + w . e3."""
    from scipy.spatial.transform import Rotation
    q = dq.reshape(net.count, DOFS)
    R = Rotation.from_rotvec(q[:, 3:]).as_matrix() @ s.R
    return State(s.X + q[:, :3], R, s.theta + float(q[-1, 3:] @ net.frame[:, 2]))
