"""Boundary values as expressions in x, y, z, t (``peridyn.physics.expressions.SpaceTime``) and
Peridigm's reported velocity of prescribed points (``ExplicitSolver(prescribed_velocity=
"difference")``)."""

import numpy as np
import pytest
from conftest import STEEL_E, STEEL_NU, STEEL_RHO

from peridyn.discretization import geometry
from peridyn.discretization.bonds import find_bonds
from peridyn.errors import InputError
from peridyn.physics.expressions import SpaceTime
from peridyn.physics.loads import BoundaryCondition, Loading
from peridyn.physics.materials import make_model
from peridyn.solvers import ExplicitSolver


@pytest.mark.bitwise
def test_expression_is_evaluated_per_point_and_time():
    """An expression in x, y, z and t is evaluated per point with NumPy, in the written order: the same
    operations as written here, so the same bits (NumPy's elementwise arithmetic and sqrt are correctly
    rounded on every CPU)."""
    points = np.array([[0.0, 2.0, 0.0], [1.0, -1.0, 3.0]])
    np.testing.assert_array_equal(
        SpaceTime("0.001*y*t/1.0e-8").at(points, 2e-9), 0.001 * points[:, 1] * 2e-9 / 1e-8
    )
    np.testing.assert_array_equal(SpaceTime("sqrt(x) + max(z, 1)").at(points, 0.0), [1.0, 4.0])
    np.testing.assert_array_equal(SpaceTime("2.5").at(points, 0.0), [2.5, 2.5])


@pytest.mark.parametrize("text", ["__import__('os')", "x.real", "q * 2", "lambda: 1", "1/x"])
def test_expression_outside_the_language_is_refused(text):
    with pytest.raises(InputError, match="expression"):
        SpaceTime(text).at(np.zeros((2, 3)), 0.0)


def _bar(prescribed_velocity):
    body = geometry.box((6e-3, 2e-3, 2e-3), 1e-3)
    body = body.with_node_set("left", body.points[:, 0] < 1e-3)
    model = make_model("lps", body, find_bonds(body, 2.015e-3), E=STEEL_E, nu=STEEL_NU, density=STEEL_RHO)
    bc = BoundaryCondition("left", "displacement", "xy", SpaceTime("1e-6 * (1 + y / 1e-3) * t / 1e-6"))
    solver = ExplicitSolver(model, Loading(body, [bc]), dt=2e-8, prescribed_velocity=prescribed_velocity)
    return body, model, solver


def test_prescribed_expression_moves_the_set():
    body, _, solver = _bar("rate")
    state = solver.initial_state()
    for _ in range(5):
        solver.step(state)
    left = body.node_set("left")
    expected = 1e-6 * (1 + body.points[left, 1] / 1e-3) * state.time / 1e-6
    np.testing.assert_allclose(state.u[left, 0], expected, rtol=1e-15)
    np.testing.assert_allclose(state.u[left, 1], expected, rtol=1e-15)


@pytest.mark.bitwise
def test_difference_velocity_is_peridigms_and_leaves_the_motion():
    """The motion is the same bit for bit; the prescribed DOFs report (u(n+1) - u(n)) / dt +
    dt/2 a with a the force acceleration f / rho (README of tests/data/peridigm), 0 at t = 0. Bit for
    bit: the reported velocity of the prescribed DOFs does not enter the motion, which is computed by
    the same operations in the same order, and the kernels are compiled without value-changing fast-math
    flags (``peridyn.kernels.FASTMATH``), so this holds on every CPU."""
    body, model, rate = _bar("rate")
    _, _, difference = _bar("difference")
    a, b = rate.initial_state(), difference.initial_state()
    left = body.node_set("left")
    assert np.all(b.v[left] == 0) and np.all(a.v[left, :2] != 0)
    dt = difference.dt
    for _ in range(6):
        u_before = b.u.copy()
        rate.step(a)
        difference.step(b)
        np.testing.assert_array_equal(b.u, a.u)
        free = np.setdiff1d(np.arange(body.n_points), left)
        np.testing.assert_array_equal(b.v[free], a.v[free])
        force_acceleration = model.force(b.u)[left, :2] / model.density[left, None]
        expected = (b.u[left, :2] - u_before[left, :2]) / dt + 0.5 * dt * force_acceleration
        np.testing.assert_allclose(b.v[left, :2], expected, rtol=1e-12, atol=0)
