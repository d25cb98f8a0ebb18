"""Pair-matrix kernels (``peridyn.kernels.pairs``) against their NumPy reference
(``kernels.reference.pairs``): exact, since the order and rounding of each entry are the
kernels' definition (``linalg.stiffness.pair_matrix`` relies on them for its bits)."""

import numpy as np
import pytest
from kernel_inputs import jittered_families

from peridyn.kernels import pairs
from peridyn.kernels.reference import owners
from peridyn.kernels.reference import pairs as ref

pytestmark = pytest.mark.kernels


def _bonds(rng):
    """Bond ends (owners int64, neighbours int32), unit vectors and coefficients of the
    intact bonds of a small jittered grid."""
    fam = jittered_families(rng)
    i = owners(fam.offsets)[fam.intact]
    j = fam.nbr[fam.intact]
    n_vec = fam.x[j] - fam.x[i]
    n_vec /= np.linalg.norm(n_vec, axis=1)[:, None]
    return fam.n, i, j, n_vec, rng.uniform(0.5, 2.0, len(i)) * 1e9


def test_pair_row_counts(rng):
    """Nonzeros per row of the pair matrix (int64): counts, compared exactly."""
    n, i, j, _, _ = _bonds(rng)
    counts = pairs.pair_row_counts(i, j, n)
    assert counts.dtype == np.int64
    np.testing.assert_array_equal(counts, ref.pair_row_counts(i, j, n))


@pytest.mark.bitwise
@pytest.mark.parametrize("rows", [(0, None), (7, 31)], ids=["all rows", "a middle chunk"])
def test_pair_rows(rng, rows):
    """All rows at once and a chunk of rows starting mid-point (row 7 = point 2, y). Column indices
    exactly, and the values bit for bit: each is the reference's products in the same order, in a kernel
    compiled without fast-math."""
    n, i, j, n_vec, coef = _bonds(rng)
    start, stop = rows[0], 3 * n if rows[1] is None else rows[1]
    ends = np.cumsum(ref.pair_row_counts(i, j, n))
    before = ends[start - 1] if start else 0
    indptr = np.concatenate([[0], ends[start:stop] - before])
    indices = np.empty(indptr[-1], dtype=np.int32)
    data = np.empty(indptr[-1])
    pairs.pair_rows(i, j, n_vec, coef, start, indptr, indices, data)
    expected_indices, expected_data = ref.pair_rows(i, j, n_vec, coef, start, indptr)
    np.testing.assert_array_equal(indices, expected_indices)
    np.testing.assert_array_equal(data, expected_data)
