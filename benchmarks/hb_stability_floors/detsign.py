"""Path (a) floor: sign det dG/dX (scipy SuperLU) at every point of DUMP (today.py) against
the parity of the real multipliers above 1 of its Hill solve."""
import sys, pickle, time, numpy as np, scipy.sparse.linalg as spla
import rawehelix as rh
from rawehelix.solvers.harmonic_balance.problem import HarmonicBalance
d = pickle.load(open(sys.argv[1],'rb'))
m = HarmonicBalance(rh.load_scene("mobile_end", elements=8, degree=3))
def sign_det(J):
    lu = spla.splu(J.tocsc())
    dU = lu.U.diagonal()
    def perm_sign(p):
        p = np.array(p); seen = np.zeros(len(p), bool); s = 1
        for i in range(len(p)):
            if not seen[i]:
                j, L = i, 0
                while not seen[j]: seen[j] = True; j = p[j]; L += 1
                if L % 2 == 0: s = -s
        return s
    return int(np.prod(np.sign(dU.real))) * perm_sign(lu.perm_r) * perm_sign(lu.perm_c), np.sum(np.log(np.abs(dU)))
out = []
for c in d['calls']:
    tang = c['tangents']
    J = m._jacobian(tang, c['f1'], c['H'])
    t = time.process_time(); s, ld = sign_det(J); dt = time.process_time() - t
    mu = c['mu']; nfold = int(np.sum((np.abs(mu.imag) < 1e-6*np.abs(mu)) & (mu.real > 1 + 1e-9)))
    out.append((c['f1'], s, nfold, dt))
print("splu+sign median ms", np.median([o[3] for o in out])*1e3)
bad = [(round(f,4), s, n) for f, s, n, _ in out if (s < 0) != (n % 2 == 1)]
print("points", len(out), "sign(det J) vs parity of real mu>1 disagree at", len(bad), bad[:10])
print("sign sequence", "".join('+' if o[1] > 0 else '-' for o in out))
print("nfold sequence", "".join(str(o[2]) for o in out))
