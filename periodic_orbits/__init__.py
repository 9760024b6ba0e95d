"""Periodic orbits as a problem, separate from how a scheme steps the rod: the
problem interface (:mod:`.problem`, after BifurcationKit's
AbstractPeriodicOrbitProblem), the shooting Newton and the Floquet multipliers of
a period map (:mod:`.floquet`), pseudo-arclength continuation (:mod:`.continuation`),
bifurcation location (:mod:`.bifurcations`) and the step guards that close in on
resonances (:mod:`.resonances`).  numpy and scipy only: the FE period map
(rawehelix.solvers.orbits) and the spline reference's
(rawehelix.references.spline_galerkin.orbits) both implement the problem, and the
references may import this room (tests/test_architecture.py)."""
