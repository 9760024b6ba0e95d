"""The section's state along s over a sweep point's recorded periods (issue 29's
``limits`` block): a :class:`SectionSampler` rides on the FE backend's steps.

During a period it keeps a copy of the rod's dofs at the first step at or past each
output time (``sweep.samples_per_period`` a period: a copy, no evaluation); after the
point has settled, :meth:`SectionSampler.sections` evaluates
:meth:`~rawehelix.solvers.probes.Probes.section` at the kept states of the recorded
periods only, restoring the solver's own dofs bit for bit.  So tracking costs a
copy per output time while a point settles (measured in
docs/explanation/structure_limits.md) and changes no number of the sweep.  Between
two output times the extremes are not seen: at 64 samples a period the maximum of a
smooth periodic signal is missed by at most about (pi / 64)^2 / 2 = 0.12 % of its
oscillation.  Normalised units; studies/analysis/structure_limits.py turns them into SI.
"""

from __future__ import annotations

import numpy as np


class SectionSampler:
    """Copies of the rod's dofs at a period's output times, and the section state
    along s at them (on one rank's solver: the sweep's COMM_SELF)."""

    def __init__(self, solver):
        if not solver.form.second_order:
            raise ValueError("SectionSampler: needs the second-order form (the sweep's "
                             "alpha2), whose u holds the whole configuration")
        self.solver = solver
        self._times, self._next, self._kept = np.empty(0), 0, []

    def expect(self, t_out):
        """The output times (normalised) of the period about to be advanced."""
        self._times, self._next, self._kept = np.asarray(t_out, dtype=float), 0, []

    def __call__(self, solver):
        """The backend's step hook: keep the dofs at each output time passed."""
        t = solver.t
        while self._next < len(self._times) and t >= self._times[self._next] * (1 - 1e-12):
            self._kept.append((float(t), solver.form.u.x.array.copy()))
            self._next += 1

    def take(self) -> list:
        """The (t, dofs) kept over the last period, handed over and forgotten."""
        kept, self._kept = self._kept, []
        return kept

    def sections(self, kept: list) -> list:
        """[(t, Probes.section() dict)] at the kept states; the solver's dofs restored."""
        u = self.solver.form.u.x
        own = u.array.copy()
        out = []
        try:
            for t, dofs in kept:
                u.array[:] = dofs
                u.scatter_forward()
                out.append((t, self.solver.probes.section()))
        finally:
            u.array[:] = own
            u.scatter_forward()
        return out
