"""Harmonic balance, in one room: periodic orbits of the forced FE rod (Sec. 5.3,
Eq. 70) as Fourier coefficients, with Floquet stability by Hill's method.

- :mod:`.scope`: where harmonic balance can run and where it is the wrong tool, and
  the size of its unknown (parameters only: the orbit-method registry asks it);
- :mod:`.harmonics`: the real Fourier basis and its AFT evaluation (numpy, scipy);
- :mod:`.hill`: Hill's method for the Floquet exponents (numpy, scipy);
- :mod:`.sparse_lu`: PETSc's sparse LU of the Newton and continuation matrices;
- :mod:`.newton`: the damped Newton at fixed f1 and H;
- :mod:`.problem`: :class:`~.problem.HarmonicBalance`, the periodic-orbit problem
  (rawehelix.periodic_orbits.problem) on the FE rod's operator.

studies/orbit_method.py registers it as ``--method hb``; nothing is imported here,
so the numpy modules load without DOLFINx."""
