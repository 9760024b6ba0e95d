"""The members carry the twist (``[section] torsion = "members"``, forms/section_law.py,
issue 29) against members.py (numpy, no UFL) and the twist equation's torque balance.

* the UFL torque Q = dW/d tau and the tau-dependent N, M equal members.py's at the
  same strains, taut and slack, to round-off; Q is UFL's derivative of W;
* a stationary state under an end torque m: the FE's twisting moment is m all along
  the rod (Eq. 31 has no distributed torque), and members.py's Q at the FE's strains
  is the FE's; the twist is the root of members.py's torque-twist curve;
* all taut, self-stressed, unlaid: the torsional modes are the solid's with the
  closed-form GJ = n R^2 P_t (the tethers' tension P_t), to the tension's variation
  along s;
* the refusals.
"""

import functools

import dolfinx
import numpy as np
import pytest
import ufl
from mpi4py import MPI
from scipy.optimize import brentq

from rawehelix.forms import section_law
from rawehelix.parameters import ParameterError
from rawehelix.solvers.modal import ModalSolver
from rawehelix.solvers.probes import SectionProbe
from rawehelix.solvers.stationary import StationarySolver
from rawehelix.studies import scene
from rawehelix.studies.analysis import structure_limits

N, P = 8, 3
#: self-stressed, unlaid: GJ = n R^2 P0 = 140 N m^2 (the helix's) at P0 = 646 N
STRESSED = {"law": "tensegrity", "torsion": "members", "self_stress_N": 646.0, "bar_EA_N": 2e4}
#: laid, the lab fit's GJ at 200 N (studies/analysis/labfit.py): its lay is held by a torque
LAID = {"law": "tensegrity", "torsion": "members", "lay_angle_deg": 16.8}


def table2(**changes):
    return scene.load("stationary_table2", elements=N, degree=P).replace(
        model={"kinematics": "extensible"}, **changes)


class PointLaw:
    """W, N, M, Q and UFL's dW/d tau of a section law at constant (eps, kappa, tau),
    assembled over the unit interval (each equals its integrand)."""

    def __init__(self, section):
        mesh = dolfinx.mesh.create_unit_interval(MPI.COMM_SELF, 1)
        self.c = [dolfinx.fem.Constant(mesh, 0.0) for _ in range(3)]
        e, k, t = (ufl.variable(x) for x in self.c)
        W = section.W(e, k, t)
        Nf, Mf = section.dW(*self.c)
        exprs = {"W": W, "N": Nf, "M": Mf, "Q": section.torque(*self.c), "Q_auto": ufl.diff(W, t)}
        self.forms = {name: dolfinx.fem.form(x * ufl.dx(mesh)) for name, x in exprs.items()}

    def __call__(self, eps, kappa, tau):
        for c, v in zip(self.c, (eps, kappa, tau)):
            c.value = v
        return {name: dolfinx.fem.assemble_scalar(f) for name, f in self.forms.items()}


@pytest.mark.parametrize("section", [STRESSED, {**LAID, "self_stress_N": 150.0, "bar_EA_N": 2e4}])
def test_ufl_torque_is_members_py(section):
    """Q, N, M, W of the UFL law with tau equal members.py's to round-off (SI:
    W~ M g, Q~ M g L0, kappa = kappa~ / L0, tau = tau~ / L0); Q = UFL's dW/d tau."""
    p = table2(section={**section, "slack_width": 1e-4})
    members = p.model.section.members(p.helix)
    law = PointLaw(section_law.from_normalised(p.normalised()))
    Mg, L0 = p.helix.mass_kg * p.environment.g_m_s2, p.helix.length_m
    seen_slack = 0
    for eps in (-0.15, -2e-3, 1e-3, 5.5e-3):  # -0.15: past the self-stress, slack
        for kappa in (0.0, 0.3, 8.0):
            for tau in (-2.0, 0.0, 0.5, 3.0):  # normalised: R tau up to ~0.04
                got = law(eps, kappa, tau)
                want = members.resultants(eps, kappa / L0, tau / L0)
                seen_slack += bool((members.strains(eps, kappa / L0, tau / L0) <= 0).any())
                assert got["W"] * Mg == pytest.approx(
                    float(members.energy(eps, kappa / L0, tau / L0)), rel=1e-10, abs=1e-9 * Mg)
                assert got["N"] * Mg == pytest.approx(float(want["N"]), rel=1e-10, abs=1e-8)
                assert got["M"] * Mg * L0 == pytest.approx(float(want["M"]), rel=1e-10, abs=1e-8)
                assert got["Q"] * Mg * L0 == pytest.approx(float(want["Q"]), rel=1e-10, abs=1e-8)
                assert got["Q_auto"] == pytest.approx(got["Q"], rel=1e-8, abs=1e-9)
    assert seen_slack >= 3


