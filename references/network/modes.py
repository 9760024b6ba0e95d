"""The network's modes about a stationary state: K q = omega^2 M q with K the energy's
Hessian in the free dofs (:mod:`.energy`: at a stationary state the chart's w are the
small rotations themselves) and M the lumped mass, m I for each ring's centre and its
inertia tensor R diag(Jd, Jd, Jp) R^T for its rotation (the kinetic energy
(m |x_t|^2 + omega . J omega) / 2); scipy.linalg.eigh, dense (6 (rings - 2) dofs).

Each mode's family is the group of dofs holding most of its kinetic energy, in the
chord's frame (e1 in the (x, z) plane, e2 = j_E, e3 along the chord): the centres
along e3 (longitudinal), along e1 (lateral in-plane) or e2 (lateral out-of-plane),
the rings' turn about e3 (torsional), or their tilt about e1 and e2 (the section's
rotation, families.ROTATION: the shear modes of a rod with rotary inertia).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from rawehelix.families import ROTATION
from rawehelix.references.network import energy as en

#: the kinetic-energy groups and their families (module docstring)
GROUPS = ("longitudinal", "lateral_in_plane", "lateral_out_of_plane", "torsional", ROTATION)
#: each group's dofs, in the chord's frame (a mode's dominant components)
DOFS_OF = {"longitudinal": "x_3", "lateral_in_plane": "x_1", "lateral_out_of_plane": "x_2",
           "torsional": "w_3", ROTATION: "w_1, w_2"}


@dataclass(frozen=True)
class Mode:
    frequency_Hz: float
    family: str
    fractions: dict  # the kinetic energy's share of each group of GROUPS
    shape: np.ndarray  # (rings, 6): every ring's (dx, w), M-normalised, ends 0


def matrices(result) -> tuple[np.ndarray, np.ndarray, sp.csr_matrix]:
    """(K, M, P): the stiffness [N/m, N, N m] and mass [kg, kg m^2] in the free dofs
    at the stationary ``result``, and the free dofs' embedding P."""
    net, s = result.network, result.state
    P = en.free_basis(net)
    H = en.gradient_hessian(net, s)[1]
    m, J = net.mass_matrix_blocks(s.R)
    blocks = [sla.block_diag(mi * np.eye(3), Ji) for mi, Ji in zip(m, J)]
    M = sp.block_diag(blocks, format="csr")
    return (P.T @ H @ P).toarray(), (P.T @ M @ P).toarray(), P


def _fractions(net, q: np.ndarray, m: np.ndarray, J: np.ndarray) -> dict:
    """The kinetic energy of each group of GROUPS for the full shape q (rings, 6)."""
    E = net.frame
    u, w = q[:, :3] @ E, q[:, 3:] @ E  # components in (e1, e2, e3)
    J_local = np.einsum("ia,rij,jb->rab", E, J, E)
    Jw = np.einsum("rab,rb->ra", J_local, w)
    parts = {"longitudinal": m @ u[:, 2] ** 2, "lateral_in_plane": m @ u[:, 0] ** 2,
             "lateral_out_of_plane": m @ u[:, 1] ** 2, "torsional": w[:, 2] @ Jw[:, 2],
             ROTATION: w[:, 0] @ Jw[:, 0] + w[:, 1] @ Jw[:, 1]}
    total = sum(parts.values()) or 1.0
    return {k: float(v / total) for k, v in parts.items()}


def modes(result, count: int | None = None) -> list[Mode]:
    """The lowest ``count`` modes (all: None), by frequency."""
    K, M, P = matrices(result)
    lam, V = sla.eigh(K, M)
    net = result.network
    m, J = net.mass_matrix_blocks(result.state.R)
    out = []
    for i in range(len(lam) if count is None else min(count, len(lam))):
        q = (P @ V[:, i]).reshape(net.count, en.DOFS)
        frac = _fractions(net, q, m, J)
        out.append(Mode(float(np.sqrt(max(lam[i], 0.0)) / (2 * np.pi)),
                        max(frac, key=frac.get), frac, q))
    return out


def lowest_of_each(found: list[Mode]) -> dict:
    """{family: the lowest frequency [Hz]} of the families present."""
    low: dict = {}
    for x in found:
        low.setdefault(x.family, x.frequency_Hz)
    return low
