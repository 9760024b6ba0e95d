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

from rawehelix.operation.generator import LAWS as GENERATOR_LAWS
from rawehelix.operation.rotor import AXES as ROTOR_AXES
from rawehelix.operation.wind import PROFILES as WIND_PROFILES
from rawehelix.parameters.checks import ParameterError
from rawehelix.parameters.generator import Generator
from rawehelix.parameters.lifter import TOPS as LIFTER_TOPS, Lifter
from rawehelix.parameters.rotor import Rotor
from rawehelix.parameters.wind import Wind
from rawehelix.parameters.damping import Damping
from rawehelix.parameters.eilaw import PAPER_EI_LAW, EILaw
from rawehelix.parameters.fingerprint import LATER_HELIX_SWITCHES, LATER_MODEL_SWITCHES
from rawehelix.parameters.hysteresis import TorsionHysteresis
from rawehelix.parameters.normalised import RPM, Normalised
from rawehelix.parameters.numerics import (BENDINGS, MESHES, PENALTY_MAX, SCHEMES,
                                           Discretisation, Sweep, Time)
from rawehelix.parameters.scene import GROUP_KEYS, Parameters
from rawehelix.parameters.sections import (GAMMA_TREATMENTS, KINEMATICS, STIFFNESS, Controller,
                                           Ends, Environment, Helix, Model, Torque)

__all__ = ["ParameterError", "Damping", "PAPER_EI_LAW", "EILaw", "LATER_HELIX_SWITCHES",
           "LATER_MODEL_SWITCHES", "TorsionHysteresis", "RPM", "Normalised", "BENDINGS", "MESHES",
           "PENALTY_MAX", "SCHEMES", "Discretisation", "Sweep", "Time", "GROUP_KEYS", "Parameters",
           "GAMMA_TREATMENTS", "KINEMATICS", "STIFFNESS", "Controller", "Ends", "Environment", "Helix", "Model",
           "Torque", "GENERATOR_LAWS", "ROTOR_AXES", "WIND_PROFILES", "LIFTER_TOPS", "Generator",
           "Lifter", "Rotor", "Wind"]
