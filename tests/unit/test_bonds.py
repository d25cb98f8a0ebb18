"""Family search, influence functions, partial volumes and pre-cracks."""

import dataclasses
import itertools

import numpy as np
import pytest

from peridyn.discretization import geometry
from peridyn.discretization.bonds import (
    cell_fraction_in_ball,
    crossing_rectangle,
    crossing_segment,
    cut_bonds,
    find_bonds,
)
from peridyn.errors import InputError


def _lattice_count(radius: float, dim: int) -> int:
    """Lattice points (integer vectors, not 0) within ``radius`` grid units: a closed form count."""
    r = int(np.ceil(radius))
    rng = range(-r, r + 1)
    pts = itertools.product(*([rng] * dim))
    return sum(1 for p in pts if 0 < sum(c * c for c in p) <= radius**2)


@pytest.mark.parametrize("factor, expected", [(1.4143, 18), (2.015, 32), (3.015, 122)])
def test_interior_family_size_3d(factor, expected):
    body = geometry.box((0.011,) * 3, 1e-3)
    bonds = find_bonds(body, factor * 1e-3, partial_volumes=False)
    centre = np.argmin(np.linalg.norm(body.points - 0.0055, axis=1))
    assert np.diff(bonds.offsets)[centre] == expected == _lattice_count(factor, 3)


def test_interior_family_size_2d():
    body = geometry.rectangle(0.011, 0.011, 1e-3, thickness=1e-3)
    bonds = find_bonds(body, 3.015e-3, partial_volumes=False)
    centre = np.argmin(np.linalg.norm(body.points[:, :2] - 0.0055, axis=1))
    assert np.diff(bonds.offsets)[centre] == _lattice_count(3.015, 2) == 28


def test_families_are_symmetric_and_sorted():
    """Each bond i->j has its reverse j->i (indices: compared exactly) with the same volume factor to
    rounding, and each family is sorted by neighbour."""
    body = geometry.plate(0.008, 0.006, 0.002, spacing=1e-3, layers=3)
    bonds = find_bonds(body, 2.5e-3)
    rev = bonds.reverse()
    owners = bonds.owners()
    np.testing.assert_array_equal(owners[rev], bonds.neighbours)
    np.testing.assert_array_equal(bonds.neighbours[rev], owners)
    np.testing.assert_allclose(bonds.volume_factor[rev], bonds.volume_factor, rtol=1e-12)
    for i in range(body.n_points):
        fam = bonds.neighbours[bonds.offsets[i] : bonds.offsets[i + 1]]
        assert np.all(np.diff(fam) > 0)


def test_reverse_of_families_in_any_order():
    """``reverse`` pairs each bond i->j with j->i when the families are not sorted by neighbour
    (as in a rank's part): the definition checked directly, and it is its own inverse. Indices: compared
    exactly."""
    body = geometry.plate(0.008, 0.006, 0.002, spacing=1e-3, layers=3)
    bonds = find_bonds(body, 2.5e-3)
    order = np.concatenate(
        [
            np.random.default_rng(i).permutation(np.arange(bonds.offsets[i], bonds.offsets[i + 1]))
            for i in range(body.n_points)
        ]
    )
    shuffled = dataclasses.replace(bonds, neighbours=bonds.neighbours[order], length=bonds.length[order])
    rev, owners = shuffled.reverse(), shuffled.owners()
    np.testing.assert_array_equal(owners[rev], shuffled.neighbours)
    np.testing.assert_array_equal(shuffled.neighbours[rev], owners)
    np.testing.assert_array_equal(rev[rev], np.arange(bonds.n_bonds))


