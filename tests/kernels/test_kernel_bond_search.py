"""Bond-search kernels (``peridyn.kernels.bond_search``) against their NumPy references
(``kernels.reference.bond_search``)."""

import numpy as np
import pytest
from kernel_inputs import SPACING, TOL64, assert_close, jittered_families
from scipy.spatial import cKDTree

from peridyn.kernels import bond_search
from peridyn.kernels.reference import bond_search as ref

pytestmark = pytest.mark.kernels


def test_bond_families(rng):
    """CSR offsets and sorted neighbours from shuffled i < j pairs, with isolated points
    (empty families): exact, dtypes included."""
    x = rng.uniform(0.0, 6 * SPACING, (40, 3))
    pairs = cKDTree(x).query_pairs(1.5 * SPACING, output_type="ndarray")
    pairs = pairs[rng.permutation(len(pairs))]
    n = len(x) + 3  # three more points, in no pair
    offsets, nbr = bond_search.bond_families(pairs, n)
    expected_offsets, expected_nbr = ref.bond_families(pairs, n)
    assert offsets.dtype == np.int64 and nbr.dtype == np.int32
    np.testing.assert_array_equal(offsets, expected_offsets)
    np.testing.assert_array_equal(nbr, expected_nbr)
    assert np.any(np.diff(offsets) == 0)


def _candidates(rng, radius, cells):
    """Jittered points and the CSR families of all pairs within the horizon plus half a cell
    diagonal (as ``find_bonds`` searches with partial volumes), with the reference families."""
    fam = jittered_families(rng)
    reach = radius + 0.5 * np.linalg.norm(cells[0])
    offsets, nbr = ref.bond_families(cKDTree(fam.x).query_pairs(reach, output_type="ndarray"), fam.n)
    return fam.x, offsets, nbr


@pytest.mark.parametrize("partial", [True, False])
@pytest.mark.parametrize("dim", [3, 2])
def test_bond_geometry(rng, partial, dim):
    """Lengths to a few ulp (the norm may be summed in another order); volume factors: the
    fraction of the neighbour's cell (a rectangle in 2D: zero third side) inside the ball,
    a midpoint quadrature of q^2 chord lengths each rounded to ~1e-16, so to 1e-12; without
    partial volumes 1 or 0, exactly (no bond of these inputs is within rounding of the
    radius)."""
    radius, q = 2.015 * SPACING, 4
    cells = np.full((1, 3), SPACING)
    if dim == 2:
        cells[:, 2] = 0.0
    x, offsets, nbr = _candidates(rng, radius, cells)
    cells = np.repeat(cells, len(x), axis=0)
    length, factor = bond_search.bond_geometry(x, cells, offsets, nbr, radius, partial, q)
    expected_length, expected_factor = ref.bond_geometry(x, cells, offsets, nbr, radius, partial, q)
    np.testing.assert_allclose(length, expected_length, rtol=1e-15)
    if partial:
        assert_close(factor, expected_factor, TOL64, 1.0)
        assert np.any((expected_factor > 0) & (expected_factor < 1))
    else:
        np.testing.assert_array_equal(factor, expected_factor)
    assert np.any(expected_factor == 0) and np.any(expected_factor == 1)


@pytest.mark.parametrize("q", [1, 3, 8])
def test_box_fraction_in_ball(rng, q):
    """Boxes and rectangles (h2 = 0) inside, outside and across the sphere: the kernel's
    shortcuts for wholly inside / outside boxes agree with the quadrature, and the partial
    fractions are the same midpoint quadrature (to 1e-12, see ``test_bond_geometry``)."""
    radius = 2.0
    sides = rng.uniform(0.5, 1.5, (60, 3))
    sides[::3, 2] = 0.0
    direction = rng.standard_normal((60, 3))
    direction /= np.linalg.norm(direction, axis=1)[:, None]
    centres = direction * rng.uniform(0.0, 2 * radius, 60)[:, None]
    got = np.array(
        [bond_search.box_fraction_in_ball(*c, *h, radius, q) for c, h in zip(centres, sides, strict=True)]
    )
    expected = ref.box_fraction_in_ball(centres, sides, radius, q)
    assert_close(got, expected, TOL64, 1.0)
    assert np.any(expected == 0) and np.any((expected > 0) & (expected < 1))


@pytest.mark.bitwise
def test_initial_bond_vectors(rng):
    """x_j - x_i of every directed bond, exactly (one subtraction, as in the reference); the
    reverse bond's vector is its negative to the last bit (Newton's third law of the kernels
    that read it)."""
    fam = jittered_families(rng)
    got = bond_search.initial_bond_vectors(fam.x, fam.offsets, fam.nbr, np.full((len(fam.nbr), 3), np.nan))
    np.testing.assert_array_equal(got, ref.initial_bond_vectors(fam.x, fam.offsets, fam.nbr))
    owner = np.repeat(np.arange(fam.n), np.diff(fam.offsets))
    pair = {(i, j): b for b, (i, j) in enumerate(zip(owner, fam.nbr, strict=True))}
    reverse = np.array([pair[(j, i)] for i, j in zip(owner, fam.nbr, strict=True)])
    np.testing.assert_array_equal(got[reverse], -got)


@pytest.mark.bitwise
def test_family_sums_are_bincounts_to_the_bit(rng):
    """Per-family sums in each family's bond order, empty families included: bit for bit the
    ``np.bincount`` over the bonds' owners that the reference (and peridyn before the kernel)
    computes. Both add each family's values one after the other in bond order, with no fast-math."""
    sizes = rng.integers(0, 9, 60)
    sizes[[0, 17, -1]] = 0  # empty families first, inside and last
    offsets = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    values = rng.normal(size=offsets[-1]) * 10.0 ** rng.integers(-8, 8, offsets[-1])
    got, expected = np.full(60, np.nan), np.full(60, np.nan)
    bond_search.family_sums(offsets, values, got)
    ref.family_sums(offsets, values, expected)
    np.testing.assert_array_equal(got, expected)
    assert got[0] == got[17] == got[-1] == 0.0
