"""Today's Fig. 8 curve by HB: CPU total, split into Hill and the rest; dumps Hill's inputs."""
import pickle, sys, time
import numpy as np
import rawehelix as rh
from rawehelix.solvers.harmonic_balance.problem import HarmonicBalance

N = int(sys.argv[1]); dump = sys.argv[2] if len(sys.argv) > 2 else None
calls = []
orig = HarmonicBalance.hill
def timed(self, f1_Hz, H, tangents):
    c = time.process_time()
    r = orig(self, f1_Hz, H, tangents)
    calls.append({"f1": f1_Hz, "H": H, "cpu": time.process_time() - c, "mu": r.multipliers,
                  "exps": r.exponents,
                  "tangents": [[m.copy() for m in t] for t in tangents] if dump else None,
                  "free": self.free, "omega": self.omega(f1_Hz)})
    return r
HarmonicBalance.hill = timed
params = rh.load_scene("mobile_end", elements=N, degree=3)
c0 = time.process_time()
res = rh.orbits(params, 15.0, 0.5, method="hb")
total = time.process_time() - c0
hill = sum(c["cpu"] for c in calls)
s = res.summary
print(f"N={N} points={len(s['branch'])} hill_calls={len(calls)} total_cpu={total:.1f}s hill={hill:.1f}s "
      f"rest={total-hill:.1f}s hill/call median={np.median([c['cpu'] for c in calls])*1e3:.0f}ms")
print("folds", [f["f1_Hz"] for f in s["folds"]], "bifs", [(b.get("kind"), b.get("f1_Hz")) for b in s["bifurcations"]])
print("unstable points", sum(not p["stable"] for p in s["branch"]))
if dump:
    pickle.dump({"calls": calls, "summary": s}, open(dump, "wb"))