@pytest.mark.parametrize("dim", [2, 3])
def test_partial_volumes_fill_the_horizon(dim):
    """The family's volume with partial volumes equals the ball's (disc's) to 0.5%."""
    h, delta = 1e-3, 3.015e-3
    if dim == 3:
        body = geometry.box((0.011,) * 3, h)
        target = 4 / 3 * np.pi * delta**3 - h**3  # ball minus the point's own cell
    else:
        body = geometry.rectangle(0.011, 0.011, h, thickness=h)
        target = (np.pi * delta**2 - h**2) * h
    bonds = find_bonds(body, delta, partial_volumes=True)
    centre = np.argmin(np.linalg.norm(body.points[:, :dim] - 0.0055, axis=1))
    fam = slice(bonds.offsets[centre], bonds.offsets[centre + 1])
    volume = np.sum(body.volumes[bonds.neighbours[fam]] * bonds.volume_factor[fam])
    # the own cell is (almost) whole inside the ball; the rest of the ball is covered by neighbours
    assert volume == pytest.approx(target, rel=5e-3)


def test_cell_fraction_simple_cases():
    cell = np.array([[1.0, 1.0, 1.0]])
    assert cell_fraction_in_ball(np.array([[0.0, 0.0, 0.0]]), cell, 2.0)[0] == 1.0
    assert cell_fraction_in_ball(np.array([[5.0, 0.0, 0.0]]), cell, 2.0)[0] == 0.0
    # a plane through the cell centre: a huge ball's surface cuts the cell in half
    big = 1e6
    half = cell_fraction_in_ball(np.array([[big, 0.0, 0.0]]), cell, big, quadrature_points=8)[0]
    assert half == pytest.approx(0.5, abs=1e-6)


@pytest.mark.parametrize(
    "name, at_horizon", [("constant", 1.0), ("inverse", 1.0), ("gaussian", np.exp(-1.0)), ("conical", 0.0)]
)
def test_influence_functions(name, at_horizon):
    body = geometry.box((0.007,) * 3, 1e-3)
    bonds = find_bonds(body, 3.0e-3 * (1 + 1e-9), influence=name, partial_volumes=False)
    far = np.isclose(bonds.length, 3.0e-3)
    np.testing.assert_allclose(bonds.influence[far], at_horizon, atol=1e-8)


def test_isolated_points_are_refused():
    body = geometry.box((0.004, 0.004, 0.004), 1e-3)
    with pytest.raises(InputError, match="horizon"):
        find_bonds(body, 0.4e-3)


def test_unknown_influence_function():
    body = geometry.box((0.004, 0.004, 0.004), 1e-3)
    with pytest.raises(InputError, match="did you mean 'gaussian'"):
        find_bonds(body, 2e-3, influence="gausian")


def test_rectangle_precrack_cuts_exactly_the_crossing_bonds():
    """Count checked against a brute-force loop over all point pairs."""
    body = geometry.box((0.010, 0.006, 0.004), 1e-3)
    bonds = find_bonds(body, 3.015e-3, partial_volumes=False)
    origin, eu, ev = (0.005, 0.0, 0.0), (0.0, 0.0032, 0.0), (0.0, 0.0, 0.004)  # x = 5 mm, y < 3.2 mm
    cut = cut_bonds(body, bonds, lambda a, b: crossing_rectangle(a, b, origin, eu, ev))
    x = body.points
    brute = 0
    for i in range(body.n_points):
        for j in range(body.n_points):
            if i == j or np.linalg.norm(x[j] - x[i]) > bonds.horizon * (1 + 1e-12):
                continue
            xa, xb = x[i], x[j]
            if (xa[0] - 0.005) * (xb[0] - 0.005) < 0:
                t = (0.005 - xa[0]) / (xb[0] - xa[0])
                hit = xa + t * (xb - xa)
                if 0 <= hit[1] <= 0.0032 and 0 <= hit[2] <= 0.004:
                    brute += 1
    assert cut == brute > 0
    assert int((~bonds.intact).sum()) == cut


