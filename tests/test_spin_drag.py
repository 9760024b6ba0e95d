"""The spinning helix's own aerodynamic torque loss (issue 43, ``[spin_drag]``,
forms/spin_drag.py): a distributed torque -c Omega |Omega| per length in Eq. (31),
c = n (1/2) rho C_d d R^3 cos(lay).  Off by default; its numpy total for the
operating point; the twist of a steady spinning helix against the closed form of
a torque falling linearly along s."""

import math

import numpy as np
import pytest
from mpi4py import MPI

from rawehelix.errors import SceneError
from rawehelix.parameters import spin_drag
from rawehelix.solvers import fields
from rawehelix.solvers.stationary import StationarySolver
from rawehelix.studies import scene

RPM = 2 * math.pi / 60


def _spinning(d=0.004, N=4, **changes):
    """Table 2's helix, straight (gravity and drag off), with the spin drag on."""
    p = scene.load("stationary_table2", elements=N)
    return p.replace(model={"gravity": False, "drag": False}, spin_drag={"tether_diameter_m": d},
                     **changes)


def linear_torque_twist(s, Q, c, omega, L0, GJ):
    """alpha(s) [rad] of a straight solid helix with the ground's twist held, the torque Q
    [N m] at the top and the spin drag's -c Omega|Omega| per length: M(s) = Q - c W|W|
    (L0 - s), so alpha(s) = [Q s - c W|W| (L0 s - s^2/2)] / GJ (SI)."""
    return (Q * s - c * omega * abs(omega) * (L0 * s - s**2 / 2)) / GJ


def test_off_by_default_and_its_coefficient():
    p = scene.load("stationary_table2")
    assert not p.model.spin_drag.active and p.normalised().spin_drag == 0.0
    assert spin_drag.loss_torque(10.0, p) == 0.0
    q = _spinning(d=0.002, section={"lay_angle_deg": 20.0})
    # n (1/2) rho C_d d R^3 cos(lay), by hand: 6 tethers, 1.225 kg/m^3, 2 mm, R 0.19 m
    c = 6 * 0.5 * 1.225 * 1.0 * 0.002 * 0.19**3 * math.cos(math.radians(20.0))
    assert spin_drag.coefficient(q) == pytest.approx(c, rel=1e-14)
    omega = np.array([-12.0, 0.0, 12.566])
    assert spin_drag.loss_torque(omega, q) == pytest.approx(c * 16.12 * omega * np.abs(omega))


@pytest.mark.parametrize("rpm", [120.0, -300.0])
def test_twist_of_a_spinning_helix_is_the_linear_torque_closed_form(rpm):
    """Rotor torque Q at the top, the ground's twist held: M(s) = Q - c W|W| (L0 - s),
    so alpha(s) = [Q s - c W|W| (L0 s - s^2/2)] / GJ (solid section, straight helix)."""
    p = _spinning(d=0.02)  # a thick tether, so the loss is 12 % of Q at 300 rpm
    q = p.normalised()
    Q, L0, GJ = 25.0 * np.sign(rpm), p.helix.length_m, p.helix.GJ_Nm2
    omega = rpm * RPM
    solver = StationarySolver(p, MPI.COMM_SELF, scene=p.name)
    solver.set_end_torques(ground=Q / q.torque_scale, top=Q / q.torque_scale)
    solver.set_spin(omega * q.t_scale)
    solver.solve()
    rod = solver.rod
    s, alpha = fields.gather(rod.w.sub(rod.model.index("twist")).collapse())
    s = q.length_m(s)
    c = spin_drag.coefficient(p)
    closed = linear_torque_twist(s, Q, c, omega, L0, GJ)
    assert np.max(np.abs(alpha[:, 0] - closed)) < 1e-9 * np.max(np.abs(closed))
    loss = spin_drag.loss_torque(omega, p)
    assert abs(loss) > 0.05 * abs(Q)  # the loss is seen, not lost in the tolerance
    # end to end: (Q - loss / 2) L0 / GJ, the mean moment
    assert alpha[-1, 0] - alpha[0, 0] == pytest.approx((Q - loss / 2) * L0 / GJ, rel=1e-9)


def test_refused_without_the_twist_equation():
    with pytest.raises(SceneError, match="spin_drag.tether_diameter_m"):
        scene.load("stationary_table2", overrides={"spin_drag.tether_diameter_m": 0.004,
                                                  "model.twist": False})


# 21 s on a cold JIT cache (the dynamics' forms with the spin drag): make test-long.  In
# make test the spin drag's term is checked by
# test_twist_of_a_spinning_helix_is_the_linear_torque_closed_form and the energy harness
# by tests/test_damping.py::test_spin_up_with_damping_closes_its_energy_balance
@pytest.mark.long
def test_spin_up_with_spin_drag_closes_its_energy_balance():
    """nominal_operation (N = 4) spun up for 1 s with a spin drag (d = 0.5 m, so that it
    takes most of the work), alpha2 with spectral radius 1 at a fixed 2 ms step: the
    energy K + U above its start equals the work of the end torques and the drag plus
    the non-variational work, minus the dissipated energy int alpha_t dD/d alpha_t,
    to 1e-4 of the dissipated energy.  Measured (1.5 s): dissipated 0.561 (normalised,
    M g L0) of an external work 0.711, balance within 4.0e-7 (7e-7 of it)."""
    from tests_util import spin_up_energy_balance
    p = scene.load("nominal_operation", elements=4, degree=3).replace(
        spin_drag={"tether_diameter_m": 0.5}, time={"dt_s": 2e-3})
    _, W_ext, _, dissipated, balance = spin_up_energy_balance(p, 1.0)
    assert dissipated[-1] > 0.3 * W_ext[-1]  # the spin drag takes a large share
    assert np.abs(balance).max() < 1e-4 * dissipated[-1]


def test_operating_point_with_the_loss_is_mppt_with_the_summed_gain():
    """With MPPT (tau = k Omega^2) the loss c L0 Omega^2 adds to the gain: the rigid
    shaft's root of Q = tau + loss (operation/rigid_shaft.py with loss_of) is the root of
    Q(Omega) = (k + c L0) Omega^2, found independently by scipy's brentq on the table."""
    from scipy.optimize import brentq
    from rawehelix.operation import generator as generator_law, rigid_shaft, rotor as rotor_law
    p = scene.load("rotor_example", overrides={"spin_drag.tether_diameter_m": 0.02})
    rotor, gen = rotor_law.from_params(p), generator_law.from_params(p)
    loss = spin_drag.loss_of(p)
    assert spin_drag.loss_of(scene.load("rotor_example")) is None
    k = p.generator.mppt_gain_Nms2
    cL = spin_drag.coefficient(p) * p.helix.length_m
    v_n, rho = 4.6761, p.environment.air_density_kg_m3
    points = [pt for pt in rigid_shaft.operating_points(rotor, gen, v_n, rho, loss=loss)
              if pt.stable]
    assert len(points) == 1
    lo, hi = (t * v_n / rotor.radius_m for t in (3.0, 8.0))
    omega = brentq(lambda w: float(rotor.torque(w, v_n, rho)) - (k + cL) * w * w, lo, hi,
                   xtol=1e-14)
    assert points[0].omega_rad_s == pytest.approx(omega, rel=1e-9)
    assert cL * omega**2 > 0.03 * points[0].rotor_torque_Nm  # the loss moves the point
    # the ground's torque is the rotor's less the loss
    assert points[0].generator_torque_Nm == pytest.approx(
        points[0].rotor_torque_Nm - float(loss.torque(omega)), rel=1e-9)
