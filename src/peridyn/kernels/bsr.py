"""Block-sparse (BSR) kernels of the block AMG V-cycle (``peridyn.linalg.block_amg``): products
and symmetric block Gauss-Seidel sweeps on a block of ``k`` vectors at once."""

import numba
import numpy as np


@numba.njit(cache=True)
def add_row_product(indptr, indices, data, x, i, scale, acc):
    """``acc`` (R, kg) += scale * (A x)_i for block row ``i`` of A (BSR arrays, ``data``
    (nnz_blocks, R, C)) and one group's ``x`` (n_block_cols, C, kg)."""
    rows, cols, kg = data.shape[1], data.shape[2], x.shape[2]
    for p in range(indptr[i], indptr[i + 1]):
        j = indices[p]
        for a in range(rows):
            for c in range(cols):
                v = scale * data[p, a, c]
                for q in range(kg):
                    acc[a, q] += v * x[j, c, q]


@numba.njit(parallel=True, cache=True)
def bsr_matmat(indptr, indices, data, x, out):
    """``out`` (OUT, (groups, n_block_rows, R, kg)) = A x for each group; ``x`` (groups,
    n_block_cols, C, kg); A in BSR form: ``data`` (nnz_blocks, R, C)."""
    for g in numba.prange(x.shape[0]):
        for i in range(out.shape[1]):
            out[g, i] = 0.0
            add_row_product(indptr, indices, data, x[g], i, 1.0, out[g, i])
    return out


@numba.njit(parallel=True, cache=True)
def symmetric_block_gauss_seidel(indptr, indices, data, diag_inv, x, b):
    """One forward then one backward block Gauss-Seidel sweep on A x = b, in place on ``x``
    (groups, n_blocks, R, kg); ``diag_inv`` (n_blocks, R, R): inverses of A's diagonal blocks."""
    groups, n, rows, kg = x.shape[0], x.shape[1], x.shape[2], x.shape[3]
    for g in numba.prange(groups):
        r = np.empty((rows, kg), dtype=x.dtype)
        for t in range(2 * n):
            i = t if t < n else 2 * n - 1 - t
            r[:, :] = b[g, i]
            add_row_product(indptr, indices, data, x[g], i, -1.0, r)
            for a in range(rows):
                for c in range(rows):
                    v = diag_inv[i, a, c]
                    for q in range(kg):
                        x[g, i, a, q] += v * r[c, q]
    return x
