"""The tensegrity section's closed forms (members.py), each against a derivation of its
own: a tether as the chord between two rings in 3-D, Tulloch's (2021) TRPT torque, the
exact piecewise-linear law of an unlaid ring, finite differences of the energy; and
the fallback ConeSection (convex, saturating, solid when taut, and the cone that
holds the members' own resultants)."""

import math

import numpy as np
import pytest
from scipy.optimize import brentq, minimize_scalar

from rawehelix.members import ConeSection, Members, critical_twist

EA, R = 3.64e4, 0.19


def ring(n=6, beta=0.0, P0=0.0, EA_b=0.0, width=0.0):
    """Tethers whose taut EA (zero strain) is the helix's 3.64e4 N."""
    cb, sb = math.cos(beta), math.sin(beta)
    k = ((EA - EA_b) / n - P0 * cb * sb * sb) / cb**3
    return Members(n=n, R=R, beta=beta, k=k, P0=P0, EA_b=EA_b, width=width)


def chords(m: Members, eps, tau, h=1e-6):
    """(N, Q) of the tethers as straight chords between the rings at s = 0 and s = h of
    a straight rod (3-D vectors, not the module's formula): a tether runs from
    R (cos phi, sin phi, 0) to R (cos(phi + theta), sin(phi + theta), (1 + eps) h) with
    theta = h (tan(beta) / R + tau), unstretched length h / cos(beta)."""
    theta = h * (math.tan(m.beta) / m.R + tau)
    N = Q = 0.0
    for phi in m.phi:
        p0 = m.R * np.array([math.cos(phi), math.sin(phi), 0.0])
        p1 = np.array([m.R * math.cos(phi + theta), m.R * math.sin(phi + theta), (1 + eps) * h])
        d = p1 - p0
        length = np.linalg.norm(d)
        f = m.k * max(length * math.cos(m.beta) / h - 1 + m.e0, 0.0)
        N += f * d[2] / length
        Q += np.cross(p0, f * d / length)[2]
    return N + m.EA_b * (eps + m.e_b0), Q + m.Q_b0


# -- the moment-curvature curve ---------------------------------------------------------

def test_unlaid_ring_moment_is_piecewise_linear_with_slack_at_first_slack_curvature():
    """beta = 0: each tether's strain is exactly eps - R kappa cos(phi) (a fibre of the
    bent rod), so M = sum k <eps - R kappa cos phi> (-R cos phi): linear with slope
    sum k R^2 cos^2 phi (the members' second moment of area) until the inner member's
    strain reaches zero at kappa = eps / R, then softer."""
    m = ring()
    eps = 2e-3
    y = m.R * np.cos(m.phi)
    EI = float(np.sum(m.k * y * y))
    kappa_s = eps / m.R
    assert m.first_slack_curvature(eps) == pytest.approx(kappa_s, rel=1e-12)
    assert m.taut_moduli()["EI"] == pytest.approx(EI, rel=1e-12)
    for kappa in np.linspace(0, kappa_s, 7):
        direct = float(np.sum(m.k * np.maximum(eps - y * kappa, 0) * (-y)))
        assert m.resultants(eps, kappa)["M"] == pytest.approx(direct, rel=1e-12, abs=1e-9)
        assert m.resultants(eps, kappa)["M"] == pytest.approx(EI * kappa, rel=1e-12, abs=1e-9)
    past = 1.5 * kappa_s
    assert m.resultants(eps, past)["M"] < 0.99 * EI * past  # the inner member is slack
    assert m.strains(eps, past)[0] < 0 < m.strains(eps, 0.99 * kappa_s)[0]


@pytest.mark.parametrize("beta_deg", [0.0, 15.0])
def test_laid_ring_slackens_at_first_slack_curvature(beta_deg):
    """With a lay the curve is linear to first order (slope taut EI at kappa -> 0);
    the inner member's chord strain (3-D, :func:`chords` geometry in the bending
    plane) is zero at first_slack_curvature, and M's slope drops there."""
    m = ring(beta=math.radians(beta_deg))
    eps = 3e-3
    h = 1e-6
    slope = m.resultants(eps, h)["M"] / h
    assert slope == pytest.approx(m.taut_moduli()["EI"], rel=2e-2)  # eps, e0 shift it
    ks = m.first_slack_curvature(eps)
    # the inner tether, phi = 0, advances 1 + eps - R kappa axially and tan(beta) across
    a, b = 1 + eps - m.R * ks, math.tan(m.beta)
    assert math.hypot(a, b) * math.cos(m.beta) - 1 == pytest.approx(0, abs=1e-13)
    d = 1e-3 * ks
    before = (m.resultants(eps, ks - d)["M"] - m.resultants(eps, ks - 2 * d)["M"]) / d
    after = (m.resultants(eps, ks + 2 * d)["M"] - m.resultants(eps, ks + d)["M"]) / d
    assert after < before - 0.1 * m.k * m.R**2  # one member's share k R^2 leaves


