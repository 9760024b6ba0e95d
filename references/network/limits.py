"""The network's own ``limits`` block over a sweep point's recorded periods: the
members' extremes, the first slack tether (its time and place) and the moment ratio,
from the network's members, the quantities the continuum's block takes from its
section (studies/analysis/structure_limits.py).

The moment ratio of a bay is the continuum's |M| / (N R) with N and M the resultants
of the bay's own members about the bay's axis (the line of its ring centres, unit u,
middle c): N = sum_m f_m (e_m . u) + the bar's force, and M the part of
sum_m (a_m - c) x f_m e_m normal to u (a_m the tether's middle; the bar on the axis
carries none).  The continuum's N and M with a member law are the same sums over its
members at a section (members.py's resultants), so the two ratios are one quantity,
measured on each model's own members.  A ratio at or above the members' saturation
c = max(-cos phi_m) is the criterion ``moment_saturation``.
"""

from __future__ import annotations

import numpy as np

from rawehelix.references.network import energy as en

#: the criteria the network checks, in members.py's CRITERIA order; its torsional
#: collapse is a bay's own large turn (the dynamics), not a criterion on a twist
KINDS = ("slack", "breaking", "moment_saturation")


def bay_resultants(net, s: en.State) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(N (bays,) [N], |M| (bays,) [N m], f (bays, n) [N]): each bay's axial force and
    bending moment about its axis from its members (module docstring), and its tethers'
    forces."""
    pa, pb, d = en.tether_chords(net, s)
    f = en.tether_forces(net, s)
    e = d / np.linalg.norm(d, axis=-1)[..., None]
    u = s.X[1:] - s.X[:-1]
    u /= np.linalg.norm(u, axis=-1)[:, None]
    F = f[..., None] * e  # (bays, n, 3)
    N = np.einsum("bmi,bi->b", F, u) + en.bar_forces(net, s)
    M = en._cross(0.5 * (pa + pb), F).sum(axis=1)  # about c: a_m - c = (pa + pb) / 2
    M -= np.einsum("bi,bi->b", M, u)[:, None] * u
    return N, np.linalg.norm(M, axis=-1), f


class Record:
    """The network's members over the sampled times (SI): :meth:`add` each time,
    :meth:`block` the limits block (the keys of structure_limits.Tracker.block)."""

    def __init__(self, net, saturation: float, breaking_N: float | None):
        self.net, self.saturation, self.breaking_N = net, saturation, breaking_N
        l = net.spacing_m
        self.s_m = l * (np.arange(net.count - 1) + 0.5)  # each bay's middle, unstretched [m]
        self.samples = 0
        self._min = self._max = self._ratio = None
        self._slack = 0.0
        self._first = dict.fromkeys(("slack", "breaking", "moment_saturation", "torsional_collapse"))

    def add(self, t_s: float, s: en.State):
        N, M, f = bay_resultants(self.net, s)
        self.samples += 1
        b, m = np.unravel_index(int(np.argmin(f)), f.shape)
        if self._min is None or f[b, m] < self._min["value"]:
            self._min = self._at(f[b, m], b, t_s, tether=int(m))
        b, m = np.unravel_index(int(np.argmax(f)), f.shape)
        if self._max is None or f[b, m] > self._max["value"]:
            self._max = self._at(f[b, m], b, t_s, tether=int(m))
        slack = f <= 0
        self._slack = max(self._slack, float(slack.mean(axis=1).max()))
        tension = N > 0
        # 0 where N <= 0, as the continuum's (a moment without tension: the saturation)
        ratio = np.where(tension, M / (np.where(tension, N, 1.0) * self.net.radius_m), 0.0)
        b = int(np.argmax(ratio))
        if self._ratio is None or ratio[b] > self._ratio["value"]:
            self._ratio = self._at(ratio[b], b, t_s)
        reached = {"slack": slack.any(axis=1),
                   "breaking": (f.max(axis=1) >= self.breaking_N) if self.breaking_N
                   else np.zeros(len(N), dtype=bool),
                   "moment_saturation": (ratio >= self.saturation) | (~tension & (M > 0))}
        for kind, mask in reached.items():
            if self._first[kind] is None and mask.any():
                b = int(np.argmax(mask))  # the lowest bay where it is met
                j = int(np.argmin(f[b]) if kind == "slack" else np.argmax(f[b]))
                value = {"slack": f[b, j], "breaking": f[b, j], "moment_saturation": ratio[b]}[kind]
                self._first[kind] = self._at(value, b, t_s, tether=j, quantity=(
                    "moment_ratio" if kind == "moment_saturation" else "member_force_N"),
                    threshold={"slack": 0.0, "breaking": self.breaking_N,
                               "moment_saturation": self.saturation}[kind])

    def _at(self, value, bay, t_s, **more) -> dict:
        return {"value": float(value), "s_m": float(self.s_m[bay]), "t_s": float(t_s),
                "bay": int(bay), **more}

    def block(self) -> dict:
        firsts = [(x["t_s"], x["s_m"], kind) for kind, x in self._first.items() if x]
        first = min(firsts) if firsts else None
        net = self.net
        return {"status": "recorded", "samples": self.samples, "law": "network",
                "members": {"tethers": net.n, "radius_m": net.radius_m,
                            "lay_angle_deg": float(np.degrees(np.arctan(net.lay_rad * net.radius_m
                                                                        / net.spacing_m))),
                            "tether_EA_N": net.k_N, "rings": net.count},
                "min_member_force_N": self._min, "max_member_force_N": self._max,
                "slack_fraction_max": self._slack, "moment_ratio_max": self._ratio,
                "moment_without_tension": None, "twist_per_length_max": None,
                "first_limit": None if first is None else
                {"kind": first[2], "s_m": first[1], "t_s": first[0]},
                "first_by_kind": dict(self._first),
                "criteria": {"slack": "a tether's force <= 0", "breaking": self.breaking_N,
                             "moment_saturation": self.saturation,
                             "torsional_collapse": "the network's own (a bay turning over)"},
                "sampled_every_s": None}


class Sampler:
    """The sweep's section sampler for the network (solvers/periodic.py): the rings'
    configurations at a period's output times (:meth:`keep`), handed over per period
    (:meth:`take`), and the block over the recorded ones (:meth:`sections`)."""

    def __init__(self, net, saturation: float, breaking_N: float | None):
        self.net, self.saturation, self.breaking_N = net, saturation, breaking_N
        self._kept = []

    def expect(self):
        """A new period (or the lead-in's) begins: what was kept before is dropped."""
        self._kept = []

    def keep(self, t_s: float, s: en.State):
        self._kept.append((t_s, s.copy()))

    def take(self) -> list:
        kept, self._kept = self._kept, []
        return kept

    def sections(self, kept: list) -> Record:
        record = Record(self.net, self.saturation, self.breaking_N)
        for t_s, s in kept:
            record.add(t_s, s)
        return record
