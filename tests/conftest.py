"""Shared fixtures.  JIT-compiler chatter is silenced; PETSc is initialised
without command-line options so that pytest's own flags do not reach it."""

import logging

import petsc4py

petsc4py.init([])
logging.getLogger().setLevel(logging.WARNING)

import pytest  # noqa: E402
from mpi4py import MPI  # noqa: E402

SCENES = ("stationary_table2", "nominal_operation", "mobile_end")


@pytest.fixture
def comm():
    return MPI.COMM_WORLD


def pytest_collection_modifyitems(config, items):
    """Under mpirun only the tests marked `mpi` run (make test selects them with -m mpi)."""
    if MPI.COMM_WORLD.size > 1:
        skip = pytest.mark.skip(reason="runs serially only")
        for item in items:
            if "mpi" not in item.keywords:
                item.add_marker(skip)