@pytest.mark.parametrize("n", [6, 5])
def test_moment_tends_to_the_tension_limited_moment(n):
    """At a fixed axial force N (the lab's dead load) and growing curvature the moment
    tends to c N R, c = max(-cos phi) (1 for even n, cos(pi / n) for odd): all the
    tension ends on the outermost member(s), whatever the stiffness."""
    m = ring(n=n)
    N = 200.0
    c = 1.0 if n % 2 == 0 else math.cos(math.pi / n)
    assert m.saturation == pytest.approx(c, rel=1e-12)
    ratio = []
    for kappa in (1e-3, 0.1, 0.5, 1.0):  # R kappa <= 0.19: no fibre reverses (a > 0)
        eps = brentq(lambda e: m.resultants(e, kappa)["N"] - N, -m.R * kappa - 1e-2, 1e-2,
                     xtol=1e-16)
        ratio.append(m.resultants(eps, kappa)["M"] / (N * m.R))
    assert ratio == sorted(ratio) and ratio[0] < 0.5 * c
    assert ratio[-1] == pytest.approx(c, rel=1e-9)


# -- torsion, axial law ------------------------------------------------------------------

@pytest.mark.parametrize("beta_deg,P0", [(0.0, 0.0), (0.0, 300.0), (17.0, 0.0), (17.0, 300.0)])
def test_torque_twist_small_twist_is_the_closed_form(beta_deg, P0):
    """dQ/dtau at zero strain from the chords' 3-D geometry (a forward difference of
    torques: without self-stress the tethers are on the edge of slack there, and
    untwisting slackens a laid ring) equals taut_moduli's GJ: the lay's elastic part
    plus the tension's geometric part, N_t R^2 / (1 + eps) at beta = 0 (Tulloch's
    TRPT, tethers of length (1 + eps) l between rings l apart)."""
    m = ring(beta=math.radians(beta_deg), P0=P0, EA_b=1e4 if P0 else 0.0)
    d = 1e-6
    GJ = (chords(m, 0.0, d)[1] - chords(m, 0.0, 0.0)[1]) / d
    assert GJ == pytest.approx(m.taut_moduli()["GJ"], rel=1e-4, abs=1e-6)
    if beta_deg == 0:
        assert m.taut_moduli()["GJ"] == pytest.approx(m.n * P0 * m.R**2, rel=1e-12, abs=1e-12)
        eps = 4e-3  # a tension without self-stress: GJ = N_t R^2
        N_t = float(m.forces(eps, 0.0).sum())
        assert m.tangent(eps, 0.0, 0.0)["GJ"] == pytest.approx(N_t * m.R**2 / (1 + eps),
                                                               rel=1e-6)


@pytest.mark.parametrize("beta_deg", [0.0, 17.0])
def test_axial_law(beta_deg):
    """N(eps) at no twist, from the chords: taut EA at zero strain (the closed form),
    and zero once every tether is slack (the strain below -e0 without bars)."""
    m = ring(beta=math.radians(beta_deg))
    for eps in (-2e-3, -1e-4, 0.0, 1e-4, 5e-3):
        assert m.resultants(eps, 0.0)["N"] == pytest.approx(chords(m, eps, 0.0)[0], rel=1e-5,
                                                             abs=1e-6)
    d = 1e-7
    assert (m.resultants(d, 0.0)["N"] - m.resultants(0, 0.0)["N"]) / d == pytest.approx(
        m.taut_moduli()["EA"], rel=1e-4)
    assert m.resultants(-1e-4, 0.0)["N"] == 0.0 and m.forces(-1e-4, 0.0).max() == 0.0


def test_resultants_are_the_energy_gradient():
    """N, M, Q = dW/d(eps, kappa, tau): central differences of energy at random states,
    with a lay, self-stress, bars and the regularised law."""
    rng = np.random.default_rng(1)
    for width in (0.0, 1e-4):
        m = ring(beta=math.radians(12.0), P0=150.0, EA_b=8e3, width=width)
        for _ in range(20):
            x = np.array([rng.uniform(-2e-3, 6e-3), rng.uniform(0, 0.05), rng.uniform(-0.3, 0.3)])
            r = m.resultants(*x)
            for i, key in enumerate("NMQ"):
                h = np.zeros(3)
                h[i] = 1e-7
                grad = (m.energy(*(x + h)) - m.energy(*(x - h))) / 2e-7
                assert grad == pytest.approx(r[key], rel=1e-5, abs=1e-4 * (1 + abs(r[key])))


