"""The excitation lines of a Campbell diagram and their crossings with the modes: numpy only.

A rotor of B blades excites the helix at multiples of its spin frequency: the 1P
line f = Omega / 2 pi, 2P, and the blade passing BP (f = B Omega / 2 pi).  Along a
branch of operating points (sorted by rotor speed) a mode crosses a line between two
adjacent points where f_mode - n f_rotor changes sign; the crossing is placed by
linear interpolation of that difference (exact when both vary linearly with the speed).
"""

from __future__ import annotations

import math

RPM_HZ = 1.0 / 60.0  # Hz per rpm


def orders(blades: int) -> tuple[int, ...]:
    """The lines' multiples of the rotor speed: 1P, 2P and BP (B blades), each once."""
    if int(blades) != blades or blades < 1:
        raise ValueError(f"rotor.blades must be a whole number >= 1, not {blades!r}")
    return tuple(sorted({1, 2, int(blades)}))


def line_name(order: int) -> str:
    return f"{order}P"


def crossings(tracks: dict, blades: int) -> list[dict]:
    """Every crossing of a line with a mode.

    ``tracks``: {(branch, family, index): [(rotor_rpm, frequency_Hz, wind_m_s), ...]}, one
    list per mode followed along a branch; the points are sorted by rotor speed here.
    Returns dicts with family, mode (1-based index), branch, line, frequency_Hz, rotor_rpm,
    wind_m_s, in increasing rotor speed."""
    out = []
    for (branch, family, index), points in tracks.items():
        points = sorted(points)
        for n in orders(blades):
            for (r0, f0, v0), (r1, f1, v1) in zip(points, points[1:]):
                g0, g1 = f0 - n * r0 * RPM_HZ, f1 - n * r1 * RPM_HZ
                if g0 == 0.0 or g0 * g1 >= 0.0:
                    if g0 == 0.0:  # on the line at a point
                        out.append(_crossing(family, index, branch, n, r0, f0, v0))
                    continue
                t = g0 / (g0 - g1)
                out.append(_crossing(family, index, branch, n, r0 + t * (r1 - r0),
                                     f0 + t * (f1 - f0), v0 + t * (v1 - v0)))
            if points and points[-1][1] - n * points[-1][0] * RPM_HZ == 0.0:
                r, f, v = points[-1]
                out.append(_crossing(family, index, branch, n, r, f, v))
    return sorted(out, key=lambda c: (c["rotor_rpm"], c["line"], c["family"]))


def _crossing(family, index, branch, n, rpm, frequency, wind) -> dict:
    if not all(math.isfinite(x) for x in (rpm, frequency, wind)):
        raise ValueError(f"a crossing of {family} {index + 1} with {line_name(n)} is not finite")
    return {"family": family, "mode": index + 1, "branch": branch, "line": line_name(n),
            "frequency_Hz": frequency, "rotor_rpm": rpm, "wind_m_s": wind}


def slack_bands_Hz(envelope: dict) -> list[tuple[float, float]]:
    """The forcing frequencies f1 where the Sec. 5.3 forced helix first slackens: per tick
    of an ``envelope`` summary, the f1 range of its branch points whose first limit is
    slack (none if no point slackens)."""
    bands = []
    for tick in envelope.get("ticks", []):
        f1 = [e["f1_Hz"] for e in tick.get("branch", []) if _kind(e.get("first_limit")) == "slack"]
        if f1:
            bands.append((min(f1), max(f1)))
    return bands


def _kind(first_limit):
    if isinstance(first_limit, dict):
        return first_limit.get("kind")
    return first_limit
