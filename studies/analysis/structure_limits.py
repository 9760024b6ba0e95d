"""The structure's limits in a result: the ``limits`` block of every summary.json
(issue 29).  The numerical limits of a discretisation are studies/limits.py's.

A :class:`Tracker` takes the section's state along s at each time it is given
(:meth:`Tracker.add`: SI arrays of the axial force N, the bending moment M, the
torque Q, the twist tau and, for a member law, the strains eps and kappa) and keeps
the extremes and the first limit reached; :meth:`Tracker.block` is the block:

* ``min_member_force_N``, ``max_member_force_N``: value, with where (s) and when (t);
* ``slack_fraction_max``: the largest fraction of slack members in a section;
* ``moment_ratio_max``: the largest |M| / (N R) (None where N <= 0 carries a moment:
  ``moment_without_tension`` then says where);
* ``twist_per_length_max``: the largest |tau| [rad/m];
* ``first_limit``: the first criterion reached (members.py::CRITERIA), its kind, s and
  t, or None; ``criteria`` gives each criterion's threshold, None where a scene key
  leaves it off (section.breaking_force_N, section.ring_spacing_m or section.rings);
* ``first_by_kind``: each criterion's own first (:func:`first_of_kind`: the earliest
  t, then the smallest s), None where not reached: a criterion met from the start
  (the twist of a collapse already at the stationary state) does not hide another
  reached later (a member going slack).

The members' forces: with the solid section, the forces of a tensegrity of the
scene's ``[section]`` members carrying the solid's resultants (members.py::
Members.linear_forces: what a tensegrity would feel); with a member law, the members'
own forces at the rod's strains (Members.forces).
"""

from __future__ import annotations

import numpy as np

from rawehelix import section_laws
from rawehelix.members import CRITERIA, Members


#: what each criterion measures (a kind's first's ``quantity``): its name and unit
QUANTITIES = {"member_force_N": ("member force", "N"), "moment_ratio": ("|M| / (N R)", ""),
              "ring_twist_rad": ("twist between rings", "rad")}


def _at(value, s, t) -> dict:
    return {"value": float(value), "s_m": float(s), "t_s": None if t is None else float(t)}


