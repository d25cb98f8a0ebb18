"""Short-range contact forces (peridyn.physics.contact): range, repulsion, Newton's third law,
Verlet-list correctness and input checks. Model: Silling's short-range force as in Peridigm
(Parks et al.), f_i = -c_sr (d_c - |Y|) / delta V_j Y / |Y| for |Y| < d_c."""

from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import cKDTree

from peridyn.discretization import geometry
from peridyn.discretization.bonds import crossing_segment, cut_bonds, find_bonds
from peridyn.errors import CaseFileError, InputError
from peridyn.io.case import load_case
from peridyn.physics.contact import Contact
from peridyn.physics.loads import InitialCondition, Loading
from peridyn.physics.materials import make_model
from peridyn.physics.materials.pmb import pmb_micromodulus
from peridyn.setup.build import build
from peridyn.solvers import ExplicitSolver

H = 1e-3


def cut_square(n=10, cut=True):
    """A 2D n x n plane-stress square of aluminium cut through along x = n h / 2."""
    body = geometry.rectangle(n * H, n * H, H, thickness=H, plane="stress")
    bonds = find_bonds(body, 3.015 * H)
    if cut:
        cut_bonds(body, bonds, lambda a, b: crossing_segment(a, b, (n * H / 2, -1), (n * H / 2, 1)))
    return make_model("pmb", body, bonds, E=70e9, density=2700.0)


def break_at_random(model, fraction, rng):
    """Break a random ``fraction`` of the bonds (both directed copies)."""
    b = model.bonds
    broken = rng.random(b.n_bonds) < fraction
    broken |= broken[b.reverse()]
    b.intact[broken] = False


def brute_force(model, contact, u):
    """All-pairs contact force density (no Verlet list), N/m^3, from the formula above."""
    x = model.body.points + u
    n = len(x)
    bonded = np.zeros((n, n), dtype=bool)
    b = model.bonds
    bonded[b.owners()[b.intact], b.neighbours[b.intact]] = True
    d = x[None, :, :] - x[:, None, :]  # d[i, j] = y_j - y_i
    r = np.linalg.norm(d, axis=2)
    act = (r < contact.radius) & ~bonded & ~np.eye(n, dtype=bool)
    mag = np.where(act, contact.stiffness * (contact.radius - r) / np.where(act, r, 1.0), 0.0)
    return -np.einsum("ij,ijk,j->ik", mag, d, model.body.volumes)


def test_force_zero_beyond_radius_and_repulsive_within():
    model = cut_square()
    contact = Contact(model, radius=H)
    right = model.body.points[:, 0] > 5 * H
    for gap, expect_force in ((0.01 * H, False), (-0.01 * H, True)):
        u = np.zeros((model.body.n_points, 3))
        u[right, 0] = gap  # open (gap > 0) or close the cut by |gap|
        f = contact.add_force(u, np.zeros_like(u))
        if not expect_force:
            assert np.all(f == 0.0)
        else:
            # faces pushed together: the right face is pushed to +x, the left one to -x
            face_r = right & (model.body.points[:, 0] < 6 * H)
            face_l = ~right & (model.body.points[:, 0] > 4 * H)
            assert np.all(f[face_r, 0] > 0) and np.all(f[face_l, 0] < 0)
            # magnitude of one facing pair: c_sr (d_c - r) / delta V (closest pair only in contact)
            c_sr = 15 * pmb_micromodulus(70e9, 2, 3.015 * H, "constant", "stress", H)
            expected = c_sr * 0.01 * H / (3.015 * H) * H**3
            np.testing.assert_allclose(f[face_r, 0], expected, rtol=1e-9)


