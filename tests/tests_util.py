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


def spin_up_energy_balance(params, until_s: float, dt_s: float = 2e-3):
    """Spin ``params`` up from its stationary state at a fixed step ``dt_s`` (alpha2 with
    spectral radius 1, the trapezoidal rule) for ``until_s``: (E - E0, external work,
    non-variational work, dissipated energy, balance) in time (normalised, M g L0), the
    works by the trapezoidal rule; balance = E - E0 - W_ext - W_nv + W_diss.  External:
    the drag (Eq. 28) and the end torques (38)-(40), x beta/delta."""
    import dolfinx.fem
    import numpy as np
    import ufl
    from rawehelix.forms import rod as rod_forms
    from rawehelix.solvers.dynamics import DynamicsSolver
    solver = DynamicsSolver.from_stationary(params, options={"ts_alpha_radius": 1.0,
                                                             "ts_adapt_type": "none"})
    form, c = solver.form, solver.rod.c
    f = form.fields
    dx, _, ds = solver.rod.measures
    x = ufl.SpatialCoordinate(solver.rod.mesh)
    external = dolfinx.fem.form(
        ufl.inner(rod_forms.body_force(f.r_t, c) - c.gravity * ufl.as_vector((0.0, 0.0, 1.0)),
                  f.r_t) * dx
        + c.beta * (c.mN * x[0] - form.m0 * (1 - x[0])) * f.alpha_t * ds)
    dt = dt_s / solver.q.t_scale
    rows = []

    def out(sv):
        e = sv.energy()
        rows.append((e["kinetic"] + e["potential"], e["power_nv"], e["dissipation"],
                     dolfinx.fem.assemble_scalar(external)))
    solver.advance(until_s / solver.q.t_scale, on_output=out, output_every=dt)
    E, p_nv, p_d, p_ext = np.array(rows).T

    def work(p_):
        return np.concatenate([[0.0], np.cumsum(dt * (p_[1:] + p_[:-1]) / 2)])
    W_ext, W_nv, W_d = work(p_ext), work(p_nv), work(p_d)
    return E - E[0], W_ext, W_nv, W_d, E - E[0] - W_ext - W_nv + W_d
