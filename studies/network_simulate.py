"""``rawehelix simulate --scheme network``: the ring-and-tether network in time
(references/network/dynamics.py) from its stationary state, as a
:class:`~rawehelix.studies.simulate.TimeSeries` with the FE run's columns: the spins
of the ground, middle and top rings [rpm], the ground torque (the controller's, Eq. 40)
[N m], the first and last bays' axial forces [N] and the middle ring's displacement
normal to the chord from the start [m].  Its summary's ``network`` block holds the
rings, the step (half the splitting's stability bound, or time.dt_s when smaller),
the smallest tether force over the run and when a tether first went slack."""

from __future__ import annotations

import time

import numpy as np

from rawehelix.parameters.checks import ParameterError
from rawehelix.parameters.normalised import RPM
from rawehelix.references.network import NetworkError
from rawehelix.references.network import dynamics as dy
from rawehelix.references.network import start as network_start
from rawehelix.references.network import energy as en
from rawehelix.studies.analysis import metrics
from rawehelix.studies.scene import SceneError


def compute(params, until_s: float):
    """The run to ``until_s`` [s], outputs every time.output_every_s: (its rows, its
    summary, why it stopped early or None), which studies/simulate.py makes its
    TimeSeries (or its SimulationError)."""
    start = time.perf_counter()
    try:
        net, st, drive, mo = network_start.start(params)  # at rest, or a rotor's operating point
    except ParameterError as err:  # a wind the rotor has no operating point at: exit 2
        raise SceneError(params.name, err.key, f"{err.value!r}: {err.allowed}") from None
    integ = dy.Integrator(net, drive, dy.default_step(net, st.state, params.time.dt_s))
    mid, e = net.count // 2, net.chord_m / np.linalg.norm(net.chord_m)
    x_mid0 = st.state.X[mid].copy()
    rows, watch = [], {"smallest_N": np.inf, "first_slack_s": None}

    def sample(m):
        spin = integ.spin(m) / RPM
        dx = m.state.X[mid] - x_mid0
        rows.append((m.t, spin[0], spin[mid], spin[-1], integ.ground_torque_Nm(m),
                     dy.bay_tension_N(net, m.state, 0), dy.bay_tension_N(net, m.state, -1),
                     float(np.linalg.norm(dx - (dx @ e) * e))))
        f = float(en.tether_forces(net, m.state).min())
        watch["smallest_N"] = min(watch["smallest_N"], f)
        if f <= 0 and watch["first_slack_s"] is None:
            watch["first_slack_s"] = m.t

    loop = time.perf_counter()
    error = None
    try:
        integ.advance(mo, until_s, params.time.output_every_s, sample)
    except NetworkError as err:
        error = str(err)
    data = np.array(rows)
    solve_s = time.perf_counter() - loop
    summary = {"scene": params.name, "scheme": "network", "rings": net.count,
               "dofs": 6 * (net.count - 2) + 2, "target_rpm": params.controller.target_rpm,
               "model": "network of rigid rings and tension-only tethers (references/network)",
               "complete": error is None, "error": error, "simulated_s": float(data[-1, 0]),
               "solve_s": solve_s, "wall_s": time.perf_counter() - start, "steps": integ.steps,
               "newton_iterations": 0,
               "settling_time_s": metrics.settling_time(data[:, 0], data[:, 1:4],
                                                        params.controller.target_rpm),
               "real_time_factor": float(data[-1, 0]) / max(solve_s, 1e-12),
               "network": {"rings": net.count, "spacing_m": net.spacing_m, "dt_s": integ.dt,
                           "stable_step_s": integ.dt / dy.STABILITY_SHARE
                           if integ.dt < params.time.dt_s else None,
                           "smallest_tether_force_N": watch["smallest_N"],
                           "first_slack_s": watch["first_slack_s"]},
               "final": {"spin_rpm": {"s0": data[-1, 1], "mid": data[-1, 2], "L0": data[-1, 3]},
                         "ground_torque_Nm": data[-1, 4], "tension_s0_N": data[-1, 5],
                         "tension_L0_N": data[-1, 6], "lateral_mid_m": data[-1, 7]},
               "tension_range_N": [float(data[:, 5:7].min()), float(data[:, 5:7].max())]}
    return data, summary, error, start
