"""References of ``peridyn.kernels.bsr``: block-sparse products and the symmetric block
Gauss-Seidel sweep, on the dense matrix.

A BSR matrix A of ``n_block_rows x n_block_cols`` blocks of R x C is given by ``indptr``,
``indices`` and ``data`` (nnz_blocks, R, C): block row i holds the blocks
``data[indptr[i]:indptr[i+1]]`` in the block columns ``indices[indptr[i]:indptr[i+1]]``.
The vectors come in groups of ``kg``: ``x`` (n_block_cols, C, kg) for one group.
"""

import numpy as np


def bsr_to_dense(indptr, indices, data, n_block_cols):
    """The dense (n_block_rows R, n_block_cols C) float64 matrix of the BSR arrays."""
    data = np.asarray(data, dtype=np.float64)
    rows, cols = data.shape[1], data.shape[2]
    n_rows = len(indptr) - 1
    block_row = np.repeat(np.arange(n_rows), np.diff(indptr))
    blocks = np.zeros((n_rows, n_block_cols, rows, cols))
    np.add.at(blocks, (block_row, np.asarray(indices)), data)
    return blocks.transpose(0, 2, 1, 3).reshape(n_rows * rows, n_block_cols * cols)


def add_row_product(indptr, indices, data, x, i, scale, acc):
    """``acc + scale (A x)_i`` (R, kg) for block row ``i`` and one group's ``x``."""
    dense = bsr_to_dense(indptr, indices, data, x.shape[0])
    r = data.shape[1]
    ax = dense @ np.asarray(x, dtype=np.float64).reshape(-1, x.shape[2])
    return np.asarray(acc, dtype=np.float64) + scale * ax[r * i : r * (i + 1)]


def bsr_matmat(indptr, indices, data, x):
    """(groups, n_block_rows, R, kg): A x for each group of ``x`` (groups, n_block_cols, C, kg)."""
    dense = bsr_to_dense(indptr, indices, data, x.shape[1])
    groups, kg, r = x.shape[0], x.shape[3], data.shape[1]
    ax = dense @ np.asarray(x, dtype=np.float64).reshape(groups, -1, kg)
    return ax.reshape(groups, -1, r, kg)


def symmetric_block_gauss_seidel(indptr, indices, data, x, b):
    """One forward then one backward block Gauss-Seidel sweep on A x = b for square blocks,
    the textbook splitting A = L + D + U (block lower, diagonal, upper parts):

        (D + L) x' = b - U x,     (D + U) x'' = b - L x',

    for each group of ``x``, ``b`` (groups, n_blocks, R, kg). Returns x'' (float64). (The
    kernel takes the inverses of D's blocks, ``diag_inv``; this uses A itself.)
    """
    groups, n, r, kg = x.shape
    a = bsr_to_dense(indptr, indices, data, n)
    block = np.arange(n * r) // r
    lower = np.where(block[:, None] > block[None, :], a, 0.0)
    upper = np.where(block[:, None] < block[None, :], a, 0.0)
    diagonal = a - lower - upper
    x = np.asarray(x, dtype=np.float64).reshape(groups, n * r, kg)
    b = np.asarray(b, dtype=np.float64).reshape(groups, n * r, kg)
    forward = np.linalg.solve(diagonal + lower, b - upper @ x)
    backward = np.linalg.solve(diagonal + upper, b - lower @ forward)
    return backward.reshape(groups, n, r, kg)
