"""`rawehelix converge`: refinement studies and work-precision figures.

For one quantity of interest, runs every method over its refinement ladder
(elements N for the space discretisations, time step dt for the time
integrators), and records for each run the value, the error, the observed
order and the wall time.

Error: relative to the **finest run of the reference method** (the most
accurate one: FE with the highest degree at the largest N for stationary and
modal quantities), not a Richardson extrapolation; the reference's own
distance to an independent reference (shooting, where one exists) is printed
so that the floor of the table is known.  For a vector of values (the lowest
eigenvalue of each family) the error is the largest relative error.

Under ``mpirun -n k`` the runs are dealt round-robin to the ranks, each on
its own communicator; rank 0 gathers and writes ``converge.csv``,
``converge.md``, ``work_precision.png`` and ``summary.json``.

Modules, one job each:

- :mod:`.methods`: the methods, one run of a method, the ladders (the quantities
  by name are in the one registry :mod:`rawehelix.studies.quantities`, which
  gives :func:`.study.run` the quantity; this room never imports it);
- :mod:`.quantity`: what a named quantity is (:class:`~.quantity.Quantity`);
- :mod:`.study`: the loop over the ladders, errors and observed orders;
- :mod:`.cache`: finished (and failed) runs in ``DIR/runs/``, for resuming;
- :mod:`.report`: ``converge.csv``, ``converge.md``, ``work_precision.png``.

The package imports only :mod:`.methods` (light: no PETSc), which the one
registry of quantities imports; the study is :func:`.study.run`.
"""

from rawehelix.studies.converge.methods import Method, Refinement

__all__ = ["Method", "Refinement"]
