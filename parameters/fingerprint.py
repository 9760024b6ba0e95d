"""Fingerprint compatibility: switches added after results were stored."""

from __future__ import annotations

import dataclasses

from rawehelix.parameters.damping import Damping
from rawehelix.parameters.hysteresis import TorsionHysteresis

#: model switches added after results were stored (sweep checkpoints, the
#: convergence cache): left out of :meth:`Parameters.as_dict` at their
#: defaults, so that those results keep their fingerprints
LATER_MODEL_SWITCHES = {"kinematics": "paper", "damping": dataclasses.asdict(Damping()),
                        "torsion_hysteresis": dataclasses.asdict(TorsionHysteresis())}
#: the same for the helix section
LATER_HELIX_SWITCHES = {"EI_law": None}


def drop_later_switches(data: dict) -> dict:
    """``data`` (Parameters as a dict) without the later switches at their defaults."""
    for section, switches in (("model", LATER_MODEL_SWITCHES),
                              ("helix", LATER_HELIX_SWITCHES)):
        for key, default in switches.items():  # fingerprints stored before them
            if data[section][key] == default:
                data[section].pop(key)
    return data