# -- Tulloch's critical twist -------------------------------------------------------------

def tulloch_torque_per_N(delta, R_, l_t):
    """Tulloch (2021): Q(delta) / N = R^2 sin(delta) / sqrt(l_t^2 - 2 R^2 (1 - cos delta))."""
    return R_ * R_ * math.sin(delta) / math.sqrt(l_t * l_t - 2 * R_ * R_ * (1 - math.cos(delta)))


@pytest.mark.parametrize("R_,l_t", [(0.4, 1.0), (0.19, 0.5), (1.0, 2.5)])
def test_critical_twist_is_the_torque_maximum(R_, l_t):
    """critical_twist (Eq. 4.34's closed form) = the argmax of Tulloch's torque, found
    numerically; his Fig. 5.25: R = 0.4 m, l_t = 1 m carries at most 0.2 N m per N."""
    best = minimize_scalar(lambda d: -tulloch_torque_per_N(d, R_, l_t), bounds=(0, math.pi),
                           method="bounded", options={"xatol": 1e-12})
    assert critical_twist(R_, l_t) == pytest.approx(best.x, rel=1e-6)
    if (R_, l_t) == (0.4, 1.0):
        assert -best.fun == pytest.approx(0.2, rel=1e-6)
    assert critical_twist(0.6, 1.0) == math.inf  # l_t < 2 R: no twist limit


# -- the regularisation ---------------------------------------------------------------------

def test_regularised_law_converges_at_second_order():
    """Away from a member's zero strain, <e>_w - <e>_0 ~ w^2 / (4 |e|): the resultants
    converge as w^2 (w halved: the error / 4), in the slack and the taut members alike."""
    eps, kappa, tau = 2e-3, 0.05, 0.05  # the inner members slack, the outer taut
    exact = ring(beta=math.radians(10.0)).resultants(eps, kappa, tau)
    e = ring(beta=math.radians(10.0)).strains(eps, kappa, tau)
    assert e.min() < -1e-3 and e.max() > 1e-3 and np.abs(e).min() > 5e-4
    errors = []
    for w in (1e-4, 5e-5, 2.5e-5):
        r = ring(beta=math.radians(10.0), width=w).resultants(eps, kappa, tau)
        errors.append(max(abs(r[k] - exact[k]) / (1 + abs(exact[k])) for k in "NMQ"))
    rates = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert errors[0] < 1e-2 and np.all(np.abs(rates - 2) < 0.05)


# -- the fallback: ConeSection ----------------------------------------------------------------

def hessian(law, eps, kappa, he=1e-9, hk=1e-7):
    r = [np.array([law.resultants(*x)[k] for k in "NM"], dtype=float)
         for x in ((eps + he, kappa), (eps - he, kappa), (eps, kappa + hk), (eps, kappa - hk))]
    H = np.column_stack([(r[0] - r[1]) / (2 * he), (r[2] - r[3]) / (2 * hk)])
    scale = np.diag([law.EA ** -0.5, law.EI ** -0.5])
    return scale @ (H + H.T) / 2 @ scale


@pytest.mark.parametrize("width", [0.0, 1e-4])
def test_cone_section_is_convex_and_its_resultants_are_its_gradient(width):
    law = ConeSection(EA=EA, EI=6000.0, R=R, c=1.0, width=width)
    rng = np.random.default_rng(2)
    for _ in range(300):
        eps, kappa = rng.uniform(-3e-3, 8e-3), rng.uniform(-0.3, 0.3)
        assert np.linalg.eigvalsh(hessian(law, eps, kappa)).min() > -1e-6
        r = law.resultants(eps, kappa)
        gN = (law.energy(eps + 1e-8, kappa) - law.energy(eps - 1e-8, kappa)) / 2e-8
        gM = (law.energy(eps, kappa + 1e-6) - law.energy(eps, kappa - 1e-6)) / 2e-6
        assert gN == pytest.approx(r["N"], rel=1e-5, abs=1e-4)
        assert gM == pytest.approx(r["M"], rel=1e-5, abs=1e-4)


