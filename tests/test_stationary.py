"""Rung 2 of the verification ladder: the FE stationary state against shooting (Sec. 5.1).

Also the Jacobian (a Taylor test, and one Newton step on a linear problem),
and the same solution on 1 and 2 MPI ranks."""

import numpy as np
import pytest
import ufl
import dolfinx.fem
import dolfinx.fem.petsc
from mpi4py import MPI

from rawehelix import compat
from rawehelix.references import shooting
from rawehelix.solvers.snes import NewtonSolver
from rawehelix.solvers.stationary import StationarySolver
from rawehelix.studies import scene

ELEMENTS = (2, 4, 8, 16)


def table2(N, p=3, **model):
    params = scene.load("stationary_table2", elements=N, degree=p)
    return params.replace(model=model) if model else params


@pytest.fixture(scope="module")
def reference():
    return shooting.solve(table2(2).normalised())


def fe_error(N, p, reference):
    solver = StationarySolver(table2(N, p), MPI.COMM_SELF)
    res = solver.solve()
    return np.max(np.linalg.norm(res.centre_line - reference.centre_line(res.s), axis=1)), res


@pytest.mark.parametrize("p,rate", [(2, 1.8), (3, 3.5), (4, 3.5)])
def test_fe_approaches_shooting(reference, p, rate):
    """max |r_FE - r_shooting| at the nodes falls at least like h^rate
    (observed: see the note of the foundation issue)."""
    errors = np.array([fe_error(N, p, reference)[0] for N in ELEMENTS])
    rates = np.log2(errors[:-1] / errors[1:])
    assert errors[-1] < 1e-5
    assert np.all(rates > rate), (errors, rates)


def test_tension_table2(reference):
    """T(0) is about 200 N and agrees with shooting to 0.1 %."""
    q = table2(16).normalised()
    _, res = fe_error(16, 3, reference)
    T0_fe, T0_ref = q.tension_N(res.tension[0]), q.tension_N(reference.tension(0.0))
    assert T0_fe == pytest.approx(200.0, rel=0.03)
    assert T0_fe == pytest.approx(T0_ref, rel=1e-3)
    assert q.tension_N(res.tension[-1]) == pytest.approx(q.tension_N(reference.tension(1.0)), rel=1e-3)


@pytest.mark.parametrize("p,rate", [(3, 0.35), (4, 0.8)])
def test_residual_at_shooting_falls(reference, p, rate):
    """The FE residual of the shooting solution falls as N grows (paper Sec. 5.1).

    It is the l2 norm of the assembled residual at the interpolant of the
    shooting centre line.  The interior-penalty terms see the jumps of the
    interpolant's slope, O(h^p), with a weight mu p^2/h^2, so the norm falls
    slowly: observed log2 ratios 0.44-0.49 for p = 3 and 1.0-1.9 for p = 4
    (N = 2 ... 64).  For p = 2 it does not fall between N = 2 and 4."""
    norms = []
    for N in ELEMENTS:
        solver = StationarySolver(table2(N, p), MPI.COMM_SELF)
        norms.append(solver.residual_at(reference.centre_line))
    norms = np.array(norms)
    rates = np.log2(norms[:-1] / norms[1:])
    assert np.all(rates > rate), (norms, rates)


def test_jacobian_taylor():
    """|F(u + e du) - F(u) - e J du| = O(e^2) at a generic 3D, twisted state with
    gamma coupling, drag and torques on: the Jacobian is the derivative of F."""
    solver = StationarySolver(table2(6, 3, gamma_eps=0.05), MPI.COMM_SELF)
    rod = solver.rod
    rod.c.m0.value, rod.c.mN.value = 0.3, 0.5
    w = rod.w
    w.sub(0).interpolate(lambda x: np.array([-0.7 * x[0] + 0.05 * np.sin(3 * x[0]),
                                             0.04 * np.sin(2 * np.pi * x[0]) + 0.03 * x[0] ** 3,
                                             -0.7 * x[0] + 0.02 * np.cos(5 * x[0])]))
    w.sub(1).interpolate(lambda x: 0.3 * np.sin(2 * x[0]))
    u0 = compat.petsc_vec(w).copy()
    rng = np.random.default_rng(1)
    du = u0.duplicate()
    du.array[:] = rng.standard_normal(du.array.size) * 1e-2
    F_form, J_form = dolfinx.fem.form(solver.F), dolfinx.fem.form(ufl.derivative(solver.F, w))

    def F_at(x):
        x.copy(compat.petsc_vec(w))
        w.x.scatter_forward()
        return dolfinx.fem.petsc.assemble_vector(F_form)

    F0 = F_at(u0)
    u0.copy(compat.petsc_vec(w))
    w.x.scatter_forward()
    J = dolfinx.fem.petsc.assemble_matrix(J_form)
    J.assemble()
    Jdu = J.createVecLeft()
    J.mult(du, Jdu)
    remainders = []
    for e in (1e-2, 5e-3, 2.5e-3, 1.25e-3):
        x = u0.copy()
        x.axpy(e, du)
        r = F_at(x) - F0
        r.axpy(-e, Jdu)
        remainders.append(r.norm())
    rates = np.log2(np.array(remainders[:-1]) / np.array(remainders[1:]))
    assert np.all(rates > 1.9), (remainders, rates)


