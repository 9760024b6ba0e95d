"""Complex-PETSc worker: reads pickled (A, B, sigma, k) CSR complex from stdin, answers eigenvalues."""
import pickle, sys, time
import numpy as np
import petsc4py; petsc4py.init()
from petsc4py import PETSc
from slepc4py import SLEPc
assert PETSc.ScalarType == np.complex128, PETSc.ScalarType
inp, out = sys.stdin.buffer, sys.stdout.buffer
while True:
    try:
        msg = pickle.load(inp)
    except EOFError:
        break
    A, B, shifts, k = msg
    c0 = time.process_time()
    mat = lambda S: PETSc.Mat().createAIJ(S.shape, csr=(S.indptr, S.indices, S.data.astype(complex)))
    PA, PB = mat(A), mat(B)
    lams = []
    for s in shifts:
        E = SLEPc.EPS().create(PETSc.COMM_SELF); E.setOperators(PA, PB)
        E.setProblemType(SLEPc.EPS.ProblemType.GNHEP); E.setDimensions(k)
        st = E.getST(); st.setType("sinvert"); st.setShift(s)
        ksp = st.getKSP(); ksp.setType("preonly"); ksp.getPC().setType("lu")
        ksp.getPC().setFactorSolverType("mumps")
        E.setTarget(s); E.setWhichEigenpairs(SLEPc.EPS.Which.TARGET_MAGNITUDE); E.setTolerances(1e-12)
        E.solve()
        lams += [E.getEigenvalue(i) for i in range(E.getConverged())]
    pickle.dump((np.array(lams), time.process_time() - c0), out); out.flush()
