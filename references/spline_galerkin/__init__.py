"""The paper's spline-Galerkin scheme (Sec. 3, Appendix A): numpy/scipy reference.

Shares no code with the FEniCSx path; only the scene and parameter objects.

basis       shape functions (43)-(45), continuity relations (A1)-(A6)
matrices    P0, P4, Q0, Q1 and the vectors of Eqs. (50)-(58)
system      state (59)-(60) and M xdot = g(x, t), Eq. (61), with Eqs. (40), (69)
stationary  Newton on f(x_s) = 0 (Sec. 5.1)
spectrum    Jacobian, eigenvalues and mode families (Table 3)
dynamics    solve_ivp time series in SI (Sec. 5.2)
"""
