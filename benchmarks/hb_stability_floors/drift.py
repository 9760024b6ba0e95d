"""Path (d) offline: the guard from drift (solvers/harmonic_balance/stability.py's GUARDED, its own
Track) replayed on a Hill-at-every-point dump (every_point.py): Hill solves and verdicts differing.
The fold events are read from f1's turning points (both neighbours counted), the natural-step
trigger is not replayed (the continuation's iterations are not in the dump)."""
import pickle, sys
import numpy as np
from rawehelix.solvers.harmonic_balance import stability as st

d = pickle.load(open(sys.argv[1], "rb"))
calls, orbits = d["calls"], d["orbits"]
n = orbits[0]["X"].size // (2 * orbits[0]["H"] + 1)
embed = lambda X, H: np.pad(X.reshape(n, -1), ((0, 0), (0, 2 * H + 1 - X.size // n))).ravel()  # noqa: E731
f1 = np.array([o["f1"] for o in orbits])
turn = np.sign(np.diff(f1))
event = np.zeros(len(f1), bool)
for i in range(1, len(f1) - 1):
    if turn[i] != turn[i - 1]:
        event[i] = event[i + 1] = True
event[-1] = True
for safety in (1.0, 2.0, 3.0, 5.0):
    for dmax in (0.25, 0.5, 1.0):
        st.SAFETY, st.D_MAX = safety, dmax
        track, hills, bad = None, 0, []
        for i, (c, o) in enumerate(zip(calls, orbits)):
            point = st.HillPoint(np.asarray(c["mu"]), o["f1"], o["X"], o["H"])
            dist = 0.0 if track is None else track.distance(o["X"], o["f1"], o["H"], embed)
            if track is not None:
                track.since += 1
            if st.GUARDED.due(track, dist, bool(event[i]), False):
                hills += 1
                if track is None:
                    track = st.Track(point)
                else:
                    track.hill(point, dist)
            if (np.abs(track.last.multipliers).max() < 1) != (np.abs(c["mu"]).max() < 1):
                bad.append(round(o["f1"], 4))
        print(f"safety {safety} D_MAX {dmax}: {hills} Hill solves of {len(calls)}, verdicts differing at {bad}")