def test_linear_problem_converges_in_one_newton_step():
    """Centre line fixed everywhere, end torques m0 = mN = m: the twist equation
    (31) is linear, alpha = m s, and Newton must converge in one step."""
    params = table2(8, 3, gamma="off")
    solver = StationarySolver(params, MPI.COMM_SELF)
    rod = solver.rod
    m = 0.4
    rod.c.m0.value = rod.c.mN.value = m
    rod.set_chord()
    V_r = rod.V_r
    r_all = dolfinx.fem.Function(V_r)
    r_all.interpolate(lambda x: np.outer(rod.q.top_position(), x[0]))
    dofs = dolfinx.fem.locate_dofs_geometrical((rod.W.sub(0), V_r), lambda x: np.full(x.shape[1], True))
    bcs = [dolfinx.fem.dirichletbc(r_all, dofs, rod.W.sub(0)), rod.bcs[-1]]
    newton = NewtonSolver(solver.F, rod.w, bcs, prefix="linear_test_",
                          options={"snes_rtol": 1e-12, "snes_atol": 1e-11, "snes_stol": 0.0})
    its = newton.solve("linear twist problem")
    assert its == 1
    alpha = rod.w.sub(1).collapse()
    alpha = alpha[0] if isinstance(alpha, tuple) else alpha
    s = alpha.function_space.tabulate_dof_coordinates()[:, 0]
    assert np.allclose(alpha.x.array, m * s, atol=1e-10)


@pytest.mark.mpi
@pytest.mark.parametrize("N,p", [(16, 3), (33, 2)])
def test_same_on_one_and_two_ranks(N, p):
    """The distributed solution equals a serial one (COMM_SELF on each rank)."""
    params = table2(N, p)
    serial = StationarySolver(params, MPI.COMM_SELF).solve()
    world = StationarySolver(params, MPI.COMM_WORLD).solve()
    if MPI.COMM_WORLD.rank == 0:
        assert np.allclose(serial.s, world.s)
        assert np.max(np.abs(serial.centre_line - world.centre_line)) < 1e-10
        assert np.max(np.abs(serial.tension - world.tension)) < 1e-6


def test_slack_is_detected():
    """A vertical helix whose pre-tension EA eps0 (0.7 N) is less than its weight
    (5 N) is compressed at the bottom: a SlackError, not a silent answer."""
    from rawehelix.solvers.stationary import SlackError
    params = table2(16).replace(ends={"elevation_deg": 90.0, "elongation": 2e-5},
                                model={"drag": False})
    with pytest.raises(SlackError, match="slack"):
        StationarySolver(params, MPI.COMM_SELF).solve()


@pytest.mark.parametrize("N,kinematics", [(8, "paper"), (64, "paper"), (8, "extensible")])
def test_planar_reduction_is_exact(N, kinematics):
    """The reduced (x, z) model of a planar, torque-free scene gives the full
    model's stationary state to round-off (with either kinematics)."""
    full = StationarySolver(table2(N, kinematics=kinematics), MPI.COMM_SELF).solve()
    planar = StationarySolver(table2(N, kinematics=kinematics), MPI.COMM_SELF, planar=True).solve()
    assert np.max(np.abs(full.centre_line - planar.centre_line)) < 1e-10
    assert np.max(np.abs(full.tension - planar.tension)) < 1e-7


@pytest.mark.long  # 7 s: make test's budget (2026-12-05); the model's line is also read by
# test_stationary_torque.py and the faults' stationary rows in make test
def test_stationary_command_says_which_model(tmp_path):
    from rawehelix.studies import stationary
    s = stationary.compute(table2(8), MPI.COMM_SELF).summary
    assert s["model"].startswith("planar")
    s = stationary.compute(table2(8).replace(model={"reduction": "off"}), MPI.COMM_SELF).summary
    assert s["model"] == "full (r, alpha); terms: gravity, drag, bending; kinematics: paper"
    s = stationary.compute(table2(8).replace(model={"reduction": "off", "twist": False,
                                                    "drag": False}), MPI.COMM_SELF).summary
    assert s["model"].startswith("centre line only (model.twist = false")
    assert s["model"].endswith("terms: gravity, bending; kinematics: paper")
    s = stationary.compute(table2(8).replace(model={"kinematics": "extensible"}),
                           MPI.COMM_SELF).summary
    assert s["model"].startswith("planar") and s["model"].endswith("kinematics: extensible")


def test_solver_defaults_do_not_leak_into_the_options_database():
    """Each solver sets its PETSc defaults for its own set-up only: the global
    options database is the same before and after (the first solver of a
    process used to fix the Newton tolerance and LU of every later one)."""
    from petsc4py import PETSc

    from rawehelix.solvers.dynamics import DynamicsSolver
    from rawehelix.solvers.modal import ModalSolver

    before = PETSc.Options().getAll()
    StationarySolver(table2(4), MPI.COMM_SELF).solve()
    DynamicsSolver.from_stationary(scene.load("nominal_operation", elements=4), MPI.COMM_SELF,
                                   options={"ts_type": "cn"})
    ModalSolver.from_stationary(table2(4), MPI.COMM_SELF).solve(nev=6)
    assert PETSc.Options().getAll() == before
