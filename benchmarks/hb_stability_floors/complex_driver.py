"""Path (c) floor: the Hill pencil of one Fig. 8 point (DUMP from today.py, call 40) solved by
shift-invert in a complex PETSc/SLEPc worker process fed by a pipe, against SuperLU + ARPACK.
Needs python3-petsc4py-complex, python3-slepc4py-complex."""
import os, pickle, subprocess, sys, time, resource
import numpy as np, scipy.sparse as sp
from rawehelix.solvers.harmonic_balance import hill
d = pickle.load(open(sys.argv[1],'rb')); c = d['calls'][40]
Fu, Fv, Fa = zip(*c['tangents']); w = c['omega']; free = c['free']; H = c['H']
A, B = hill.hill_matrix(Fa, Fv, Fu, w, H, free); A, B = A.tocsr(), B.tocsr()
shifts = [0.0, 0.5j * w] + hill.averaged_exponents(Fa, Fv, Fu, free, 2)
env = dict(os.environ, PETSC_DIR="/usr/lib/petscdir/petsc3.18/x86_64-linux-gnu-complex",
           SLEPC_DIR="/usr/lib/slepcdir/slepc3.18/x86_64-linux-gnu-complex")
t0 = time.perf_counter()
p = subprocess.Popen([sys.executable, os.path.join(os.path.dirname(__file__), "complex_worker.py")], stdin=subprocess.PIPE, stdout=subprocess.PIPE, env=env)
# start-up: an empty job
pickle.dump((sp.identity(4, format="csr", dtype=complex), sp.identity(4, format="csr", dtype=complex), [0.5], 1), p.stdin); p.stdin.flush()
pickle.load(p.stdout); print(f"worker start-up {time.perf_counter() - t0:.2f} s wall")
for rep in range(3):
    t0 = time.perf_counter(); c0 = time.process_time()
    pickle.dump((A, B, shifts, 6), p.stdin); p.stdin.flush()
    lams, wcpu = pickle.load(p.stdout)
    rt = time.perf_counter() - t0
    print(f"complex SLEPc, 4 shifts: worker CPU {wcpu*1e3:.0f} ms, round trip wall {rt*1e3:.0f} ms, driver CPU {(time.process_time()-c0)*1e3:.0f} ms, {len(lams)} eigenvalues")
c0 = time.process_time(); r = hill._shift_invert(A, B, np.array(shifts, complex), 6); print(f"today's SuperLU+ARPACK 4 shifts: {(time.process_time()-c0)*1e3:.0f} ms")
T = 2*np.pi/w
mu = np.exp(lams*T); print("max |mu| among SLEPc's", np.abs(mu).max(), "Hill's physical", abs(c['mu'][0]))
p.stdin.close(); p.wait()
