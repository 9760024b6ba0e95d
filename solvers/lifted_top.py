"""The lifted top end in a dynamic run (issue 44, ``[lifter] top = "lifted"``): r(1)
is free, its condition the natural end term of forms/lifter.py, now with the top's
lumped mass and the rotor's thrust of the step:

    m_top r_tt(1) . v(1) - F . v(1) - F_t(alpha_t(1)) t(1) . v(1)

F = lifter + m_top g k_E (constant: the potential -F . r(1)), F_t the rotor's thrust
1/2 rho pi R^2 V_n^2 CT(lambda) along the end tangent t = r'/|r'| (a follower force, at
the V_n of the step's wind as the rotor's torque), m_top = rotor.mass_kg by the rod's
M.  The energy account gains the top's 1/2 m_top |r_t(1)|^2 - F . r(1) in the stored
energy and the thrust's power F_t t(1) . r_t(1) in the work in.  All normalised
(Eq. 29: forces by M g, masses by M)."""

from __future__ import annotations

import dolfinx.fem
import numpy as np
from petsc4py import PETSc

import math

from scipy.optimize import brentq

from rawehelix.errors import SceneError
from rawehelix.forms import lifter
from rawehelix.solvers import lifted


class LiftedTop:
    """The lifted top's Constants on ``rod`` and its forms (module docstring)."""

    def __init__(self, params, rod):
        load = lifted.top_load(params)  # the lifter's pull and the top's weight [N]
        self.force = dolfinx.fem.Constant(rod.mesh, np.asarray(
            load.total_N() / rod.q.force_scale, dtype=PETSc.ScalarType))
        self.mass = params.rotor.mass_kg / params.helix.mass_kg  # m_top / M

    def residual(self, fields, v, ds, ends):
        """The top's terms of F(t, U, V, A); ``ends`` the run's EndTorques (None: no
        machine), whose rotor's thrust F_t [M g] at the top's spin it takes."""
        thrust = 0.0 if ends is None else ends.thrust(fields)
        return (lifter.top_inertia_residual(self.mass, fields.r_tt, v, ds)
                + lifter.end_residual(self.force, fields.r, v, ds)
                + lifter.follower_residual(thrust, fields.r, v, ds))

    def stored_energy(self, fields, ds):
        """1/2 m_top |r_t(1)|^2 - F . r(1) [M g L0]."""
        return (lifter.top_kinetic(self.mass, fields.r_t, ds)
                + lifter.end_potential(self.force, fields.r, ds))

    @staticmethod
    def thrust_power(fields, ds, thrust):
        """F_t t(1) . r_t(1) [M g L0 / t_scale]: the thrust's work in."""
        return lifter.thrust_power(thrust, fields.r, fields.r_t, ds)


#: the adaptive step's largest, per period of the top's axial mode: alpha2's Newton
#: diverged at 0.075 s (2.3 steps per period; step_rated, N = 2) and ran at 0.038 s
STEPS_PER_AXIAL_PERIOD = 8


def axial_period_s(params) -> float:
    """The period [s] of the top's axial mode: a bar (the helix: EA, L0, M) fixed at the
    ground with the tip mass m_top, kL tan kL = M / m_top, omega = k sqrt(EA L0 / M)."""
    h, m = params.helix, params.rotor.mass_kg
    if m <= 0:  # no tip mass: the fixed-free bar's quarter wave
        kL = math.pi / 2
    else:
        kL = brentq(lambda x: x * math.tan(x) - h.mass_kg / m, 1e-12, math.pi / 2 - 1e-12)
    return 2 * math.pi * h.length_m / (kL * math.sqrt(h.EA_N * h.length_m / h.mass_kg))


def max_step_s(params) -> float:
    """The adaptive step's largest [s] with a lifted top (:data:`STEPS_PER_AXIAL_PERIOD`)."""
    return axial_period_s(params) / STEPS_PER_AXIAL_PERIOD


def of(params, rod, ts_type: str) -> LiftedTop | None:
    """The run's lifted top (None: the top held at [ends]' position); the first-order
    TS forms are refused with it (SceneError, exit 2)."""
    if not params.lifter.active:
        return None
    if ts_type != "alpha2":
        raise SceneError(params.name, "lifter.top",
                         f"'lifted' runs with the second-order time stepper only, not "
                         f"-rawehelix_ts_type {ts_type}: drop that option (alpha2, the default)")
    return LiftedTop(params, rod)


__all__ = ["LiftedTop", "STEPS_PER_AXIAL_PERIOD", "axial_period_s", "max_step_s", "of"]
