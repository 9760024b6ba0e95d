"""Helpers for the tests (not a test module)."""

import tomllib
from pathlib import Path

import pytest

from rawehelix.studies import scene


def _toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return f'"{v}"'
    return repr(v)


def write_scene(path, changes: dict, base: dict | None = None, name="stationary_table2"):
    """Write the shipped scene ``name`` (or ``base``) with ``changes`` applied."""
    data = base if base is not None else tomllib.loads(scene.resolve(name).read_text())
    for section, values in changes.items():
        data.setdefault(section, {}).update(values)
    lines = []
    for key, value in data.items():
        if not isinstance(value, dict):
            lines.append(f"{key} = {_toml_value(value)}")
    for section, values in data.items():
        if isinstance(values, dict):
            lines.append(f"[{section}]")
            lines += [f"{k} = {_toml_value(v)}" for k, v in values.items()]
    path.write_text("\n".join(lines) + "\n")
    return path


def assert_same_on_one_and_two_ranks(params):
    """The stationary state and the spectrum of ``params`` on MPI.COMM_WORLD equal
    the serial ones (COMM_SELF on each rank): state to 1e-10, tension to 1e-7
    of its maximum (T = sigma (|r'| - 1), sigma ~ 7e3), eigenvalues to 1e-8."""
    import numpy as np
    from mpi4py import MPI

    from rawehelix.solvers.modal import ModalSolver
    from rawehelix.solvers.stationary import StationarySolver

    serial = StationarySolver(params, MPI.COMM_SELF).solve()
    world = StationarySolver(params, MPI.COMM_WORLD).solve()
    lam = [[abs(m.eigenvalue) for m in ModalSolver.from_stationary(params, comm).solve()][:8]
           for comm in (MPI.COMM_SELF, MPI.COMM_WORLD)]
    if MPI.COMM_WORLD.rank == 0:
        assert np.max(np.abs(serial.centre_line - world.centre_line)) < 1e-10
        # the tension is a DG field: its two values at a node (one per cell) may come in
        # either order from a gather over ranks, so compare them sorted within each node
        T1, T2 = (x.tension[np.lexsort((x.tension, x.s_tension))] for x in (serial, world))
        assert np.max(np.abs(T1 - T2)) < 1e-7 * np.max(serial.tension)
        assert np.allclose(lam[0][1:], lam[1][1:], rtol=1e-8)  # [0]: the rigid rotation


def residual_and_energy_derivative(params, extra=None):
    """(F(w; v), central difference d/dh U(w + h v), extra(rod, v)) at a bent,
    stretched state w (alpha = 0) of ``params`` (serial), for a centre-line
    direction v, U the potential of forms/energy.py; ``extra`` (optional)
    returns a UFL form assembled at w."""
    import numpy as np
    import ufl
    import dolfinx.fem
    from mpi4py import MPI

    from rawehelix.forms import energy
    from rawehelix.solvers.discrete import RodDiscretisation

    rod = RodDiscretisation(params, MPI.COMM_SELF)
    rod.set_centre_line(lambda s: np.column_stack([-0.8 * s + 0.05 * np.sin(3 * s),
                                                   0.03 * s**2 * (1 - s), -0.75 * s]))
    direction = dolfinx.fem.Function(rod.W)
    direction.sub(0).interpolate(lambda x: np.vstack([np.sin(2 * x[0]), x[0]**2, np.cos(x[0])]))
    F = dolfinx.fem.form(ufl.replace(rod.stationary_residual(), {rod.test: direction}))
    r, alpha = ufl.split(rod.w)[:2]
    U = dolfinx.fem.form(energy.potential(r, alpha, rod.c, rod.degree, rod.penalty, rod.measures))
    more = None if extra is None else dolfinx.fem.assemble_scalar(
        dolfinx.fem.form(extra(rod, ufl.split(direction)[0])))
    w0 = rod.w.x.array.copy()
    h, values = 1e-5, []
    for sign in (1, -1):
        rod.w.x.array[:] = w0 + sign * h * direction.x.array
        values.append(dolfinx.fem.assemble_scalar(U))
    rod.w.x.array[:] = w0
    return dolfinx.fem.assemble_scalar(F), (values[0] - values[1]) / (2 * h), more


def world_folder(tmp_path_factory, name: str,
                 why: str = "compares 1 and 2 ranks: run under mpirun -n 2"):
    """(COMM_WORLD, a fresh folder of rank 0's that every rank is given): for the
    tests marked ``mpi`` that need two ranks; skipped (``why``) on one."""
    from mpi4py import MPI
    comm = MPI.COMM_WORLD
    if comm.size == 1:
        pytest.skip(why)
    return comm, Path(comm.bcast(str(tmp_path_factory.mktemp(name)) if comm.rank == 0 else None))
