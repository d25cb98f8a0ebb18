"""Implicit Newmark dynamics against explicit velocity Verlet, and its energy conservation."""

import numpy as np
import pytest

from peridyn.discretization import geometry
from peridyn.discretization.bonds import find_bonds
from peridyn.errors import InputError
from peridyn.linalg.tangent import tangent_stiffness
from peridyn.physics.damage import BondDamage
from peridyn.physics.loads import BoundaryCondition, InitialCondition, Loading
from peridyn.physics.materials import make_model
from peridyn.physics.timefunctions import Ramp, ToneBurst
from peridyn.solvers import ExplicitSolver
from peridyn.solvers.newmark import NewmarkSolver


def _strip():
    """An 80 x 4 mm PMB strip (2D plane stress, h = 1 mm) whose left edge moves along x by a
    1.5-cycle 100 kHz tone burst of 1 um; sensor at x = 40 mm on the centre line."""
    h = 1e-3
    body = geometry.rectangle(0.080, 0.004, h, thickness=h)
    body = body.with_node_set("left", geometry.face(body, "x-"))
    model = make_model("pmb", body, find_bonds(body, 3.015 * h), E=200e9, density=7850.0, nu=1 / 3)
    loading = Loading(body, [BoundaryCondition("left", "displacement", "x", ToneBurst(100e3, 1.5, 1e-6))])
    sensor = int(np.argmin(np.linalg.norm(body.points[:, :2] - [0.040, 0.0015], axis=1)))
    return model, loading, sensor


def _peak(solver, sensor, duration=22e-6):
    """Largest |u_x| at the sensor over ``duration`` (before the far-end echo arrives)."""
    state = solver.initial_state()
    peak = 0.0
    for _ in range(int(round(duration / solver.dt))):
        solver.step(state)
        peak = max(peak, abs(state.u[sensor, 0]))
    return peak


def test_newmark_matches_explicit_on_a_wave():
    """The burst's peak at the sensor from Newmark (Newton to 1e-13 m) agrees with velocity
    Verlet at 0.8 of the stable step within 1%, both at that same step and at the full
    explicit stable step (measured: -0.06% and -0.28% of the explicit peak; against an explicit
    run at dt/8 on a 6 mm wide strip: Newmark -0.04% and -0.10%, explicit -0.07%; the two
    schemes' phase errors are (omega dt)^2 / 12 and / 24)."""
    model, loading, sensor = _strip()
    explicit = ExplicitSolver(model, loading)
    reference = _peak(explicit, sensor)
    for dt in (explicit.dt, explicit.stable_dt):
        implicit = NewmarkSolver(model, loading, dt=dt, tolerance=1e-13)
        peak = _peak(implicit, sensor)
        print(f"dt = {dt:.4g} s: Newmark / explicit peak - 1 = {peak / reference - 1:.2e}")
        assert peak == pytest.approx(reference, rel=0.01)


def test_newmark_conserves_energy_of_a_linear_vibration():
    """Average acceleration conserves (v^T M v + u^T K u) / 2 exactly for a linear system,
    at any step. A free 8 x 8 PMB square set vibrating by a random initial velocity of
    1 mm/s without rigid-body part (strains ~1e-7, so the kernel is linear to ~1e-7) is
    integrated 60 steps at 10 times the explicit stable step (which velocity Verlet refuses):
    the total energy, with the strain energy u^T K u / 2 of the tangent at rest, stays within
    1e-6 of its initial value (measured 7e-8)."""
    h = 1e-3
    body = geometry.rectangle(0.008, 0.008, h, thickness=h)
    body = body.with_node_set("all", np.ones(body.n_points, dtype=bool))
    model = make_model("pmb", body, find_bonds(body, 3.015 * h), E=200e9, density=7850.0, nu=1 / 3)
    v0 = 1e-3 * np.random.default_rng(7).standard_normal((body.n_points, 2))
    v0 -= v0.mean(axis=0)  # no rigid translation or rotation: a finite rotation is nonlinear
    r = body.points[:, :2] - body.points[:, :2].mean(axis=0)
    spin = np.sum(r[:, 0] * v0[:, 1] - r[:, 1] * v0[:, 0]) / np.sum(r * r)
    v0 -= spin * np.stack([-r[:, 1], r[:, 0]], axis=1)
    loading = Loading(body, initial=[InitialCondition("all", "velocity", "xy", v0)])
    solver = NewmarkSolver(model, loading, dt=10 * model.critical_time_step(), tolerance=1e-18)
    k = tangent_stiffness(model, np.zeros((body.n_points, 3)))
    state = solver.initial_state()

    def energy():
        u = state.u.ravel()
        return solver.kinetic_energy(state) + 0.5 * u @ (k @ u)

    e0 = energy()
    drift = []
    for _ in range(60):
        solver.step(state)
        drift.append(energy() / e0 - 1)
    print("largest relative energy change", np.max(np.abs(drift)))
    assert np.max(np.abs(state.u)) > 1e-10  # it did move
    assert np.max(np.abs(drift)) < 1e-6


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"dt": -1e-8}, "time step must be positive"),
        ({"tolerance": 0.0}, "displacement tolerance must be positive"),
        ({"max_iterations": 0}, "max_iterations must be a positive integer"),
        ({"damping": -1.0}, "damping must be non-negative"),
        ({"linear_solver": "lsu"}, "unknown linear solver 'lsu' \\(did you mean 'lu'\\?\\)"),
    ],
)
def test_newmark_bad_input(kwargs, message):
    """Bad arguments raise InputError naming the argument."""
    model, loading, _ = _strip()
    with pytest.raises(InputError, match=message):
        NewmarkSolver(model, loading, **kwargs)


