"""Block-sparse kernels (``peridyn.kernels.bsr``) against their NumPy references on the dense
matrix (``kernels.reference.bsr``), float64 (the block AMG's dtype)."""

import numpy as np
import pytest
from kernel_inputs import TOL64, assert_close

from peridyn.kernels import bsr
from peridyn.kernels.reference import bsr as ref

pytestmark = pytest.mark.kernels


def _random_bsr(rng, pattern, rows, cols):
    """BSR arrays (indptr, indices int32 sorted per row, data (nnz, rows, cols)) of a block
    pattern (n_block_rows, n_block_cols) bool, random blocks."""
    block_rows, block_cols = np.nonzero(pattern)
    indptr = np.concatenate([[0], np.cumsum(pattern.sum(axis=1))]).astype(np.int32)
    data = rng.standard_normal((len(block_cols), rows, cols))
    return indptr, block_cols.astype(np.int32), data


def _rectangular(rng):
    """A 6 x 5 block matrix of 3 x 2 blocks (a prolongator's shape), an empty block row
    included, and its dense magnitudes |A|."""
    pattern = rng.random((6, 5)) < 0.5
    pattern[2] = False
    indptr, indices, data = _random_bsr(rng, pattern, 3, 2)
    return indptr, indices, data, ref.bsr_to_dense(indptr, indices, np.abs(data), 5)


def test_add_row_product(rng):
    """acc + scale (A x)_i for every block row: scale |acc| + |scale| |A| |x| (products and
    sums of a few terms)."""
    indptr, indices, data, magnitude = _rectangular(rng)
    x = rng.standard_normal((5, 2, 4))
    for i in range(6):
        for scale in (1.0, -2.5):
            acc = rng.standard_normal((3, 4))
            expected = ref.add_row_product(indptr, indices, data, x, i, scale, acc)
            got = acc.copy()
            bsr.add_row_product(indptr, indices, data, x, i, scale, got)
            row_magnitude = (magnitude @ np.abs(x).reshape(10, 4))[3 * i : 3 * i + 3]
            assert_close(got, expected, TOL64, np.abs(acc) + abs(scale) * row_magnitude)


def test_bsr_matmat(rng):
    """A x for each group of vectors: scale |A| |x|."""
    indptr, indices, data, magnitude = _rectangular(rng)
    x = rng.standard_normal((2, 5, 2, 4))
    out = np.full((2, 6, 3, 4), np.nan)
    got = bsr.bsr_matmat(indptr, indices, data, x, out)
    scale = (magnitude @ np.abs(x).reshape(2, 10, 4)).reshape(2, 6, 3, 4)
    assert_close(got, ref.bsr_matmat(indptr, indices, data, x), TOL64, scale)


def test_symmetric_block_gauss_seidel(rng):
    """One forward and one backward sweep, against the textbook splitting (D + L) x' = b - U x,
    (D + U) x'' = b - L x' on the dense matrix. A is symmetric and strictly block diagonally
    dominant (off-diagonal entries in [-1, 1], diagonal 3 R n), so the triangular solves are
    well conditioned and both sides get x'' to ~1e-15 of its largest entry."""
    n, r = 7, 3
    pattern = rng.random((n, n)) < 0.4
    pattern = pattern | pattern.T | np.eye(n, dtype=bool)
    blocks = np.where(pattern[:, :, None, None], rng.uniform(-1.0, 1.0, (n, n, r, r)), 0.0)
    dense = blocks.transpose(0, 2, 1, 3).reshape(n * r, n * r)
    dense = dense + dense.T + 3 * r * n * np.eye(n * r)
    block_rows, block_cols = np.nonzero(pattern)
    data = dense.reshape(n, r, n, r).transpose(0, 2, 1, 3)[block_rows, block_cols]
    indptr = np.concatenate([[0], np.cumsum(pattern.sum(axis=1))]).astype(np.int32)
    indices = block_cols.astype(np.int32)
    diag_inv = np.linalg.inv(data[block_rows == block_cols])
    x0 = rng.standard_normal((2, n, r, 3))
    b = rng.standard_normal((2, n, r, 3))
    x = x0.copy()
    bsr.symmetric_block_gauss_seidel(indptr, indices, data, diag_inv, x, b)
    expected = ref.symmetric_block_gauss_seidel(indptr, indices, data, x0, b)
    assert_close(x, expected, TOL64, np.abs(expected).max())
