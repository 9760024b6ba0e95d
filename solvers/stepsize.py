"""Is a fixed time step fine enough for the scene?  One criterion, checked before a run.

The FE dynamics take fixed steps of ``time.dt_s`` whenever the upper end moves
(Eq. 70; :class:`~rawehelix.solvers.dynamics.DynamicsSolver`, the sweep's
:class:`~rawehelix.solvers.forced.FEBackend`).  Such a run must resolve the
fastest motion the scene excites:

* the forcing, the circle of the upper end at f1 (Eq. 70), omega = 2 pi f1;
* the first longitudinal mode, omega_L = :func:`rawehelix.solvers.analytic.bar`
  (n = 1) about the stationary tension T = sigma eps0.  A moving end excites it:
  the end's velocity and acceleration jump when the motion starts and at every
  new f1 of a sweep (the circle restarts at phase 0 with the new speed), and
  it is the mode that carries the tension at s = 0.

The criterion (one, for every fixed-step run):

    omega_max dt <= THETA_MAX,   omega_max = max(2 pi f1, omega_L)

that is at least 2 pi / THETA_MAX steps per period of either.  A step past it
is refused before the run (:class:`~rawehelix.errors.SceneError` naming
``time.dt_s``, the limit and why).  THETA_MAX is the measured edge: see
docs/explanation/step_size.md (probes of the Sec. 5.3 sweep paths at dt = 0.5-10 ms).

The lateral modes and the torsional ones the scene excites are slower than
omega_L in every shipped scene (Table 3); the discrete operator's modes above
omega_L are not resolved by any practical step and need not be: alpha2 is
unconditionally stable for them in the linear range (Chung & Hulbert 1993).
Adaptive runs (a fixed upper end: Sec. 5.2) choose their own steps and are
not checked; ``time.dt_s`` is only their first step.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from rawehelix.errors import SceneError
from rawehelix.parameters import schemes
from rawehelix.solvers import analytic

#: the largest omega dt a fixed step may have (2 pi / THETA_MAX ~ 6.3 steps per
#: period of the fastest excited motion); measured in docs/explanation/step_size.md
THETA_MAX = 1.0


@dataclass(frozen=True)
class StepLimit:
    """The largest fixed step [s] of a scene and what sets it."""

    dt_max_s: float
    omega_max_rad_s: float
    what: str  # "the forcing f1 = ... Hz" or "the first longitudinal mode ... Hz"

    def allows(self, dt_s: float) -> bool:
        return dt_s <= self.dt_max_s * (1 + 1e-12)


def limit(params, f1_Hz: float | None = None) -> StepLimit:
    """The step limit of the criterion for the scene at the forcing f1 [Hz]
    (default: the scene's ``ends.circle_frequency_Hz``)."""
    q = params.normalised()
    f1 = params.ends.circle_frequency_Hz if f1_Hz is None else f1_Hz
    omega_f = 2 * math.pi * f1
    omega_L = float(analytic.bar(q, 1, q.sigma * q.eps0)) / q.t_scale  # [rad/s]
    if omega_f >= omega_L:
        omega, what = omega_f, f"the forcing f1 = {f1:g} Hz"
    else:
        omega, what = omega_L, (f"the first longitudinal mode ({omega_L / (2 * math.pi):.1f} Hz, "
                                "excited by the moving end and carrying the tension at s = 0)")
    return StepLimit(THETA_MAX / omega, omega, what)


def check(params, f1_Hz=None, fixed_steps: bool | None = None):
    """Refuse ``time.dt_s`` if it breaks the criterion at any f1 of ``f1_Hz``
    (a number or a list [Hz]; default the scene's ``ends.circle_frequency_Hz``).
    Only FE runs whose upper end moves are checked, and only with fixed steps
    (``fixed_steps``, default True: the dynamics' default with a moving end).
    Raises :class:`SceneError`; returns the StepLimit (None: not checked)."""
    moving = params.ends.circle_radius_m > 0 if f1_Hz is not None else params.normalised().moving_end
    if fixed_steps is None:
        fixed_steps = moving
    if not schemes.of(params).fixed_time_step or not (fixed_steps and moving):
        return None
    values = [f1_Hz] if f1_Hz is None or isinstance(f1_Hz, (int, float)) else list(f1_Hz)
    worst = min((limit(params, f) for f in values), key=lambda lim: lim.dt_max_s)
    dt = params.time.dt_s
    if not worst.allows(dt):
        raise SceneError(params.name, "time.dt_s",
                         f"{dt:g} s is too long for fixed steps: it must resolve {worst.what}, "
                         f"omega dt <= {THETA_MAX:g} (at least {2 * math.pi / THETA_MAX:.1f} steps "
                         f"per period), so dt <= {worst.dt_max_s:.3g} s; longer steps let "
                         f"alpha2 go wrong or unstable (docs/explanation/step_size.md)")
    return worst
