"""The tensegrity as a network of rigid rings and tension-only tethers (issue 45): a
third reference, independent of the continuum's homogenised section.

* :mod:`.network`: the network built from a scene's ``[section]`` (rings, tethers,
  bars, masses, loads, ends);
* :mod:`.energy`: its potential energy, gradient and analytic sparse Hessian;
* :mod:`.stationary`: Newton with a backtracking line search on the energy;
* :mod:`.modes`: the stiffness and lumped mass at a stationary state, scipy's eigh;
* :mod:`.dynamics`: the rings in time, a symplectic Strang splitting, the ends of
  Eqs. (40), (69) and (70);
* :mod:`.forced`: the sweep's backend (solvers/periodic.py's protocol).

numpy and scipy only: the import contract (.importlinter) forbids the FE path.
"""

from rawehelix.references.network.network import Network, NetworkError, Ring
from rawehelix.references.network.stationary import StationaryNetwork, solve

__all__ = ["Network", "NetworkError", "Ring", "StationaryNetwork", "solve"]