class Tracker:
    """The extremes of the members' state over the sections and times it is given."""

    def __init__(self, members: Members, law: str = "solid", cone=None, ring: str = "worst"):
        self.members, self.law, self.cone = members, law, cone  # cone: the law's numpy resultants
        self.section_law = section_laws.get(law)  # what the law decides (section_laws.py)
        self.ring = ring  # the ring's phase: "worst" (psi = 0) or "turning" (the probe's psi)
        self._min = self._max = self._ratio = self._twist = None
        self._slack = 0.0
        self._no_tension = None
        self._first = None
        self._by_kind = dict.fromkeys(CRITERIA)
        self.history: list[tuple] = []  # (t [s], min, max member force [N]) per add()
        self.slack_history: list[bool] = []  # any member slack anywhere, per add()
        self.sampled_every_s = None  # set by a caller that adds every k-th output only

    def thresholds(self) -> dict:
        """Each criterion's threshold, None when off (members.py)."""
        m = self.members
        dcrit = m.critical_twist()
        return {"slack": "a member's strain <= 0 (solid: its force <= 0)",
                "breaking": m.breaking_N,
                "moment_saturation": m.saturation,
                "torsional_collapse": None if not np.isfinite(dcrit) else dcrit}

    def forces(self, N, M, Q, eps=None, kappa=None, tau=None, psi=0.0):
        """The members' forces (..., n) [N] and their slack mask (``psi`` the ring's phase
        of a turning ring, members.py)."""
        return self.section_law.member_forces(self.members, N, M, Q, eps, kappa, tau, psi)

    def law_resultants(self, N, M, eps, kappa, tau, psi=0.0):
        """(N, M) of the section law: the members' or the cone's own resultants at the
        strains (the model's tension and bending-moment observables are the solid's,
        sigma eps and EI kappa); the solid's given N and M otherwise."""
        return self.section_law.resultants(self.members, self.cone, N, M, eps, kappa, tau, psi)

    def moment_ratio(self, N, M):
        """|M| / (N R) per section (0 where N <= 0) and the mask of N > 0."""
        tension = N > 0
        return np.where(tension, np.abs(M) / np.where(tension, N * self.members.R, 1.0), 0.0), tension

    def profile(self, N, M, Q, tau, eps=None, kappa=None, psi=0.0) -> dict:
        """Along s, one time: ``member_force_min_N``, ``member_force_max_N`` and
        ``moment_ratio`` per section (the fields of simulate's frames)."""
        N, M, Q, tau = (np.asarray(x, dtype=float) for x in (N, M, Q, tau))
        kappa = np.abs(kappa) if kappa is not None else None
        N, M = self.law_resultants(N, M, eps, kappa, tau, psi)
        f, _ = self.forces(N, M, Q, eps, kappa, tau, psi)
        return {"member_force_min_N": f.min(axis=-1), "member_force_max_N": f.max(axis=-1),
                "moment_ratio": self.moment_ratio(N, M)[0]}

    def add(self, s_m, N, M, Q, tau, t_s=None, eps=None, kappa=None, psi=0.0):
        """The sections at ``s_m`` (ns,) at the time ``t_s`` (None: a stationary
        state): N [N], M [N m] (magnitude), Q [N m], tau [rad/m] of shape (ns,); eps and
        kappa [1/m] for a member law, psi [rad] the ring's phase (a turning ring).  Each time's smallest and largest member force
        is kept in :attr:`history` (t, min, max)."""
        s_m, N, M, Q, tau = (np.asarray(x, dtype=float) for x in (s_m, N, M, Q, tau))
        kappa = np.abs(kappa) if kappa is not None else None
        N, M = self.law_resultants(N, M, eps, kappa, tau, psi)
        f, slack = self.forces(N, M, Q, eps, kappa, tau, psi)
        self.history.append((np.nan if t_s is None else float(t_s), float(f.min()), float(f.max())))
        i = int(np.argmin(f.min(axis=-1)))
        if self._min is None or f[i].min() < self._min["value"]:
            self._min = _at(f[i].min(), s_m[i], t_s)
        i = int(np.argmax(f.max(axis=-1)))
        if self._max is None or f[i].max() > self._max["value"]:
            self._max = _at(f[i].max(), s_m[i], t_s)
        fraction = slack.mean(axis=-1)
        self.slack_history.append(bool((fraction > 0).any()))
        self._slack = max(self._slack, float(fraction.max()))
        ratio, tension = self.moment_ratio(N, M)
        i = int(np.argmax(ratio))
        if self._ratio is None or ratio[i] > self._ratio["value"]:
            self._ratio = _at(ratio[i], s_m[i], t_s)
        bad = ~tension & (np.abs(M) > 0)
        if bad.any() and self._no_tension is None:
            self._no_tension = _at(0.0, s_m[np.argmax(bad)], t_s)
        i = int(np.argmax(np.abs(tau)))
        if self._twist is None or abs(tau[i]) > self._twist["value"]:
            self._twist = _at(abs(tau[i]), s_m[i], t_s)
        reached = self._reached(f, fraction, ratio, bad, tau)
        if self._first is None:
            self._first = self._first_of(s_m, t_s, reached)
        psi = np.broadcast_to(np.asarray(psi, dtype=float), np.shape(s_m))
        for kind, mask in reached.items():
            if self._by_kind[kind] is None and mask.any():
                i = int(np.argmax(mask))  # the smallest s where it is met
                self._by_kind[kind] = {**_at(0.0, s_m[i], t_s),
                                       **self._where(kind, f[i], ratio[i], tau[i], psi[i])}

    def _reached(self, f, fraction, ratio, no_tension, tau) -> dict:
        """Each criterion's mask over the sections at one time (members.py)."""
        m = self.members
        return {"slack": fraction > 0,
                "breaking": (f.max(axis=-1) >= m.breaking_N) if m.breaking_N is not None
                else np.zeros_like(fraction, dtype=bool),
                "moment_saturation": (ratio >= m.saturation) | no_tension,
                "torsional_collapse": np.abs(m.ring_twist(tau)) >= m.critical_twist()}

    def _where(self, kind, f, ratio, tau, psi) -> dict:
        """What a criterion met at one section measures there: ``value`` of its
        ``quantity`` (:data:`QUANTITIES`) against its ``threshold``, and for a member's
        criterion which member: its index and its angle from the bending plane's inner
        side (members.py)."""
        m = self.members
        if kind in ("slack", "breaking"):
            j = int(np.argmin(f) if kind == "slack" else np.argmax(f))
            return {"value": float(f[j]), "quantity": "member_force_N",
                    "threshold": 0.0 if kind == "slack" else m.breaking_N, "member": j,
                    "member_angle_deg": float(np.degrees(m.phi[j] + psi) % 360.0)}
        if kind == "moment_saturation":
            return {"value": float(ratio) if ratio > 0 else None,  # None: a moment without tension
                    "quantity": "moment_ratio", "threshold": m.saturation}
        return {"value": float(abs(m.ring_twist(tau))), "quantity": "ring_twist_rad",
                "threshold": m.critical_twist()}

    @staticmethod
    def _first_of(s_m, t_s, reached):
        """The first criterion reached at this time (smallest s; CRITERIA's order on a tie)."""
        hits = [(float(s_m[np.argmax(mask)]), CRITERIA.index(kind), kind)
                for kind, mask in reached.items() if mask.any()]
        if not hits:
            return None
        s, _, kind = min(hits)
        return {"kind": kind, "s_m": s, "t_s": None if t_s is None else float(t_s)}

    def slack_time_fraction(self) -> float | None:
        """The fraction of the times added at which any member was slack anywhere
        (None: nothing added)."""
        return float(np.mean(self.slack_history)) if self.slack_history else None

    def block(self) -> dict:
        """The ``limits`` block (module docstring); None values where nothing was added."""
        m = self.members
        return {
            "law": self.law,
            "members": {"tethers": m.n, "radius_m": m.R, "lay_angle_deg": float(np.degrees(m.beta)),
                        "tether_EA_N": m.k, "self_stress_N": m.P0, "ring": self.ring},
            "min_member_force_N": self._min,
            "max_member_force_N": self._max,
            "slack_fraction_max": self._slack,
            "moment_ratio_max": self._ratio,
            "moment_without_tension": self._no_tension,
            "twist_per_length_max": self._twist,
            "first_limit": self._first,
            "first_by_kind": dict(self._by_kind),
            "criteria": self.thresholds(),
            "sampled_every_s": self.sampled_every_s,
        }