@functools.lru_cache
def twisted_state(section_items, torque_Nm):
    """The stationary state of Table 2 with the members' torsion and a torque at the top
    (the twist pinned at the ground); SI section state along s."""
    p = table2(section=dict(section_items))
    q = p.normalised()
    S = StationarySolver(p, MPI.COMM_SELF)
    S.set_end_torques(top=torque_Nm / q.torque_scale)
    res = S.solve()
    return p, res, structure_limits.si(q, SectionProbe.of_rod(S.rod).section())


@pytest.mark.parametrize("section, torque_Nm", [(STRESSED, 3.0), (LAID, 12.0)])
def test_torque_balance_with_the_members_torque(section, torque_Nm):
    """Eq. (31) at rest: the twisting moment is the end torque all along s; members.py's
    Q at the FE's strains is the FE's and the end torque, and the FE's twist is the root
    of members.py's torque-twist curve Q(eps, kappa, .) = m."""
    p, _, x = twisted_state(tuple(section.items()), torque_Nm)
    members = p.model.section.members(p.helix)
    Q = members.resultants(x["eps"], x["kappa"], x["tau"])["Q"]
    assert np.allclose(Q, x["Q"], rtol=1e-9, atol=1e-9 * torque_Nm)
    # the torque balance holds at the nodes to the discretisation's error
    assert np.max(np.abs(x["Q"] - torque_Nm)) < 3e-4 * torque_Nm, x["Q"]  # measured 7e-5
    for k in range(0, len(x["tau"]), 5):
        root = brentq(lambda t: float(members.resultants(x["eps"][k], x["kappa"][k], t)["Q"]) - torque_Nm,
                      -0.5, 0.5, xtol=1e-14)
        assert x["tau"][k] == pytest.approx(root, rel=3e-3, abs=1e-8)
    # the members are taut and the twist is held (the laid ring does not unwind)
    assert members.strains(x["eps"], x["kappa"], x["tau"]).min() > 0


def test_laid_members_held_by_the_tensions_torque_barely_twist():
    """A laid ring under tension N carries the torque ~ N R tan(beta) at tau = 0 (12 N m
    at 206 N, 16.8 deg): held by that torque it keeps its lay, |R tau| << tan(beta)."""
    p, _, x = twisted_state(tuple(LAID.items()), 12.0)
    m = p.model.section.members(p.helix)
    assert np.max(np.abs(m.R * x["tau"])) < 0.05 * np.tan(m.beta)


@pytest.mark.long
def test_stressed_torsional_modes_are_the_solids_with_the_geometric_GJ():
    """Unlaid, self-stressed, all taut: the members' GJ is geometric, n R^2 P_t / (1 + eps),
    with the tethers' tension P_t = P0 + k eps (members.py's closed form at beta = 0 is
    its value at eps = 0).  The
    torsional modes equal the solid's with GJ = n R^2 P_t at the mean strain, to the
    strain's variation along s (P_t within 0.1 %), to 1e-4.  (With the helix's GJ = 140 N m^2
    instead they are 0.86 % lower: 142.4 / 140 = 1.0086^2.)"""
    p, _, x = twisted_state(tuple(STRESSED.items()), 0.0)
    m = p.model.section.members(p.helix)
    P_t = m.P0 + m.k * x["eps"]
    assert np.ptp(P_t) / P_t.mean() < 1e-3
    # Q = sum_m k e_m R b / l_m with b = R tau, l_m = sqrt(a^2 + b^2), a = 1 + eps: its
    # slope at tau = 0 is n R^2 P_t / (1 + eps) (the 1 / (1 + eps): 0.28 % in frequency)
    GJ = m.n * m.R**2 * np.mean(P_t / (1 + x["eps"]))
    # helix.EI_Nm2 sets the rotational inertia too (delta, Eq. 27): the same in both
    EI = m.taut_moduli()["EI"]
    solid = table2(helix={"EI_Nm2": EI, "GJ_Nm2": GJ})
    tens = table2(helix={"EI_Nm2": EI}, section=STRESSED)
    freqs = {}
    for name, sc in (("tensegrity", tens), ("solid", solid)):
        modes = ModalSolver.from_stationary(sc, MPI.COMM_SELF).solve()
        freqs[name] = np.sort([abs(md.eigenvalue) for md in modes if md.family == "torsional"])[:3]
    assert len(freqs["solid"]) == 3
    # measured 1.2e-6; without the 1 / (1 + eps), 2.8e-3
    assert np.allclose(freqs["tensegrity"], freqs["solid"], rtol=1e-4, atol=0), freqs


def test_refusals():
    with pytest.raises(ParameterError, match="only with section.law = 'tensegrity'"):
        table2(section={"law": "saturating", "torsion": "members"})
    with pytest.raises(ParameterError, match="no torsional stiffness at zero strain"):
        table2(section={"law": "tensegrity", "torsion": "members"})
    with pytest.raises(ParameterError, match="must be one of"):
        table2(section={"law": "tensegrity", "torsion": "bars"})
