"""The network's own limits block (references/network/limits.py) against one bay's
closed form written out here: a bay of n = 6 tethers, no lay, its top ring tilted by
a about the frame's first axis.  To first order in a the tether at phi_m changes its
length by -/+ a R sin(phi_m), so its force is f_0 + s (k / l0) a R sin(phi_m) and

    N = n f_0,   |M| = (k / l0) a R^2 sum sin^2 = n k a R^2 / (2 l0),

the first tether going slack where (k / l0) a R sin(60 deg) = f_0.  Under 1 s."""

import math

import numpy as np
import pytest

from rawehelix.references.network import Network, Ring
from rawehelix.references.network import energy as en
from rawehelix.references.network.limits import Record, Sampler, bay_resultants
from rawehelix.references.network.network import rotation_about
from rawehelix.studies import scene

N_TETHERS, RADIUS, K, HEIGHT, REST = 6, 0.19, 6000.0, 1.0, 0.99  # [-], [m], [N], [m], [m]
F0 = K * (HEIGHT - REST) / REST  # each tether's force, straight [N]


def tilted(a):
    ring = Ring(1.0, 1.0, 1.0)
    net = Network(n=N_TETHERS, radius_m=RADIUS, k_N=K, l0_m=REST,
                  chord_m=np.array([0.0, 0.0, -HEIGHT]), lay_rad=0.0, rings=(ring, ring),
                  loads_N=np.zeros((2, 3)), spacing_m=HEIGHT)
    X, R = net.reference()
    R[1] = rotation_about(net.frame[:, 0], a) @ R[1]
    return net, en.State(X, R)


def test_a_tilted_bays_resultants_are_the_hand_written_sums():
    a = 1e-4  # [rad]
    net, s = tilted(a)
    N, M, f = bay_resultants(net, s)
    assert N[0] == pytest.approx(N_TETHERS * F0, rel=1e-6)
    assert M[0] == pytest.approx(N_TETHERS * K * a * RADIUS ** 2 / (2 * REST), rel=1e-3)
    assert np.sort(f[0]) == pytest.approx(np.sort(F0 + K / REST * a * RADIUS * np.sin(
        2 * np.pi * np.arange(N_TETHERS) / N_TETHERS)), rel=1e-6)


def test_the_first_slack_is_where_the_hand_written_tilt_puts_it():
    a_slack = F0 * REST / (K * RADIUS * math.sin(math.pi / 3))  # [rad], first order
    record = Record(*tilted(0.9 * a_slack)[:1], saturation=1.0, breaking_N=None)
    record.add(0.5, tilted(0.9 * a_slack)[1])
    block = record.block()
    assert block["first_by_kind"]["slack"] is None and block["slack_fraction_max"] == 0
    ratio = block["moment_ratio_max"]["value"]  # |M| / (N R) = k a R / (2 l0 f0)
    assert ratio == pytest.approx(K * 0.9 * a_slack * RADIUS / (2 * REST * F0), rel=2e-2)
    net, s = tilted(1.1 * a_slack)
    record.add(1.5, s)
    first = record.block()["first_by_kind"]["slack"]
    assert first["t_s"] == 1.5 and first["bay"] == 0 and first["s_m"] == pytest.approx(0.5)
    assert first["tether"] in (1, 2, 4, 5)  # at sin(phi) = +-sin(60 deg): two go at once
    assert record.block()["slack_fraction_max"] == pytest.approx(2 / 6)
    assert record.block()["first_limit"]["kind"] == "slack"


def test_the_sampler_keeps_a_period_and_drops_what_came_before():
    net, s = tilted(1e-3)
    sampler = Sampler(net, 1.0, None)
    sampler.keep(0.0, s)
    sampler.expect()  # a new period: the lead-in's sample is dropped
    sampler.keep(1.0, s)
    sampler.keep(2.0, s)
    record = sampler.sections(sampler.take())
    assert record.samples == 2 and sampler.take() == []
    assert record.block()["min_member_force_N"]["t_s"] == 1.0


def test_the_sweeps_network_point_carries_its_limits_block():
    """A network sweep point on Sec. 5.3's circle (5 rings, one period at 6 Hz):
    its entry has the network's moment ratio and smallest tether force, recorded."""
    from mpi4py import MPI
    from rawehelix.studies import sweep
    p = scene.load("mobile_end").replace(
        section={"law": "tensegrity", "torsion": "members", "self_stress_N": 632.6,
                 "bar_EA_N": 18200.0, "rings": 5},
        model={"kinematics": "extensible"}, discretisation={"scheme": "network"},
        sweep={"lead_in_s": 0.0, "min_periods": 1, "max_periods": 1, "record_periods": 1,
               "samples_per_period": 8})
    point = sweep.compute(p, [6.0], comm=MPI.COMM_SELF, log=lambda m: None).points[0]
    block = point["limits"]
    assert block["status"] == "recorded" and block["samples"] == 8
    assert 0 < point["moment_ratio_max"] < 1
    assert 0 < block["min_member_force_N"]["value"] < 632.6 * 1.2