def si(q, section: dict) -> dict:
    """A section state along s in the model's normalised units (solvers/probes.py::
    SectionProbe.section: s, tension, twist, strain, curvature, bending_moment, torque,
    ring_phase)
    as :meth:`Tracker.add`'s SI arguments; ``q`` the scene's Normalised."""
    L0 = q.L0
    return {"s_m": q.length_m(section["s"]), "N": q.tension_N(section["tension"]),
            "M": section["bending_moment"] * q.force_scale * L0,
            "Q": q.torque_Nm(section["torque"]), "tau": section["twist"] / L0,
            "eps": section["strain"], "kappa": section["curvature"] / L0,
            "psi": section.get("ring_phase", 0.0)}


def add_normalised(tracker: Tracker, q, section: dict, t=None):
    """:meth:`Tracker.add` of a section state in normalised units (:func:`si`), ``t``
    normalised or None."""
    tracker.add(**si(q, section), t_s=None if t is None else float(q.time_s(t)))


def of_params(params) -> Tracker:
    """A tracker of a scene's ``[section]`` members and law."""
    section, helix = params.model.section, params.helix
    members = section.members(helix)
    cone = section_laws.get(section.law).limits_law(section, helix, members)
    return Tracker(members, section.law, cone, section.ring)


def line(block: dict | None) -> str:
    """The block as a report's last line ("\n  members ..."), "" without one."""
    if not block or not block.get("min_member_force_N"):
        return ""
    first, ratio = block["first_limit"], block["moment_ratio_max"]
    at = lambda x: f"s = {x['s_m']:.3f} m" + ("" if x["t_s"] is None else f", t = {x['t_s']:.4f} s")  # noqa: E731
    return (f"\n  members ({block['law']}): force {block['min_member_force_N']['value']:.1f} .. "
            f"{block['max_member_force_N']['value']:.1f} N; moment ratio |M|/(N R) max "
            f"{ratio['value']:.3f} at {at(ratio)}; first limit: "
            + (f"{first['kind']} at {at(first)}" if first else "none"))