def test_newmark_reports_a_step_that_does_not_converge():
    """One Newton iteration cannot meet a 1e-30 m increment tolerance: the error names the
    step and the increment."""
    model, loading, _ = _strip()
    solver = NewmarkSolver(model, loading, dt=1e-7, tolerance=1e-30, max_iterations=1)
    state = solver.initial_state()
    with pytest.raises(InputError, match=r"Newmark step 1 .* did not converge in 1 Newton"):
        for _ in range(30):
            solver.step(state)


def test_newmark_cg_and_lu_agree():
    """The two linear solvers give the same steps: 12 steps of the wave case at twice the
    stable step agree to 1e-8 of the largest displacement (CG stops at 1e-12 relative)."""
    model, loading, _ = _strip()
    states = []
    for method in ("lu", "cg"):
        solver = NewmarkSolver(
            model, loading, dt=2 * model.critical_time_step(), tolerance=1e-14, linear_solver=method
        )
        states.append(solver.run(solver.initial_state(), 12))
    scale = np.abs(states[0].u).max()
    assert scale > 0 and np.abs(states[1].u - states[0].u).max() < 1e-8 * scale


def test_newmark_breaks_the_same_bonds_as_explicit():
    """A 30 x 4 mm PMB strip pulled at both ends (ramps to +-30 um over 10 us, critical stretch
    1e-3, damage off within 4.5 mm of the ends): at the same dt, Newmark and velocity Verlet
    break their first bonds at the same step, and the same ones (measured: step 20, 112
    directed bonds, where the two waves from the ends meet). Later counts differ by ~10%
    (396 and 436 at 12 us): once bonds break, the fracture amplifies the schemes' O(dt^2)
    differences, so only the onset is compared. Bond indices, compared exactly: the two schemes differ
    by O(dt^2), far more than rounding, and still break the same bonds."""
    h = 1e-3
    body = geometry.rectangle(0.030, 0.004, h, thickness=h)
    body = body.with_node_set("left", geometry.face(body, "x-"))
    body = body.with_node_set("right", geometry.face(body, "x+"))
    x = body.points[:, 0]
    body = body.with_node_set("grips", (x < 0.0045) | (x > 0.0255))
    onsets = []
    for kind in ("explicit", "newmark"):
        model = make_model("pmb", body, find_bonds(body, 3.015 * h), E=200e9, density=7850.0, nu=1 / 3)
        loading = Loading(
            body,
            [
                BoundaryCondition("left", "displacement", "x", Ramp(0, 10e-6, 0, -30e-6)),
                BoundaryCondition("right", "displacement", "x", Ramp(0, 10e-6, 0, 30e-6)),
            ],
        )
        damage = BondDamage(model, critical_stretch=1e-3, no_damage_sets=["grips"])
        solver = ExplicitSolver(model, loading, damage=damage)
        if kind == "newmark":
            solver = NewmarkSolver(model, loading, dt=solver.dt, tolerance=1e-13, damage=damage)
        state = solver.initial_state()
        while solver.step(state) == 0 and state.time < 12e-6:
            pass
        onsets.append((state.step, np.flatnonzero(~model.bonds.intact)))
    print("first breaking step and bonds:", [(step, len(broken)) for step, broken in onsets])
    assert len(onsets[0][1]) > 0
    assert onsets[0][0] == onsets[1][0]
    np.testing.assert_array_equal(onsets[0][1], onsets[1][1])
