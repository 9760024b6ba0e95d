"""Physics post-processing of the drivers' results: the structure's limits at a state
(`structure_limits`) and along a branch (`branch_limits`), time-series metrics, the
envelope curves, and the lab test's fit (`labfit`, `labmembers`).  Imports nothing
else of studies/."""
