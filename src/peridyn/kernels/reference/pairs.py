"""Reference of ``peridyn.kernels.pairs``: the pair matrix's COO list, sorted by row."""

import numpy as np


def pair_entries(i, j, n_vec, coef):
    """The COO list ``(rows, cols, values)`` (each (36 n_bonds,)) of the pair matrix in the
    order of the kernels' module docstring: block groups ii, jj, ij, ji; in each, bond by
    bond, row a by row, column c by column; values ``h * ((coef * n_a) * n_c)``, h = 1/2 on
    ii and jj, -1/2 on ij and ji (the rounding of the NumPy expression is the definition)."""
    i = np.asarray(i, dtype=np.int64)
    j = np.asarray(j, dtype=np.int64)
    outer = coef[:, None, None] * n_vec[:, :, None] * n_vec[:, None, :]  # (n_bonds, a, c)
    a = np.arange(3)
    rows, cols, values = [], [], []
    for p, q, h in ((i, i, 0.5), (j, j, 0.5), (i, j, -0.5), (j, i, -0.5)):
        rows.append(np.broadcast_to(3 * p[:, None, None] + a[None, :, None], outer.shape).ravel())
        cols.append(np.broadcast_to(3 * q[:, None, None] + a[None, None, :], outer.shape).ravel())
        values.append(h * outer.ravel())
    return np.concatenate(rows), np.concatenate(cols), np.concatenate(values)


def pair_row_counts(i, j, n_points):
    """(3 n_points,) int64: entries of each row in the COO list."""
    rows, _, _ = pair_entries(i, j, np.zeros((len(i), 3)), np.zeros(len(i)))
    return np.bincount(rows, minlength=3 * n_points).astype(np.int64)


def pair_rows(i, j, n_vec, coef, row_start, indptr):
    """``(indices, data)`` of the rows ``row_start`` .. ``row_start + len(indptr) - 2``: the COO
    list stably sorted by row (each row keeps the list's order), those rows' entries."""
    rows, cols, values = pair_entries(i, j, n_vec, coef)
    order = np.argsort(rows, kind="stable")
    rows, cols, values = rows[order], cols[order], values[order]
    kept = (rows >= row_start) & (rows < row_start + len(indptr) - 1)
    return cols[kept].astype(np.int32), values[kept]
