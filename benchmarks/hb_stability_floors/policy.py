"""Path (a) offline: the guarded Hill (stride, fold guard) replayed on the multipliers of DUMP (today.py)."""
import pickle, sys, numpy as np
d = pickle.load(open(sys.argv[1],'rb')); calls = d['calls']
def nonfold_max(mu):
    mu = np.asarray(mu); real = np.abs(mu.imag) <= 1e-6*np.maximum(1, np.abs(mu))
    s = mu[~(real & (mu.real > 0))]; return np.abs(s).max() if s.size else 0.0
def near_fold(mu):
    mu = np.asarray(mu); real = np.abs(mu.imag) <= 1e-6*np.maximum(1, np.abs(mu))
    r = mu[real & (mu.real > 0)]; return r.size and np.min(np.abs(r.real - 1)) 
nf = [nonfold_max(c['mu']) for c in calls]
print("nonfold max range", min(nf), max(nf), "max step change", np.max(np.abs(np.diff(nf))))
for stride in (5, 8, 10, 15, 20):
  for fg in (0.0, 0.02, 0.05):
    last, since, hills, bad = None, 0, 0, 0
    for i, c in enumerate(calls):
        mu = c['mu']; unstable = np.abs(mu[0]) >= 1.0
        fold = i > 0 and (np.sum((np.abs(mu.imag) < 1e-6) & (mu.real > 1+1e-9)) % 2) != (np.sum((np.abs(calls[i-1]['mu'].imag) < 1e-6) & (calls[i-1]['mu'].real > 1+1e-9)) % 2)
        due = last is None or fold or since + 1 >= stride or (fg and 0 < (near_fold(last) or 9) < fg) or nonfold_max(last) > 1 - 2e-3
        if due: last, since, hills = mu, 0, hills + 1
        else: since += 1
        if (np.abs(last[0]) >= 1.0) != unstable: bad += 1
    print(f"stride {stride} foldguard {fg}: hill calls {hills}/{len(calls)}, verdicts differing {bad}")
