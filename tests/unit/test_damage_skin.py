"""The stretch-test skin of ``BondDamage.update`` (peridyn.physics.damage, module docstring).

Its contract is exactness: the bonds broken, and so every later displacement, are bit for
bit those of testing every bond at every call (``FULL_TEST_SHARE = 0`` forces that). The
skin itself rests on one inequality: between two displacements a bond's deformed length
|xi + u_j - u_i| changes by at most |du_i| + |du_j| (triangle inequality).
"""

import numpy as np
import pytest

from peridyn.discretization import geometry
from peridyn.discretization.bonds import crossing_rectangle, crossing_segment, cut_bonds, find_bonds
from peridyn.physics.damage import BondDamage
from peridyn.physics.loads import BoundaryCondition, Loading
from peridyn.physics.materials import make_model
from peridyn.physics.timefunctions import Constant
from peridyn.solvers import ExplicitSolver

H = 0.5e-3


def edge_cracked_plate():
    """A 20 x 10 mm plate (spacing 0.5 mm) with a 7 mm edge pre-crack at mid-height, its
    top and bottom 1.5 mm pulled apart at 1 m/s, bonds within 3 mm of its top and bottom
    edges unbreakable (``grips``): the crack runs from the pre-crack's tip."""
    body = geometry.rectangle(0.020, 0.010, spacing=H, thickness=1e-3, plane="stress")
    y = body.points[:, 1]
    body = (
        body.with_node_set("top", y > 0.010 - 3 * H)
        .with_node_set("bottom", y < 3 * H)
        .with_node_set("grips", (y > 0.007) | (y < 0.003))
    )
    bonds = find_bonds(body, 3.015 * H, partial_volumes=False)
    cut_bonds(body, bonds, lambda a, b: crossing_segment(a, b, (-0.001, 0.005), (0.007, 0.005)))
    model = make_model("pmb", body, bonds, E=70e9, density=2700)
    pull = [
        BoundaryCondition("top", "velocity", "y", Constant(1.0)),
        BoundaryCondition("bottom", "velocity", "y", Constant(-1.0)),
    ]
    return model, Loading(body, pull)


def shaken_cube(side=12):
    """The setting of ``benchmarks/bench_contact.py`` (mid-plane pre-crack) on a 12^3 cube."""
    spacing = 1e-3
    body = geometry.box((side * spacing,) * 3, spacing)
    bonds = find_bonds(body, 3.015 * spacing, partial_volumes=False)
    half = 0.5 * side * spacing
    cut_bonds(body, bonds, lambda a, b: crossing_rectangle(a, b, (half, -1, -1), (0, 3, 0), (0, 0, 3)))
    model = make_model("pmb", body, bonds, E=200e9, density=7850)
    return model, Loading(body)


def run_pair(build, critical_stretch, n_steps, v0=None, no_damage_sets=()):
    """The same run twice: skin (default) and every bond tested at every step."""
    runs = []
    for share in (BondDamage.FULL_TEST_SHARE, 0.0):
        model, loading = build()
        damage = BondDamage(model, critical_stretch=critical_stretch, no_damage_sets=no_damage_sets)
        damage.FULL_TEST_SHARE = share
        solver = ExplicitSolver(model, loading, damage=damage)
        state = solver.initial_state()
        if v0 is not None:
            state.v[:] = v0
        broken = [solver.step(state) for _ in range(n_steps)]
        runs.append((model, damage, state, broken))
    return runs


@pytest.mark.bitwise
def test_skin_breaks_the_bonds_of_a_full_test_in_a_growing_crack():
    """Edge-cracked plate pulled apart: same bonds broken at every step, same displacements
    to the last bit, with the skin and with every bond tested at every step. The run must
    grow the crack (bonds broken beyond the pre-crack) and the skin must have skipped
    many full tests, or the comparison proves nothing. Bit for bit: both test the bonds with the same
    kernels and the same squared lengths, and the kernels are compiled without value-changing fast-math
    flags (``peridyn.kernels.FASTMATH``), so this holds on every CPU."""
    runs = run_pair(edge_cracked_plate, 2e-3, 400, no_damage_sets=["grips"])
    (m1, skin, s1, broken1), (m2, full, s2, broken2) = runs
    assert broken1 == broken2
    np.testing.assert_array_equal(m1.bonds.intact, m2.bonds.intact)
    np.testing.assert_array_equal(s1.u, s2.u)
    assert sum(broken1) >= 2000  # the crack grew by many bonds (2780 here)
    assert np.ptp(np.flatnonzero(broken1)) > 100  # over many steps, not in one burst
    assert full.full_tests == 400 and full.partial_tests == 0
    assert skin.partial_tests >= 200  # at most half the calls were full tests (116 here)


@pytest.mark.bitwise
def test_skin_breaks_the_bonds_of_a_full_test_when_bonds_break_everywhere():
    """Cube of the contact benchmark shaken by 2 m/s rms random velocities: bonds break here
    and there all through it. Same broken bonds and displacements as full tests. Bit for bit: both test
    the bonds with the same kernels and the same squared lengths, and the kernels are compiled without
    value-changing fast-math flags (``peridyn.kernels.FASTMATH``), so this holds on every CPU."""
    rng = np.random.default_rng(3)
    v0 = rng.normal(scale=2.0 / np.sqrt(3), size=(12**3, 3))
    (m1, skin, s1, broken1), (m2, _, s2, broken2) = run_pair(shaken_cube, 1e-3, 60, v0)
    assert broken1 == broken2
    np.testing.assert_array_equal(m1.bonds.intact, m2.bonds.intact)
    np.testing.assert_array_equal(s1.u, s2.u)
    assert sum(broken1) > 0.001 * m1.bonds.n_bonds  # 356 of 155 512 here
    assert np.count_nonzero(broken1) > 30  # in most steps (52 of 60 here)
    assert skin.partial_tests >= 20  # 31 here
    b = m1.bonds
    np.testing.assert_array_equal(b.intact, b.intact[b.reverse()])  # both copies together


