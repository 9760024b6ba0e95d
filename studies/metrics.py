"""Time-series metrics (numpy only)."""

from __future__ import annotations

import numpy as np

SETTLING_BAND = 0.02  # all three spins within 2% of the target


def settling_time(t_s, spins_rpm, target_rpm) -> float | None:
    """First time after which all three spins stay within 2% of the target (None if never)."""
    if target_rpm == 0 or len(t_s) == 0:
        return None
    outside = np.any(np.abs(np.asarray(spins_rpm) - target_rpm) > SETTLING_BAND * abs(target_rpm),
                     axis=1)
    if outside[-1]:
        return None
    last_out = np.nonzero(outside)[0]
    return float(t_s[last_out[-1] + 1]) if len(last_out) else float(t_s[0])
