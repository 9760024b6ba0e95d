"""The paper's own schemes, kept as independent references of the FE solver:
the shooting of the stationary boundary-value problem (:mod:`.shooting`) and the
spline-Galerkin scheme (:mod:`.spline_galerkin`); and the tensegrity as a network of
rigid rings and tension-only tethers (:mod:`.network`), the discrete helix that the
continuum's section homogenises.  They import no FE code
(dolfinx, ufl, petsc4py, rawehelix.forms, rawehelix.solvers): the import
contracts in tests/test_architecture.py say so."""
