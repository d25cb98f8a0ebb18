"""Pair-matrix kernels: the rows of ``peridyn.linalg.stiffness.pair_matrix`` before their
duplicates are summed, written straight into CSR arrays.

The pair matrix is the sum over bonds b = (i, j) of ``h coef_b n n^T`` (n = ``n_vec[b]``) on
the four 3 x 3 blocks ii (h = 1/2), jj (1/2), ij (-1/2) and ji (-1/2). Its entries, listed
block group by block group (all ii blocks in bond order, then jj, ij, ji), each block row
by row (a), column by column (c), are the COO triplets of the matrix; a stable sort of that
list by row (scipy's ``coo_tocsr``) gives, per row, the order these kernels write.
"""

import numba
import numpy as np


@numba.njit(cache=True)
def pair_row_counts(i, j, n_points):
    """(3 n_points,) int64: entries (duplicates included) of each row of the pair matrix of
    the bonds (``i``, ``j``) (n_bonds,) int: 6 per bond end, on each of its 3 rows."""
    counts = np.zeros(3 * n_points, dtype=np.int64)
    for b in range(i.shape[0]):
        for a in range(3):
            counts[3 * i[b] + a] += 6
            counts[3 * j[b] + a] += 6
    return counts


@numba.njit(cache=True)
def pair_rows(i, j, n_vec, coef, row_start, indptr, indices, data):
    """Entries of the pair-matrix rows ``row_start`` .. ``row_start + len(indptr) - 2``, with
    their duplicates, in COO-list order within each row.

    ``i``, ``j``: (n_bonds,) int bond ends; ``n_vec``: (n_bonds, 3) float64 unit vectors;
    ``coef``: (n_bonds,) float64. ``indptr``: (n_rows + 1,) int64, the rows' offsets in
    ``indices`` ((nnz,) int32, OUT: columns) and ``data`` ((nnz,) float64, OUT: values
    ``h * ((coef * n_a) * n_c)``, rounded as the NumPy expression of ``pair_matrix``).
    """
    n_rows = indptr.shape[0] - 1
    row_end = row_start + n_rows
    fill = indptr[:-1].copy()
    for group in range(4):
        h = 0.5 if group < 2 else -0.5
        for b in range(i.shape[0]):
            p = i[b] if group == 0 or group == 2 else j[b]
            q = i[b] if group == 0 or group == 3 else j[b]
            for a in range(3):
                row = 3 * p + a
                if row < row_start or row >= row_end:
                    continue
                at = fill[row - row_start]
                scaled = coef[b] * n_vec[b, a]
                for c in range(3):
                    indices[at + c] = 3 * q + c
                    data[at + c] = h * (scaled * n_vec[b, c])
                fill[row - row_start] = at + 3