def test_intact_bonds_exclude_contact_broken_ones_do_not():
    """Uncut body compressed: bonded pairs never act; once the bonds break they do."""
    model = cut_square(cut=False)
    contact = Contact(model, radius=H)
    u = np.zeros((model.body.n_points, 3))
    u[:, 0] = -0.05 * model.body.points[:, 0]  # 5 % compression: neighbours at 0.95 h < d_c
    assert np.all(contact.add_force(u, np.zeros_like(u)) == 0.0)
    model.bonds.intact[:] = False
    f = contact.add_force(u, np.zeros_like(u))
    assert np.abs(f).max() > 0
    np.testing.assert_allclose(f, brute_force(model, contact, u), rtol=1e-10, atol=1e-6 * np.abs(f).max())


def test_newton_third_law_total_force_vanishes():
    rng = np.random.default_rng(1)
    model = cut_square()
    break_at_random(model, 0.5, rng)
    contact = Contact(model, radius=0.9 * H)
    u = rng.normal(scale=0.2 * H, size=(model.body.n_points, 3))
    u[:, 2] = 0.0
    f = contact.add_force(u, np.zeros_like(u))
    total = (f * model.body.volumes[:, None]).sum(axis=0)
    scale = (np.abs(f) * model.body.volumes[:, None]).sum()
    assert contact.touching > 10
    assert np.abs(total).max() < 1e-13 * scale


def test_verlet_list_matches_brute_force_at_every_step_of_random_motion():
    """The skin list gives the all-pairs force at every step; rebuilds happen only when needed."""
    rng = np.random.default_rng(7)
    model = cut_square(n=8)
    break_at_random(model, 0.7, rng)
    contact = Contact(model, radius=H, skin=0.4 * H)
    u = np.zeros((model.body.n_points, 3))
    velocity = rng.normal(scale=0.02 * H, size=u.shape)
    velocity[:, 2] = 0.0
    steps = 120
    for _ in range(steps):
        u += velocity + rng.normal(scale=0.005 * H, size=u.shape) * [1, 1, 0]
        f = contact.add_force(u, np.zeros_like(u))
        ref = brute_force(model, contact, u)
        np.testing.assert_allclose(f, ref, rtol=1e-9, atol=1e-9 * max(np.abs(ref).max(), 1.0))
    # ~0.03 h per step: a rebuild every ~0.2 h / 0.03 h ~ 7 steps at most, never every step
    assert 2 <= contact.rebuilds < steps / 3


def test_list_is_rebuilt_exactly_when_a_point_moved_half_the_skin():
    """Verlet-list rule (Allen and Tildesley, Computer Simulation of Liquids, sec. 5.3): two
    points approach each other by at most twice the largest move, so the list built with a
    skin s stays complete while every point moved less than s / 2, and must be rebuilt after."""
    model = cut_square(n=6)
    skin = 0.4 * H
    contact = Contact(model, radius=H, skin=skin)
    u = np.zeros((model.body.n_points, 3))
    contact.rebuild(u)
    u[17] = [0.6, 0.8, 0.0]  # a unit direction
    u[17] *= 0.499 * skin
    assert not contact.needs_rebuild(u)
    u[17] *= 0.501 / 0.499
    assert contact.needs_rebuild(u)


def test_collision_conserves_momentum_and_bounces():
    """Two halves of a cut square thrown at each other: momentum conserved, they separate."""
    model = cut_square(n=10)
    body = model.body
    right = body.points[:, 0] > 5 * H
    body = body.with_node_set("left_half", ~right).with_node_set("right_half", right)
    model.body = body
    v0 = 5.0
    loading = Loading(
        body,
        initial=[
            InitialCondition("left_half", "velocity", "x", v0),
            InitialCondition("right_half", "velocity", "x", -v0),
        ],
    )
    contact = Contact(model, radius=H)
    solver = ExplicitSolver(model, loading, contact=contact)
    state = solver.initial_state()
    mass = model.density * body.volumes

    def momentum(s):
        return (mass[:, None] * s.v).sum(axis=0)

    p0 = momentum(state)
    scale = (mass * v0).sum()
    # faces touch from the start (d_c = h); an overlap of 0.1 h is reached in 0.05 h / v0
    solver.run(state, int(4 * 0.1 * H / v0 / solver.dt))
    assert np.abs(momentum(state) - p0).max() < 1e-10 * scale
    v_left = state.v[~right, 0].mean()
    v_right = state.v[right, 0].mean()
    assert v_left < 0 < v_right  # bounced: repulsion reversed the approach


