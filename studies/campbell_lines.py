"""The excitation lines of a Campbell diagram and their crossings with the modes: numpy only.

A rotor of B blades excites the helix at multiples of its spin frequency: the 1P
line f = Omega / 2 pi, 2P, and the blade passing BP (f = B Omega / 2 pi).  Along a
branch of operating points (sorted by rotor speed) a mode crosses a line between two
adjacent points where f_mode - n f_rotor changes sign; the crossing is placed by
linear interpolation of that difference (exact when both vary linearly with the speed).

A mode is followed from point to point (:func:`follow`) by its frequency: within its
family, the pairs of modes of two adjacent points nearest in frequency are matched
first, and a pair whose frequencies differ by more than MATCH_TOL (relative) is not
the same mode: a mode that appears (an overdamped pair that starts to oscillate, as the
rotor's slow torsional mode does at low wind) starts a track, one that vanishes ends
its track, and no crossing is interpolated across such a gap.
"""

from __future__ import annotations

import math

RPM_HZ = 1.0 / 60.0  # Hz per rpm
#: the largest relative change of a mode's frequency between two adjacent points that
#: still counts as the same mode (the modes of a family lie further apart: the rotor's
#: slow torsional mode at 0.3-0.4 Hz and the next at 2.5 Hz on rotor_example)
MATCH_TOL = 0.25


def follow(points: list) -> list[list]:
    """The tracks of one family along one branch: ``points`` = [(rotor_rpm, wind_m_s,
    [frequency_Hz of each mode of the family])] in any order; returns tracks, each a
    list of (rotor_rpm, frequency_Hz, wind_m_s, index) with index the mode's rank in
    its family at that point (0: the lowest)."""
    tracks, active = [], {}  # active: track number -> its last frequency
    for rpm, wind, freqs in sorted(points, key=lambda p: p[0]):
        pairs = sorted((abs(f - active[t]) / max(f, active[t], 1e-300), t, k)
                       for t in active for k, f in enumerate(freqs))
        taken_t, taken_k, now = set(), set(), {}
        for gap, t, k in pairs:
            if gap <= MATCH_TOL and t not in taken_t and k not in taken_k:
                taken_t.add(t)
                taken_k.add(k)
                now[t] = k
        for k in range(len(freqs)):
            if k not in taken_k:
                tracks.append([])
                now[len(tracks) - 1] = k
        active = {}
        for t, k in now.items():
            tracks[t].append((rpm, freqs[k], wind, k))
            active[t] = freqs[k]
    return tracks


def orders(blades: int) -> tuple[int, ...]:
    """The lines' multiples of the rotor speed: 1P, 2P and BP (B blades), each once."""
    if int(blades) != blades or blades < 1:
        raise ValueError(f"rotor.blades must be a whole number >= 1, not {blades!r}")
    return tuple(sorted({1, 2, int(blades)}))


def line_name(order: int) -> str:
    return f"{order}P"


def crossings(tracks: dict, blades: int) -> list[dict]:
    """Every crossing of a line with a mode.

    ``tracks``: {(branch, family, track): [(rotor_rpm, frequency_Hz, wind_m_s, index,
    ...), ...]}, one list per mode followed along a branch (:func:`follow`; what follows
    the index is not read), sorted by rotor speed here.  Returns dicts with family, mode (its 1-based rank in the family at the
    lower point), branch, line, frequency_Hz, rotor_rpm, wind_m_s, in increasing rotor
    speed."""
    out = []
    for (branch, family, _), points in tracks.items():
        points = sorted(points)
        for n in orders(blades):
            for (r0, f0, v0, k0, *_), (r1, f1, v1, *_) in zip(points, points[1:]):
                g0, g1 = f0 - n * r0 * RPM_HZ, f1 - n * r1 * RPM_HZ
                if g0 == 0.0 or g0 * g1 >= 0.0:
                    if g0 == 0.0:  # on the line at a point
                        out.append(_crossing(family, k0, branch, n, r0, f0, v0))
                    continue
                t = g0 / (g0 - g1)
                out.append(_crossing(family, k0, branch, n, r0 + t * (r1 - r0),
                                     f0 + t * (f1 - f0), v0 + t * (v1 - v0)))
            if points and points[-1][1] - n * points[-1][0] * RPM_HZ == 0.0:
                r, f, v, k = points[-1][:4]
                out.append(_crossing(family, k, branch, n, r, f, v))
    return sorted(out, key=lambda c: (c["rotor_rpm"], c["line"], c["family"]))


def _crossing(family, index, branch, n, rpm, frequency, wind) -> dict:
    if not all(math.isfinite(x) for x in (rpm, frequency, wind)):
        raise ValueError(f"a crossing of {family} {index + 1} with {line_name(n)} is not finite")
    return {"family": family, "mode": index + 1, "branch": branch, "line": line_name(n),
            "frequency_Hz": frequency, "rotor_rpm": rpm, "wind_m_s": wind}


def slack_bands_Hz(envelope: dict, value=None) -> list[tuple[float, float]]:
    """The forcing frequencies f1 where the Sec. 5.3 forced helix slackens, from an
    ``envelope`` summary: along each tick's branch (in the order traced, through its
    folds), each run of points whose first limit is slack spans [min f1, max f1]; the
    runs merged where they overlap.  ``value``: only the tick whose value of the
    envelope's key is nearest it (the scene's own value); None: every tick."""
    ticks = envelope.get("ticks", [])
    if value is not None and ticks:
        ticks = [min(ticks, key=lambda t: abs(float(t["value"]) - float(value)))]
    runs, run = [], []
    for tick in ticks:
        for e in tick.get("branch", []) + [None]:  # None: the end of the branch
            if e is not None and _kind(e.get("first_limit")) == "slack":
                run.append(float(e["f1_Hz"]))
            elif run:
                runs.append((min(run), max(run)))
                run = []
    merged = []
    for lo, hi in sorted(runs):
        if merged and lo <= merged[-1][1]:
            merged[-1] = (merged[-1][0], max(hi, merged[-1][1]))
        else:
            merged.append((lo, hi))
    return merged


def _kind(first_limit):
    if isinstance(first_limit, dict):
        return first_limit.get("kind")
    return first_limit
