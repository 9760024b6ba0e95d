"""Hill at every point: dump each Hill call (f1, H, mu, exps, cpu) and each finished orbit (f1, X, H)."""
import pickle, sys, time
import numpy as np
import rawehelix as rh
from rawehelix.solvers.harmonic_balance import problem as hbp
from rawehelix.solvers.harmonic_balance.stability import EVERY_POINT
from rawehelix.studies import orbit_method
N = int(sys.argv[1]); out = sys.argv[2]
calls, orbits = [], []
hill, finish = hbp.HarmonicBalance.hill, hbp.HarmonicBalance.finish
def timed(self, f1, H, tangents):
    c = time.process_time(); r = hill(self, f1, H, tangents)
    calls.append({"f1": f1, "H": H, "cpu": time.process_time() - c, "mu": r.multipliers, "exps": r.exponents,
                  "omega": self.omega(f1)})
    return r
def kept(self, X, f1, *a, **k):
    o = finish(self, X, f1, *a, **k); orbits.append({"f1": f1, "X": np.array(X), "H": o.steps, "Tmax": o.tension_max_N}); return o
hbp.HarmonicBalance.hill, hbp.HarmonicBalance.finish = timed, kept
orbit_method.HB.stability = EVERY_POINT
params = rh.load_scene("mobile_end", elements=N, degree=3)
c0 = time.process_time()
res = rh.orbits(params, 15.0, 0.5, method="hb")
total = time.process_time() - c0
s = res.summary
print(f"N={N} points={len(s['branch'])} hill={len(calls)} total={total:.1f} hillcpu={sum(c['cpu'] for c in calls):.1f}")
print("folds", [f["f1_Hz"] for f in s["folds"]], "bifs", len(s["bifurcations"]))
pickle.dump({"calls": calls, "orbits": orbits, "summary": s, "total": total}, open(out, "wb"))