def test_cone_section_is_the_solid_when_taut_and_saturates_at_cNR():
    """Inside the cone (EI |kappa| <= c R EA eps) the solid's W, N = EA eps, M = EI kappa;
    outside it M = c R N exactly; with eps + c R |kappa| <= 0 nothing; and at a fixed
    N and growing curvature M -> c N R."""
    law = ConeSection(EA=EA, EI=6000.0, R=R, c=0.8)
    eps = 4e-3
    edge = law.c * R * EA * eps / law.EI
    for kappa in (0.0, 0.3 * edge, -0.9 * edge):
        r = law.resultants(eps, kappa)
        assert r["N"] == pytest.approx(EA * eps, rel=1e-12)
        assert r["M"] == pytest.approx(law.EI * kappa, rel=1e-12, abs=1e-12)
        assert law.energy(eps, kappa) == pytest.approx(EA * eps**2 / 2 + law.EI * kappa**2 / 2,
                                                       rel=1e-12)
    for kappa in (1.1 * edge, 5 * edge, -3 * edge):
        r = law.resultants(eps, kappa)
        assert abs(r["M"]) == pytest.approx(law.c * R * r["N"], rel=1e-12)
        assert abs(r["M"]) < law.EI * abs(kappa)  # softer than the solid
    assert law.resultants(-1e-3, 1e-3)["N"] == 0.0 and law.energy(-1e-3, 1e-3) == 0.0
    N = 100.0
    for kappa in (1e-3, 1.0):  # the law's own N at the eps that carries N
        e = brentq(lambda x: law.resultants(x, kappa)["N"] - N, -1.0, 1.0, xtol=1e-16)
        ratio = law.resultants(e, kappa)["M"] / (law.c * R * N)
    assert ratio == pytest.approx(1.0, rel=1e-10)


def test_cone_section_regularisation_converges():
    exact = ConeSection(EA=EA, EI=6000.0, R=R, c=1.0)
    errors = []
    for w in (1e-4, 5e-5, 2.5e-5):
        law = ConeSection(EA=EA, EI=6000.0, R=R, c=1.0, width=w)
        errors.append(max(abs(law.resultants(e, k)["N"] - exact.resultants(e, k)["N"])
                          for e, k in ((4e-3, 0.01), (4e-3, 0.2), (2e-3, 0.0))))
    assert errors[0] < 1.0 and np.log2(errors[0] / errors[1]) == pytest.approx(2, abs=0.05)


@pytest.mark.parametrize("n,beta_deg,width", [(6, 0.0, 0.0), (5, 17.0, 0.0), (3, 30.0, 1e-4)])
def test_the_members_own_resultants_lie_in_the_cone(n, beta_deg, width):
    """Tension-only tethers (no bars) give |M| <= c R N at every state: why c comes
    from the member geometry.  And the bound is reached (the cone is the tightest)."""
    m = ring(n=n, beta=math.radians(beta_deg), width=width)
    rng = np.random.default_rng(3)
    x = np.column_stack([rng.uniform(-3e-3, 1e-2, 2000), rng.uniform(-0.5, 0.5, 2000),
                         rng.uniform(-0.5, 0.5, 2000)])
    r = m.resultants(x[:, 0], np.abs(x[:, 1]), x[:, 2])
    assert np.all(np.abs(r["M"]) <= m.saturation * m.R * r["N"] * (1 + 1e-12) + 1e-12)
    assert np.all(r["N"] >= 0)
    assert (np.abs(r["M"]) / (m.saturation * m.R * np.maximum(r["N"], 1e-300))).max() > 0.99


@pytest.mark.parametrize("beta_deg, P0", [(0.0, 0.0), (0.0, 632.6), (16.8, 0.0), (30.0, 50.0)])
def test_shear_stiffness_is_the_sheared_energy_curvature(beta_deg, P0):
    """GA = n cos(beta) [k sin^2 beta + f (1 + cos^2 beta)] / 2 (the shearable rod's GA from
    the members) against the second difference of the tethers' energy under a shear strain
    (Members.sheared_energy, which writes the tethers' lengths out), to 1e-6; at beta = 0 with
    no self-stress and tether force f it is n f, the tension: a ring of parallel tethers resists
    shear by its tension alone; and the lay's part is GJ_el / (2 R^2)."""
    m = Members(n=6, R=0.19, beta=math.radians(beta_deg), k=6000.0, P0=P0,
                EA_b=1e4 if P0 else 0.0)
    for f in (P0 + 30.0, P0 + 60.0):  # taut: at f = 0 half the tethers would go slack
        h = 1e-4
        numeric = (m.sheared_energy(h, f) - 2 * m.sheared_energy(0.0, f)
                   + m.sheared_energy(-h, f)) / h**2
        assert m.shear_stiffness(f) == pytest.approx(float(numeric), rel=1e-6)
    if beta_deg == 0:
        assert m.shear_stiffness(25.0) == pytest.approx(6 * 25.0)
    GJ_el = m.taut_moduli()["GJ"] - m.n * math.cos(m.beta) ** 3 * m.R**2 * m.P0
    assert m.shear_stiffness(0.0) == pytest.approx(GJ_el / (2 * m.R**2), rel=1e-12, abs=1e-9)
