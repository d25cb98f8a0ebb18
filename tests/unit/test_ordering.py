"""Geometric nested dissection (linalg.ordering): a permutation whose separators split."""

import numpy as np
from scipy.spatial import cKDTree

from peridyn.linalg.ordering import nested_dissection, order_unknowns


def test_order_is_a_permutation_and_the_halves_before_the_last_separator_are_uncoupled():
    """George (1973): ordered as (part A, part B, separator S), A and B share no coupling, so
    the factor's fill never joins them. Checked on the top level of a random 3D cloud. Indices: compared
    exactly."""
    rng = np.random.default_rng(3)
    points = rng.uniform(0, 1, size=(3000, 3)) * [4.0, 2.0, 0.5]
    reach = 0.15
    order = nested_dissection(points, reach, leaf=32)
    assert np.array_equal(np.sort(order), np.arange(len(points)))
    # the last separator is the slab across the longest axis (x) at the median
    middle = np.median(points[:, 0])
    in_slab = np.abs(points[:, 0] - middle) <= reach / 2
    assert set(order[-in_slab.sum() :]) == set(np.flatnonzero(in_slab))
    left, right = points[points[:, 0] < middle - reach / 2], points[points[:, 0] > middle + reach / 2]
    assert cKDTree(left).count_neighbors(cKDTree(right), reach) == 0


def test_unknowns_follow_their_points():
    points = np.c_[np.arange(10.0), np.zeros(10), np.zeros(10)]
    unknown_points = np.repeat(np.arange(10), 3)
    perm = order_unknowns(unknown_points, points, reach=1.0)
    rank = np.empty(10, dtype=int)
    rank[nested_dissection(points, 1.0)] = np.arange(10)
    assert np.all(np.diff(rank[unknown_points[perm]]) >= 0)
