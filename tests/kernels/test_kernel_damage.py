"""Bond-breaking kernels (``peridyn.kernels.damage``) against their NumPy references
(``kernels.reference.damage``), float64 (the damage drivers' dtype)."""

import numpy as np
import pytest
from kernel_inputs import SPACING, TOL64, assert_close, displacement, jittered_families

from peridyn.kernels import damage
from peridyn.kernels.reference import bond_vectors
from peridyn.kernels.reference import damage as ref

pytestmark = pytest.mark.kernels


@pytest.mark.bitwise
@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_squared_length_keeps_its_roundings(rng, dtype):
    """Compiled without fast-math, the squared length is y0^2 + y1^2 + y2^2 rounded step by
    step as written (its definition: every kernel gets the same number): exact equality."""
    y = rng.standard_normal((20, 3)).astype(dtype)
    got = np.array([damage.squared_length(*row) for row in y])
    np.testing.assert_array_equal(got, ref.squared_length(y[:, 0], y[:, 1], y[:, 2]))


def _stretch_inputs(rng, share_tested):
    """Families stretched so that about a tenth of the bonds fail, a tenth unbreakable
    (limit inf), and a random ``share_tested`` of the points tested, with random moves."""
    fam = jittered_families(rng)
    u = displacement(rng, fam, 3e-3)
    _, _, y = bond_vectors(fam.x, u, fam.offsets, fam.nbr)
    stretch = np.linalg.norm(y, axis=1) / fam.length - 1.0
    limit = fam.length * (1.0 + np.quantile(stretch, 0.9))
    limit[rng.random(fam.n_bonds) < 0.1] = np.inf
    tested = rng.random(fam.n) < share_tested
    points = np.flatnonzero(tested)
    moved = np.where(tested, 1e-3 * SPACING * rng.random(fam.n), 0.0)
    return fam, u, limit, tested, points, moved


@pytest.mark.bitwise
@pytest.mark.parametrize("share_tested", [1.0, 0.5])
@pytest.mark.parametrize("quantum", [2.015 * SPACING / damage.MAX_QUANTA, 1e-7], ids=["fine", "coarse"])
def test_stretch_test_families(rng, share_tested, quantum):
    """Bonds broken (both copies where the other end is not tested) and their count: exact (same
    squared lengths, same comparison, and the kernels are compiled without value-changing
    fast-math flags, ``peridyn.kernels.FASTMATH``: on every CPU). Margins: the same whole number
    of quanta, then rounded to ~1e-16; the kernel multiplies a bond's room by 1 / quantum where
    NumPy divides it by quantum, which may round it by an ulp otherwise and changes its whole
    quanta only when it lies within an ulp of a whole number, so at most one point in a hundred
    may be one quantum off. Entries of the points not tested are left alone."""
    fam, u, limit, tested, points, moved = _stretch_inputs(rng, share_tested)
    intact = fam.intact.copy()
    margin = np.full(fam.n, -1.0)
    broken = damage.stretch_test_families(
        fam.x, u, fam.offsets, fam.nbr, limit, intact, points, tested, moved, quantum, margin
    )
    expected_intact, expected_margin, expected_broken = ref.stretch_test_families(
        fam.x, u, fam.offsets, fam.nbr, limit, fam.intact, points, tested, moved, quantum
    )
    assert broken == expected_broken > 0
    np.testing.assert_array_equal(intact, expected_intact)
    off_by = np.rint((margin[points] - expected_margin) / quantum)
    assert np.all(np.abs(off_by) <= 1) and np.count_nonzero(off_by) <= len(points) // 100
    assert_close(margin[points], expected_margin + off_by * quantum, TOL64, np.abs(expected_margin))
    assert np.all(margin[~tested] == -1.0)


def test_flag_moved_points(rng):
    """moved = |u - u_ref| to a few ulp (the kernel may sum the squares in another order);
    the flags margin <= 2 moved and their count exactly (no margin of these random inputs
    lies within rounding of 2 moved); -1 when a move is not finite."""
    fam = jittered_families(rng)
    u_ref = displacement(rng, fam, 1e-3)
    u = u_ref + displacement(rng, fam, 1e-4)
    margin = 1e-7 * rng.random(fam.n)
    moved = np.full(fam.n, np.nan)
    tested = np.zeros(fam.n, dtype=bool)
    count = damage.flag_moved_points(u, u_ref, margin, moved, tested)
    expected_moved, expected_tested, expected_count = ref.flag_moved_points(u, u_ref, margin)
    np.testing.assert_allclose(moved, expected_moved, rtol=1e-15)
    np.testing.assert_array_equal(tested, expected_tested)
    assert count == expected_count > 0
    u[3, 1] = np.nan
    assert damage.flag_moved_points(u, u_ref, margin, moved, tested) == -1
    assert ref.flag_moved_points(u, u_ref, margin)[2] == -1


def test_damage_index(rng):
    """phi = 1 - intact / total weight per family, 0 for an empty family or one of zero
    weight: phi is in [0, 1] and its sums of < 10 positive weights are exact to ~1e-15."""
    sizes = np.array([3, 0, 4, 2, 5, 1, 6])
    offsets = np.concatenate([[0], np.cumsum(sizes)])
    weight = rng.uniform(0.5, 1.5, offsets[-1])
    weight[offsets[3] : offsets[4]] = 0.0  # a family of zero weight
    intact = rng.random(offsets[-1]) < 0.6
    got = damage.damage_index(offsets, weight, intact, np.full(len(sizes), np.nan))
    expected = ref.damage_index(offsets, weight, intact)
    assert expected[1] == expected[3] == 0.0
    assert_close(got, expected, TOL64, 1.0)
