"""Path (b) floor: monodromy of M x'' + C x' + K x = 0 from the HB samples by 4th-order
Magnus (2 Gauss points a step), massless dofs condensed; eigenvalues vs Hill's."""
import pickle, sys, time, numpy as np, scipy.linalg as sl
from rawehelix.solvers.harmonic_balance import hill
d = pickle.load(open(sys.argv[1], 'rb')); calls = d['calls']
def coeffs(samples, free):
    S = np.array([s.toarray()[np.ix_(free, free)] for s in samples])
    return np.fft.fft(S, axis=0) / len(samples)
def at(Ck, t, w):  # trigonometric interpolation, N samples (N even: Nyquist halved)
    N = Ck.shape[0]; k = np.fft.fftfreq(N, 1 / N)
    ph = np.exp(1j * k * w * t); ph[N // 2] = np.cos(N // 2 * w * t)
    return np.real(np.tensordot(ph, Ck, axes=1))
for idx in [int(a) for a in sys.argv[2].split(",")]:
    c = calls[idx]; Fu, Fv, Fa = zip(*c['tangents']); free = c['free']; w = c['omega']; T = 2*np.pi/w
    t0 = time.process_time()
    Mk, Ck, Kk = coeffs(Fa, free), coeffs(Fv, free), coeffs(Fu, free)
    m = len(free); M0 = at(Mk, 0.0, w)
    mass = np.flatnonzero(np.abs(np.diag(M0)) > 1e-12 * np.abs(np.diag(M0)).max())
    rest = np.setdiff1d(np.arange(m), mass)
    def A(t):
        M, C, K = at(Mk, t, w), at(Ck, t, w), at(Kk, t, w)
        # condense the massless dofs r: C_rr x_r' + K_rr x_r + ... assume K_rr invertible, C_r* = 0
        if rest.size:
            Kr = np.linalg.solve(K[np.ix_(rest, rest)], K[np.ix_(rest, mass)])
            K = K[np.ix_(mass, mass)] - K[np.ix_(mass, rest)] @ Kr
            Cc = C[np.ix_(mass, mass)]; M = M[np.ix_(mass, mass)]
        else:
            Cc = C
        n = M.shape[0]; Mi = np.linalg.inv(M)
        return np.block([[np.zeros((n, n)), np.eye(n)], [-Mi @ K, -Mi @ Cc]])
    prep = time.process_time() - t0
    for steps in (32, 64, 128):
        t0 = time.process_time(); h = T / steps; Phi = None
        g = np.sqrt(3) / 6
        for j in range(steps):
            A1, A2 = A((j + 0.5 - g) * h), A((j + 0.5 + g) * h)
            Om = h / 2 * (A1 + A2) + np.sqrt(3) / 12 * h * h * (A2 @ A1 - A1 @ A2)
            E = sl.expm(Om); Phi = E if Phi is None else E @ Phi
        mu = np.linalg.eigvals(Phi); mu = mu[np.argsort(-np.abs(mu))]
        cpu = time.process_time() - t0
        print(f"f1={c['f1']:.3f} size {Phi.shape[0]} (massless {rest.size}) steps {steps}: {cpu*1e3:.0f} ms; "
              f"max|mu| {abs(mu[0]):.5f} vs Hill {abs(c['mu'][0]):.5f}; top3 {np.round(np.abs(mu[:3]),4)} vs {np.round(np.abs(c['mu'][:3]),4)}")