def test_segment_precrack_2d():
    """A 2D segment pre-crack cuts the bonds that cross it, found here by a direct intersection with the
    line x = 5 mm. Booleans, compared exactly: both sides are NumPy elementwise arithmetic, correctly
    rounded on every CPU; the four bonds through the segment's end (5, 4) mm land on it exactly on both
    sides (y = 4 mm, a zero orientation) and are not cut."""
    body = geometry.rectangle(0.010, 0.010, 1e-3, thickness=1e-3)
    bonds = find_bonds(body, 2.015e-3, partial_volumes=False)
    cut = cut_bonds(body, bonds, lambda a, b: crossing_segment(a, b, (0.005, 0.0), (0.005, 0.004)))
    owners = bonds.owners()
    xa, xb = body.points[owners], body.points[bonds.neighbours]
    crosses = (xa[:, 0] - 0.005) * (xb[:, 0] - 0.005) < 0
    y_hit = xa[:, 1] + (0.005 - xa[:, 0]) / np.where(crosses, xb[:, 0] - xa[:, 0], 1) * (xb[:, 1] - xa[:, 1])
    expected = crosses & (y_hit > 0) & (y_hit < 0.004)
    assert cut == int(expected.sum()) > 0
    np.testing.assert_array_equal(~bonds.intact, expected)


def test_family_sums_gives_zero_for_an_empty_family():
    """An empty CSR family sums to 0 (np.add.reduceat would return the next family's first value). Sums
    of small whole numbers are exact: compared exactly."""
    from peridyn.discretization.bonds import family_sums

    offsets = np.array([0, 2, 2, 5])
    sums = family_sums(offsets, np.array([1.0, 2.0, 3.0, 4.0, 5.0]))
    np.testing.assert_array_equal(sums, [3.0, 0.0, 12.0])


def test_cut_bonds_cuts_both_copies_of_a_bond_ending_on_the_crack_edge():
    """A segment ending exactly where a diagonal bond crosses it (x = 12 mm between point
    columns 11.5 and 12.5 mm) may be seen as crossed from one end only (round-off); a bond
    broken in one direction makes the LPS force and stiffness disagree, so cut_bonds breaks
    both directed copies (peridynamic bonds are pairs)."""
    from peridyn.discretization.bonds import crossing_segment, cut_bonds

    body = geometry.rectangle(0.050, 0.008, 1e-3, 3e-3)
    bonds = find_bonds(body, 3.0005e-3, partial_volumes=False)
    cut = cut_bonds(body, bonds, lambda a, b: crossing_segment(a, b, [-1.0, 0.004], [0.012, 0.004]))
    assert cut > 0
    np.testing.assert_array_equal(bonds.intact, bonds.intact[bonds.reverse()])


def test_box_neighbourhood_is_every_point_within_the_half_widths():
    """``box``: the neighbours of each point are exactly the other points with |x_j - x_i| <=
    the half-widths along every axis (brute force over all pairs), with no partial volumes
    and the lengths |xi|; a box asked with partial volumes is refused."""
    body = geometry.box((0.6, 0.4, 0.3), [0.1, 0.1, 0.1])
    half = np.array([0.2, 0.1, 0.1])
    bonds = find_bonds(body, 0.2, partial_volumes=False, box=half)
    x = body.points
    near = np.all(np.abs(x[:, None, :] - x[None, :, :]) <= half * (1 + 1e-12), axis=2)
    np.fill_diagonal(near, False)
    for i in range(body.n_points):
        family = bonds.neighbours[bonds.offsets[i] : bonds.offsets[i + 1]]
        assert family.tolist() == np.flatnonzero(near[i]).tolist()
    owners = bonds.owners()
    np.testing.assert_allclose(
        bonds.length, np.linalg.norm(x[bonds.neighbours] - x[owners], axis=1), rtol=1e-15
    )
    assert np.all(bonds.volume_factor == 1.0)
    with pytest.raises(InputError, match="box neighbourhood"):
        find_bonds(body, 0.2, box=half)
