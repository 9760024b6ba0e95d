"""The ``limits`` block's tracker (studies/analysis/structure_limits.py) on hand-made states
whose member forces follow from statics alone (a ring of n tethers carrying N and M:
f = N/n + 2 M cos(phi)/(n R) with phi from the bending plane's outer side)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rawehelix.members import Members
from rawehelix.studies.analysis.structure_limits import Tracker

R, N0 = 0.19, 76.0


def ring(**kw):
    return Members(n=6, R=R, beta=0.0, k=6000.0, **kw)


def test_pure_tension_loads_each_tether_equally():
    tr = Tracker(ring())
    s = np.linspace(0, 7.9, 5)
    tr.add(s, np.full(5, N0), np.zeros(5), np.zeros(5), np.zeros(5))
    b = tr.block()
    assert b["min_member_force_N"]["value"] == pytest.approx(N0 / 6)
    assert b["max_member_force_N"]["value"] == pytest.approx(N0 / 6)
    assert b["slack_fraction_max"] == 0 and b["first_limit"] is None
    assert b["moment_ratio_max"]["value"] == 0


def test_the_inner_tether_slackens_at_half_the_tension_limited_moment():
    """Statics: the member on the bending plane's inner side carries N/n - 2 M/(n R),
    zero at M = N R / 2; a 6-ring has one slack member of 6 just past it."""
    s = np.array([0.0, 1.0, 2.0])
    for ratio, slack in ((0.49, 0.0), (0.51, 1 / 6)):
        tr = Tracker(ring())
        M = np.array([0.0, ratio * N0 * R, 0.0])
        tr.add(s, np.full(3, N0), M, np.zeros(3), np.zeros(3), t_s=0.25)
        b = tr.block()
        f_inner = N0 / 6 - 2 * M[1] / (6 * R)
        assert b["min_member_force_N"]["value"] == pytest.approx(f_inner)
        assert b["max_member_force_N"]["value"] == pytest.approx(N0 / 6 + 2 * M[1] / (6 * R))
        assert b["min_member_force_N"]["s_m"] == 1.0
        assert b["slack_fraction_max"] == pytest.approx(slack)
        assert b["moment_ratio_max"]["value"] == pytest.approx(ratio)
        assert (b["first_limit"] is None) == (slack == 0)
    assert b["first_limit"] == {"kind": "slack", "s_m": 1.0, "t_s": 0.25}


def test_the_first_limit_is_the_earliest_and_stays():
    tr = Tracker(ring(breaking_N=20.0))
    s = np.array([0.0, 1.0])
    tr.add(s, np.full(2, N0), np.zeros(2), np.zeros(2), np.zeros(2), t_s=0.0)
    tr.add(s, np.array([N0, 150.0]), np.zeros(2), np.zeros(2), np.zeros(2), t_s=0.1)  # 25 N
    tr.add(s, np.full(2, N0), np.array([N0 * R, 0.0]), np.zeros(2), np.zeros(2), t_s=0.2)
    b = tr.block()
    assert b["first_limit"] == {"kind": "breaking", "s_m": 1.0, "t_s": 0.1}
    assert b["moment_ratio_max"] == {"value": pytest.approx(1.0), "s_m": 0.0, "t_s": 0.2}
    assert b["criteria"]["breaking"] == 20.0 and b["criteria"]["torsional_collapse"] is None


def test_torsional_collapse_past_tullochs_angle():
    m = ring(ring_spacing_m=0.5)
    dcrit = m.critical_twist()
    assert math.degrees(dcrit) == pytest.approx(102.25, abs=0.01)  # l_t = 0.5 m, R = 0.19 m
    tr = Tracker(m)
    s = np.array([0.0, 1.0])
    tau = np.array([0.0, 1.01 * dcrit / 0.5])
    tr.add(s, np.full(2, N0), np.zeros(2), np.zeros(2), 0.99 * tau, t_s=0.0)
    assert tr.block()["first_limit"] is None
    tr.add(s, np.full(2, N0), np.zeros(2), np.zeros(2), tau, t_s=1.0)
    b = tr.block()
    assert b["first_limit"] == {"kind": "torsional_collapse", "s_m": 1.0, "t_s": 1.0}
    assert b["twist_per_length_max"]["value"] == pytest.approx(tau[1])


def test_a_moment_without_tension_saturates():
    tr = Tracker(ring())
    tr.add(np.array([0.0, 1.0]), np.array([N0, -1.0]), np.array([0.0, 1.0]), np.zeros(2),
           np.zeros(2))
    b = tr.block()
    assert b["moment_without_tension"]["s_m"] == 1.0
    assert b["first_limit"]["kind"] == "slack"  # the tethers of a compressed section are slack
    # f = -1/6 - 2 cos(phi) / (6 R): slack at phi = 0, 60 and 300 degrees
    assert b["slack_fraction_max"] == pytest.approx(0.5)


def test_a_member_law_reads_the_strains():
    """With the tensegrity law the members' own strains decide: at the closed-form
    first-slack curvature the inner member is just taut, past it slack."""
    m = ring()
    eps = 0.002
    ks = m.first_slack_curvature(eps)
    for kappa, slack in ((0.99 * ks, 0.0), (1.01 * ks, 1 / 6)):
        tr = Tracker(m, "tensegrity")
        tr.add(np.array([0.0]), np.array([0.0]), np.array([0.0]), np.zeros(1), np.zeros(1),
               t_s=0.0, eps=np.array([eps]), kappa=np.array([kappa]))
        assert tr.block()["slack_fraction_max"] == pytest.approx(slack)


@pytest.mark.parametrize("law", ["tensegrity", "saturating"])
def test_a_member_law_reports_its_own_moment_ratio(law):
    """With a member law the ratio is that of the law's own resultants (not the
    solid's EI kappa passed in): a tension-only section's (N, M) lie in the cone
    |M| <= c N R (members.py), so the ratio stays <= c = 1 however large the
    curvature (for the 6-ring at a fixed strain it tends to 3/4: the members at 180
    and +-120 degrees all stretch), while the solid's moment would pass it many times."""
    from rawehelix.members import ConeSection
    m = ring()
    cone = ConeSection(EA=36400.0, EI=4381.0, R=R, c=m.saturation, width=0.0)
    tr = Tracker(m, law, cone)
    eps = np.full(50, 0.002)
    kappa = np.linspace(0.0, 1.0, 50)  # up to ~100 x the first slack curvature
    huge = 4381.0 * kappa  # the solid's EI kappa, passed as M
    tr.add(np.linspace(0, 7.9, 50), 36400.0 * eps, huge, np.zeros(50), np.zeros(50),
           t_s=0.0, eps=eps, kappa=kappa)
    b = tr.block()
    assert 0.5 < b["moment_ratio_max"]["value"] <= 1.0 + 1e-9
    assert b["slack_fraction_max"] > 0
