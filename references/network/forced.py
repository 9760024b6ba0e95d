"""The network as a backend of the sweep's periodic response (solvers/periodic.py's
protocol: normalised times and tensions, the state packed to arrays): the forced
response of Sec. 5.3, the top on the circle of Eq. (70) at each f1, integrated by
:mod:`.dynamics`."""

from __future__ import annotations

import numpy as np

from rawehelix.references.network import dynamics as dy
from rawehelix.references.network import energy as en
from rawehelix.references.network.limits import Sampler
from rawehelix.references.network.network import Network
from rawehelix.references.network.stationary import solve


class NetworkBackend:
    scheme = "network"
    section_sampler = None  # no fields along s to sample (solvers/periodic.py)

    def track_sections(self) -> None:
        """Sample the network's members at the output times (limits.py: the first slack
        tether, the moment ratio), for the sweep point's limits block."""
        members = self.params.model.section.members(self.params.helix)
        self.section_sampler = Sampler(self.net, members.saturation, members.breaking_N)

    def __init__(self, params):
        self.params, self.q = params, params.normalised()
        self.net = Network.from_parameters(params, end_torque_Nm=0.0)
        self.integrator = None
        #: the smallest tether force seen [N] and the slack tethers' count at it
        self.smallest_tether_N = np.inf

    def stationary(self) -> dy.Motion:
        """At rest in the stationary state, the top at its circle's phase 0 (t = 0)."""
        st = solve(self.net)
        drive = dy.Drive.from_parameters(self.params)
        self.integrator = dy.Integrator(self.net, drive,
                                        dy.default_step(self.net, st.state, self.params.time.dt_s))
        return dy.at_rest(st.state, 0.0, drive)

    def set_frequency(self, f1_Hz: float, t_start: float):
        """The circle of Eq. (70) at f1, at phase 0 at the normalised time t_start."""
        if self.integrator is None:
            self.stationary()
        self.integrator.drive = dy.Drive.from_parameters(self.params, f1_Hz,
                                                         t_start * self.q.t_scale)

    def advance(self, mo: dy.Motion, t0: float, t1: float, t_out):
        """(the motion at t1, T(0) / (M g) at t_out) from mo at t0 (normalised times)."""
        ts, integ = self.q.t_scale, self.integrator
        mo = mo.copy()
        drive = integ.drive
        if drive.top_position is not None:  # the end's velocity jumps to the circle's
            mo.state.X[-1], mo.V[-1] = drive.top_position(t0 * ts), drive.top_velocity(t0 * ts)
        tension, sampler = [], self.section_sampler
        if sampler is not None:
            sampler.expect()
        outputs = list(np.asarray(t_out, dtype=float))
        for k, target in enumerate(outputs + [t1]):
            span = target * ts - mo.t
            if span > 1e-12 * max(1.0, mo.t):
                n = int(np.ceil(span / integ.dt * (1 - 1e-12)))
                for _ in range(n):
                    integ.step(mo, span / n)
            self.smallest_tether_N = min(self.smallest_tether_N,
                                         float(en.tether_forces(self.net, mo.state).min()))
            tension.append(dy.bay_tension_N(self.net, mo.state) / self.q.force_scale)
            if sampler is not None and k < len(outputs):
                sampler.keep(mo.t, mo.state)
        return mo, np.array(tension[:-1])

    def parts(self, mo: dy.Motion) -> dict:
        """The motion's parts whose change over a period says what still moves
        (solvers/periodic.py's ``unsettled``), normalised as the FE's: the rings'
        centres (L0) and velocities (L0 / t_scale)."""
        q = self.q
        return {"the ring centres": mo.state.X / q.L0,
                "the ring centres' velocity": mo.V * q.t_scale / q.L0}

    @staticmethod
    def pack(mo: dy.Motion) -> dict:
        s = mo.state
        return {"X": s.X, "R": s.R, "theta": s.theta, "V": mo.V, "L": mo.L, "t_s": mo.t,
                "turns": np.array([mo.ground_turn, mo.ground_spin, mo.top_spin])}

    @staticmethod
    def unpack(data) -> dy.Motion:
        turns = np.asarray(data["turns"], dtype=float)
        return dy.Motion(float(data["t_s"]), en.State(np.array(data["X"]), np.array(data["R"]),
                                                       float(data["theta"])),
                         np.array(data["V"]), np.array(data["L"]), *map(float, turns))