def test_contact_lowers_the_stable_step_by_its_stiffness_bound():
    model = cut_square()
    contact = Contact(model, radius=H)
    dt_model = ExplicitSolver(model).stable_dt
    dt_contact = ExplicitSolver(model, contact=contact).stable_dt
    bound = model.stiffness_bound() + contact.stiffness_bound()
    assert dt_contact == pytest.approx(2 / np.sqrt(np.max(bound / model.density)), rel=1e-12)
    assert 0.6 * dt_model < dt_contact < dt_model


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"radius": 0.0}, "contact radius must be positive"),
        ({"radius": -1e-3}, "contact radius must be positive"),
        ({"radius": 4e-3}, "larger than the horizon"),
        ({"radius": 1e-3, "stiffness_factor": 0.0}, "stiffness factor must be positive"),
        ({"radius": 1e-3, "skin": -1.0}, "skin must be positive"),
    ],
)
def test_bad_contact_input(kwargs, message):
    with pytest.raises(InputError, match=message):
        Contact(cut_square(n=6), **kwargs)


def test_contact_beyond_the_horizon_when_allowed():
    """A contact distance above the horizon is refused unless allowed (Peridigm's decks): then
    every unbonded pair within d_c = 4.95 h (between lattice distances) touches, those beyond
    the horizon 3.015 h too (counted here from the points), and the forces on the body sum to
    zero (each pair's are equal and opposite)."""
    model = cut_square(n=6)
    with pytest.raises(InputError, match="larger than the horizon"):
        Contact(model, radius=5 * H)
    contact = Contact(model, radius=4.95 * H, beyond_horizon=True)
    body, bonds = model.body, model.bonds
    f = np.zeros((body.n_points, 3))
    contact.add_force(np.zeros((body.n_points, 3)), f)
    near = cKDTree(body.points).query_pairs(4.95 * H, output_type="ndarray")
    intact = {
        (int(i), int(j))
        for i, j, ok in zip(bonds.owners(), bonds.neighbours, bonds.intact, strict=True)
        if ok
    }
    unbonded = [p for p in map(tuple, near) if p not in intact]
    assert contact.touching == len(unbonded) > 0
    assert any(np.linalg.norm(body.points[i] - body.points[j]) > 3.015 * H for i, j in unbonded)
    total = np.abs(f * body.volumes[:, None]).sum()
    assert np.abs((f * body.volumes[:, None]).sum(axis=0)).max() < 1e-12 * total


def breathing_case(**contact):
    """The breathing-crack case file, its contact block replaced by ``contact`` if given."""
    path = Path(__file__).resolve().parents[2] / "cases" / "lamb_breathing_crack.yaml"
    overrides = [f"contact={contact}"] if contact else []
    return load_case(path, overrides)


def test_case_contact_block_builds_contact_in_metres():
    setup = build(breathing_case())
    assert isinstance(setup.contact, Contact)
    assert setup.contact.radius == pytest.approx(1.0e-3)  # radius: 1.0 spacing of 1 mm
    assert setup.contact.stiffness_factor == 15.0


def test_case_contact_block_errors():
    with pytest.raises(CaseFileError, match="exactly one of radius"):
        breathing_case(stiffness_factor=10.0)
    with pytest.raises(CaseFileError, match="larger than the horizon"):
        build(breathing_case(radius=4.0))


def test_contact_with_an_implicit_solver_is_refused():
    """Newton and Newmark have no contact forces: the case must say so, not drop them."""
    path = Path(__file__).resolve().parents[2] / "cases" / "lamb_breathing_crack.yaml"
    with pytest.raises(CaseFileError, match="newmark solver has no contact forces"):
        load_case(path, ["solver.type=newmark", "solver.dt=2e-8"])
