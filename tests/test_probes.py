"""The point values a run records (solvers/probes.py): all of them by one Expression
at the cells' ends (PointValues, issue 46) against the scalar forms they replace."""

import numpy as np
import pytest
from mpi4py import MPI

import dolfinx.fem

from rawehelix.solvers.dynamics import DynamicsSolver
from rawehelix.studies import scene


def _point_values_against_forms(comm, scene_name, elements):
    params = scene.load(scene_name, elements=elements, degree=3)
    solver = DynamicsSolver.from_stationary(params, comm)
    rng = np.random.default_rng(3 + comm.rank)  # a state off the stationary one, U and V
    for f in (solver.form.u, solver.form.v):
        f.x.array[:] += 1e-2 * rng.standard_normal(f.x.array.size)
        f.x.scatter_forward()
    probes = solver.probes
    forms = {k: comm.allreduce(dolfinx.fem.assemble_scalar(f), op=MPI.SUM)
             for k, f in probes.forms.items()}
    values = probes.values()
    assert set(values) == set(forms)
    for k, v in forms.items():
        assert abs(values[k] - v) <= 1e-13 * max(1.0, abs(v)), k
    # a value the state moves: so the comparison is not of two zeros
    assert min(abs(forms["spin0"]), abs(forms["spin_mid"]), abs(forms["y_mid"])) > 1e-6


@pytest.mark.parametrize("scene_name, elements", [("mobile_end", 3), ("mobile_end", 8),
                                                  ("rotor_example", 4)])
def test_point_values_equal_the_forms(scene_name, elements):
    """Every point value (ends, the middle vertex: its dS average) equals its form's
    assembly to round-off (measured: 1.7e-14 relative at most) at a perturbed state,
    the paper's ends and the machine's end torques (m0's other form)."""
    _point_values_against_forms(MPI.COMM_SELF, scene_name, elements)


@pytest.mark.mpi
def test_point_values_equal_the_forms_on_two_ranks():
    """MPI: the cells at a point split between ranks (each its owned cells, the middle
    vertex's average by weights), summed: the forms' values on every rank."""
    if MPI.COMM_WORLD.size == 1:
        pytest.skip("run under mpirun -n 2")
    _point_values_against_forms(MPI.COMM_WORLD, "mobile_end", 8)


def test_section_and_fields_equal_function_interpolate():
    """The section's state and the fields by the C++ interpolation (compat's) equal
    dolfinx's Function.interpolate of the same expressions, bit for bit."""
    params = scene.load("mobile_end", elements=3, degree=3)
    solver = DynamicsSolver.from_stationary(params, MPI.COMM_SELF)
    solver.form.u.x.array[:] += 1e-2 * np.random.default_rng(4).standard_normal(solver.form.u.x.array.size)
    probes = solver.probes
    section, fields = probes.section(), probes.fields()
    sp = probes.section_probe
    sp._u.interpolate(sp._expr)
    assert np.array_equal(sp._u.x.array.reshape(-1, len(sp.names))[:, 4][np.argsort(
        sp._u.function_space.tabulate_dof_coordinates()[:, 0], kind="stable")], section["tension"])
    for name, (expr, u) in probes.field_exprs.items():
        u.interpolate(expr)
        s = u.function_space.tabulate_dof_coordinates()[:, 0]
        vals = u.x.array.reshape(s.size, -1)[np.argsort(s, kind="stable")]
        assert np.array_equal(vals if vals.shape[1] > 1 else vals[:, 0], fields[name]), name
    assert np.ptp(section["tension"]) > 0
