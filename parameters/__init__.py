"""Physical parameters of a helix scene (SI) and their normalisation, Eqs. (25)-(29).

Users read and write SI units only (N, m, s, Nm, rpm, Hz).  Every solver works
in the normalised variables of the paper:

    t~ = t / t_scale,  t_scale = sqrt(L0 / g)         (25)
    s~ = s / L0,  r~ = r / L0,  v~ = v / sqrt(g L0)   (25)

This package is numpy-only: both the FEniCSx path and the independent
references (shooting, spline Galerkin) import it, and nothing else in common.

The package's modules, one job each: :mod:`.checks` (the error, the range
checks), :mod:`.sections` (the physical sections), the components' sections
(:mod:`.damping`, :mod:`.hysteresis`, :mod:`.eilaw`), :mod:`.numerics`
(discretisation, time, sweep), :mod:`.scene` (:class:`Parameters`, the
cross-checks), :mod:`.fingerprint` (compatibility of stored fingerprints),
:mod:`.normalised` (the groups) and :mod:`.forcing` (the ends' laws).
Every name stays importable from ``rawehelix.parameters``.
"""

from rawehelix.parameters.checks import ParameterError, _non_negative, _positive  # noqa: F401
from rawehelix.parameters.damping import Damping  # noqa: F401
from rawehelix.parameters.eilaw import PAPER_EI_LAW, EILaw  # noqa: F401
from rawehelix.parameters.fingerprint import LATER_HELIX_SWITCHES, LATER_MODEL_SWITCHES  # noqa: F401
from rawehelix.parameters.hysteresis import TorsionHysteresis  # noqa: F401
from rawehelix.parameters.normalised import RPM, Normalised  # noqa: F401
from rawehelix.parameters.numerics import (BENDINGS, MESHES, PENALTY_MAX, SCHEMES,  # noqa: F401
                                           Discretisation, Sweep, Time)
from rawehelix.parameters.scene import GROUP_KEYS, Parameters  # noqa: F401
from rawehelix.parameters.sections import (GAMMA_TREATMENTS, KINEMATICS, Controller,  # noqa: F401
                                           Ends, Environment, Helix, Model, Torque)
