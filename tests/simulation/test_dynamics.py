"""Explicit dynamics: energy conservation, stable step, restart, wave speeds."""

import numpy as np
import pytest
from conftest import STEEL_E, STEEL_NU, STEEL_RHO
from scipy.sparse.linalg import LinearOperator, eigsh

from peridyn.discretization import geometry
from peridyn.discretization.bonds import find_bonds
from peridyn.physics.loads import InitialCondition, Loading
from peridyn.physics.materials import make_model
from peridyn.solvers import ExplicitSolver


def _bar_model(name, n=(12, 4, 4), h=1e-3, horizon=2.015, **kw):
    body = geometry.box(tuple(k * h for k in n), h)
    body = body.with_node_set("all", np.ones(body.n_points, dtype=bool))
    bonds = find_bonds(body, horizon * h, **kw)
    return make_model(name, body, bonds, E=STEEL_E, nu=0.25 if name == "pmb" else STEEL_NU, density=STEEL_RHO)


def _energy_error(model, fraction: float, n_steps: int = 5000) -> float:
    """Largest relative error of kinetic + strain energy over ``n_steps`` steps of a free
    vibration started from the first axial mode shape as velocity."""
    x = model.body.points
    length = x[:, 0].max() + x[:, 0].min()
    v0 = 0.1 * np.sin(np.pi * x[:, 0] / length)  # m/s
    loading = Loading(model.body, initial=[InitialCondition("all", "velocity", "x", v0)])
    solver = ExplicitSolver(model, loading, dt=fraction * model.critical_time_step())
    state = solver.initial_state()
    e0 = solver.kinetic_energy(state)
    errors = []
    for _ in range(n_steps // 100):
        solver.run(state, 100)
        errors.append(abs(solver.kinetic_energy(state) + model.strain_energy(state.u) - e0) / e0)
    return max(errors)


@pytest.mark.parametrize("name", ["pmb", "lps"])
def test_energy_is_conserved_over_5000_steps(name):
    """Undamped velocity Verlet keeps kinetic + strain energy to 1e-4 over 5000 steps at
    a tenth of the stable step, and the error falls as dt^2 (second-order integrator)."""
    model = _bar_model(name)
    coarse = _energy_error(model, 0.2)
    fine = _energy_error(model, 0.1)
    assert fine < 1e-4, f"relative energy error {fine:.2e}"
    order = np.log2(coarse / fine)
    assert 1.8 < order < 2.2, f"observed order {order:.2f}"


@pytest.mark.parametrize("name", ["pmb", "lps"])
def test_stable_step_bounds_the_highest_frequency(name):
    """The Gershgorin step is below 2 / omega_max of the linearised model (omega_max by Lanczos)."""
    model = _bar_model(name, n=(6, 5, 4), horizon=3.015)
    n = model.body.n_points
    eps = 1e-9

    def matvec(v):
        u = eps * v.reshape(n, 3)
        return (-model.force(u) / model.density[:, None]).ravel() / eps

    op = LinearOperator((3 * n, 3 * n), matvec=matvec, dtype=float)
    lam_max = eigsh(op, k=1, which="LA", tol=1e-8, return_eigenvectors=False)[0]
    exact = 2.0 / np.sqrt(lam_max)
    bound = model.critical_time_step()
    assert bound <= exact
    assert bound > 0.2 * exact  # and not uselessly small


def test_too_large_step_blows_up_and_is_reported():
    from peridyn.errors import InstabilityError

    model = _bar_model("pmb", n=(6, 4, 4))
    body = model.body
    rng = np.random.default_rng(1)
    loading = Loading(
        body,
        initial=[
            InitialCondition("all", "displacement", "xyz", 1e-9 * rng.standard_normal((body.n_points, 3)))
        ],
    )
    solver = ExplicitSolver(model, loading)
    solver.dt = 3.0 * solver.stable_dt  # bypass the check on purpose
    with pytest.raises(InstabilityError, match="unstable at step"):
        solver.run(solver.initial_state(), 2000)


def test_mass_proportional_damping_decays_energy_at_its_rate():
    """rho u'' = f - rho c u': every elastic mode's energy decays as exp(-c t) (c << omega).

    The start is the first free-free axial mode shape cos(pi x / L), which carries no net
    momentum (a rigid translation would lose its energy twice as fast: all kinetic)."""
    model = _bar_model("lps")
    x = model.body.points
    length = x[:, 0].max() + x[:, 0].min()
    v0 = 0.1 * np.cos(np.pi * x[:, 0] / length)
    loading = Loading(model.body, initial=[InitialCondition("all", "velocity", "x", v0)])
    c = 2e4  # 1/s, small against the first axial mode (~1e6 rad/s)
    solver = ExplicitSolver(model, loading, dt=0.2 * model.critical_time_step(), damping=c)
    state = solver.initial_state()
    e0 = solver.kinetic_energy(state)
    # average the energy over the last few hundred steps to smooth the exchange between
    # kinetic and strain energy (the mode's period is about 200 steps)
    n_steps = 4000
    solver.run(state, n_steps - 400)
    energies, times = [], []
    for _ in range(400):
        solver.step(state)
        energies.append(solver.kinetic_energy(state) + model.strain_energy(state.u))
        times.append(state.time)
    expected = np.exp(-c * np.array(times))
    assert np.mean(energies) / e0 == pytest.approx(np.mean(expected), rel=0.03)