def line_model():
    """A 10 x 1.5 mm plate strip (2D, spacing 0.5 mm)."""
    body = geometry.rectangle(0.010, 0.0015, spacing=H, thickness=1e-3, plane="stress")
    bonds = find_bonds(body, 3.015 * H, partial_volumes=False)
    return make_model("pmb", body, bonds, E=70e9, density=2700)


def bond_index(bonds, i, j):
    lo, hi = bonds.offsets[i], bonds.offsets[i + 1]
    return lo + int(np.flatnonzero(bonds.neighbours[lo:hi] == j)[0])


def pair_along_x(model):
    """Point i near the strip's middle and its neighbour j = i + (0.5 mm, 0)."""
    x = model.body.points
    i = int(np.argmin(np.hypot(x[:, 0] - 0.005, x[:, 1] - 0.00075)))
    j = int(np.flatnonzero((np.abs(x[:, 0] - x[i, 0] - H) < 1e-9) & (np.abs(x[:, 1] - x[i, 1]) < 1e-9))[0])
    return i, j


@pytest.mark.parametrize("mover", ["owner", "neighbour"])
def test_bond_near_its_limit_is_caught_when_a_far_point_moves_a_lot(mover):
    """A bond left 1e-12 m short of its critical length L_c = |xi| (1 + s_c) by the full
    test, then stretched by 2e-12 m in one step while a far point jumps 1 mm away from the
    body: the bond breaks in that step (both copies), whichever end moved, and so do all
    the far point's bonds; a stretch of 0.9e-12 m (1e-13 m short of L_c) breaks only the
    far point's bonds. Done by a partial test (the skin), not a full one."""
    s_c = 1e-3
    for extra, pair_breaks in ((2e-12, True), (0.9e-12, False)):
        model = line_model()
        b = model.bonds
        x = model.body.points
        i, j = pair_along_x(model)
        far = int(np.argmin(x[:, 0]))
        far_bonds = b.offsets[far + 1] - b.offsets[far]
        damage = BondDamage(model, critical_stretch=s_c)
        u = np.zeros_like(x)
        u[j, 0] = H * (1 + s_c) - H - 1e-12
        assert damage.update(u) == 0
        u[far, 0] -= 1e-3
        if mover == "neighbour":
            u[j, 0] += extra
        else:
            u[i, 0] -= extra
        assert damage.update(u) == 2 * far_bonds + (2 if pair_breaks else 0)
        assert b.intact[bond_index(b, i, j)] == (not pair_breaks)
        assert b.intact[bond_index(b, j, i)] == (not pair_breaks)
        assert not b.intact[b.offsets[far] : b.offsets[far + 1]].any()
        assert damage.full_tests == 1 and damage.partial_tests == 1


def test_slow_creep_past_the_limit_breaks_at_the_first_step_beyond_it():
    """Many steps each far below the margin add up: the bond breaks in the first step at which
    |Y| exceeds L_c (checked against the closed form), not later."""
    model = line_model()
    i, j = pair_along_x(model)
    s_c = 1e-3
    damage = BondDamage(model, critical_stretch=s_c)
    u = np.zeros_like(model.body.points)
    step = 1.3e-8  # 0.026 of the margin s_c |xi| = 5e-7 m
    first = None
    for k in range(1, 60):
        u[j, 0] = k * step
        broken = damage.update(u)
        if broken and first is None:
            first = k
    assert first == int(np.floor(s_c * H / step)) + 1
    assert damage.full_tests == 1


def test_criteria_are_frozen_after_the_first_update_until_reset():
    """Edits of ``critical_stretch`` or ``breakable`` after the first update would be ignored
    by the skin: they raise instead; ``reset`` re-reads them (and mended bonds)."""
    model = line_model()
    damage = BondDamage(model, critical_stretch=1e-3)
    damage.breakable[:3] = False  # allowed before the first update
    u = np.zeros_like(model.body.points)
    u[:, 0] = 2e-3 * model.body.points[:, 0]  # uniform strain 2e-3 > s_c along x
    broken = damage.update(u)
    assert broken > 0
    with pytest.raises(ValueError, match="read-only"):
        damage.critical_stretch[:] = 5e-3
    with pytest.raises(ValueError, match="read-only"):
        damage.breakable[:] = False
    damage.reset()
    damage.critical_stretch[:] = 5e-3  # now above the strain: nothing breaks
    model.bonds.intact[:] = True  # mended
    assert damage.update(u) == 0
    assert damage.full_tests == 2


def test_a_non_finite_displacement_falls_back_to_a_full_test():
    """An infinite displacement has no finite move to bound: ``update`` tests every bond, and
    the infinitely stretched bonds of that point (both copies) break, as a full test breaks them.
    Booleans: compared exactly."""
    model = line_model()
    b = model.bonds
    damage = BondDamage(model, critical_stretch=1e-3)
    u = np.zeros_like(model.body.points)
    assert damage.update(u) == 0
    k = 7
    u[k, 0] = np.inf
    family = b.offsets[k + 1] - b.offsets[k]
    assert damage.update(u) == 2 * family
    assert damage.full_tests == 2 and damage.partial_tests == 0
    assert not b.intact[b.offsets[k] : b.offsets[k + 1]].any()
    np.testing.assert_array_equal(b.intact, b.intact[b.reverse()])
