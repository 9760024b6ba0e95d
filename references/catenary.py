"""The elastic catenary in closed form: the independent reference of the lifted top
(solvers/lifted.py) for a cable without bending and twist.

Irvine (Cable Structures, 1981, Sec. 2.2): a cable of unstretched length L0, weight
w per unstretched length and axial stiffness EA (tension T = EA (|r'| - 1), Eq. 29),
anchored at the origin and pulled at its upper end by the force (H, V) (H
horizontal, V vertical up, both > 0), has its upper end at

    x = H L0 / EA + (H / w) [asinh(V / H) - asinh((V - w L0) / H)],
    h = V L0 / EA - w L0^2 / (2 EA)
        + (H / w) [sqrt(1 + (V / H)^2) - sqrt(1 + ((V - w L0) / H)^2)],

h the height above the anchor.  With w = 0 the cable is straight and stretched
by |F| L0 / EA along F.  Numpy only: shares no code with the FE path.
"""

from __future__ import annotations

import math


def top(H: float, V: float, w: float, EA: float, L0: float) -> tuple[float, float]:
    """(x, h) [m] of the upper end: horizontal distance and height above the anchor
    (H, V [N]; w [N/m]; EA [N]; L0 [m])."""
    if H <= 0:
        raise ValueError(f"H = {H} must be > 0 (a vertical cable is the straight case)")
    if w == 0:
        stretch = 1.0 + math.hypot(H, V) / EA
        return H / math.hypot(H, V) * L0 * stretch, V / math.hypot(H, V) * L0 * stretch
    a, b = V / H, (V - w * L0) / H
    x = H * L0 / EA + H / w * (math.asinh(a) - math.asinh(b))
    h = V * L0 / EA - w * L0**2 / (2 * EA) + H / w * (math.sqrt(1 + a * a) - math.sqrt(1 + b * b))
    return x, h


def elongation(F: float, EA: float, L0: float) -> float:
    """A weightless straight rod under the axial end force F [N]: F L0 / EA [m]."""
    return F * L0 / EA
