"""A state of the FE rod: what solvers take and return.

A :class:`RodState` holds the dof values of one discretisation (the mixed
(r, alpha) space of :class:`~rawehelix.solvers.discrete.RodDiscretisation`),
normalised (Eqs. 25-29), as this rank's local arrays including ghosts: the
position ``w`` and, for dynamics, the velocity ``w_t``, at the normalised
time ``t``.  It can be copied and restored, because shooting, continuation
and studies restart the same solver many times.  It is tied to the scene's
discretisation and to the communicator it was made on (same partition);
``dofs`` guards against handing it to another discretisation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class RodState:
    w: np.ndarray  # (r, alpha) dofs, this rank's local values with ghosts (normalised)
    w_t: np.ndarray | None = None  # velocity dofs (None: at rest)
    t: float = 0.0  # normalised time, Eq. (25)
    dofs: int = 0  # global number of dofs of the discretisation it belongs to
    offset: float | None = None  # C of the controller, Eq. (40) integrated (None: not started)

    def copy(self) -> "RodState":
        return RodState(self.w.copy(), None if self.w_t is None else self.w_t.copy(),
                        self.t, self.dofs, self.offset)

    def arrays(self) -> dict:
        """Plain arrays (for a file of the caller's): see :meth:`from_arrays`."""
        out = {"w": self.w, "t": np.float64(self.t), "dofs": np.int64(self.dofs)}
        if self.w_t is not None:
            out["w_t"] = self.w_t
        if self.offset is not None:
            out["offset"] = np.float64(self.offset)
        return out

    @classmethod
    def from_arrays(cls, data) -> "RodState":
        """The state of :meth:`arrays` (a dict or an open .npz)."""
        keys = set(data.keys())
        return cls(np.asarray(data["w"]).copy(),
                   np.asarray(data["w_t"]).copy() if "w_t" in keys else None,
                   float(data["t"]), int(data["dofs"]),
                   float(data["offset"]) if "offset" in keys else None)

    def check(self, dofs: int, size: int, what: str = "solver"):
        """Refuse a state of another discretisation."""
        if self.dofs != dofs or self.w.size != size:
            raise ValueError(f"{what}: the state has {self.dofs} dofs ({self.w.size} local), "
                             f"the discretisation {dofs} ({size} local): a state belongs to "
                             f"the scene, discretisation and communicator it was made on")
