"""``linalg.stiffness.pair_matrix``, written row chunk by row chunk (``kernels.pairs``) without
a COO list, is bit for bit the matrix scipy makes of the whole COO list (``coo_matrix(...).tocsr()``,
the former construction): a stable sort by row, each row sorted by column and its duplicates
summed in that order. Same bits keep the stiffness and the AMG proxy, hence every modal and
static result built on them, unchanged (issue 22, item 3)."""

import numpy as np
import pytest
import scipy.sparse as sp
from conftest import small_model

from peridyn.kernels.reference.pairs import pair_entries
from peridyn.linalg import stiffness


def _bonds(model):
    """Bond ends, unit vectors and coefficients of the intact bonds, as ``stiffness_parts``
    passes them."""
    b = model.bonds
    i = b.owners()[b.intact]
    j = b.neighbours[b.intact]
    x = model.body.points
    n_vec = (x[j] - x[i]) / b.length[b.intact, None]
    return i, j, n_vec, model.body.volumes[i] * model.linearisation().pair[b.intact]


@pytest.mark.bitwise
@pytest.mark.parametrize("chunk", [2**25, 1000, 1], ids=["one chunk", "chunks", "a row per chunk"])
def test_pair_matrix_is_scipys_coo_conversion(monkeypatch, chunk):
    """The pair matrix assembled in chunks of any size is scipy's COO to CSR conversion of the same
    entries: the structure exactly, and the values bit for bit: both sum each entry's duplicates in the
    list's order, with the same products, and the kernels are compiled without fast-math."""
    model = small_model("lps", n=6)
    i, j, n_vec, coef = _bonds(model)
    n = model.body.n_points
    rows, cols, values = pair_entries(i, j, n_vec, coef)
    expected = sp.coo_matrix((values, (rows, cols)), shape=(3 * n, 3 * n)).tocsr()
    monkeypatch.setattr(stiffness, "PAIR_CHUNK_ENTRIES", chunk)
    got = stiffness.pair_matrix(i, j, n_vec, coef, n)
    assert got.has_canonical_format
    np.testing.assert_array_equal(got.indptr, expected.indptr)
    np.testing.assert_array_equal(got.indices, expected.indices)
    np.testing.assert_array_equal(got.data, expected.data)  # exact: the same sums in the same order


@pytest.mark.bitwise
@pytest.mark.parametrize("chunk", [2**22, 1000, 1], ids=["one chunk", "chunks", "a row per chunk"])
def test_zeros_dropped_chunk_by_chunk_are_the_whole_matrix_without_them(monkeypatch, chunk):
    """``drop_zeros`` (the AMG proxy's: an axis-parallel bond's block is mostly zeros, which a
    whole matrix held all at once) gives the canonical matrix less its zero entries, same bits. The same
    kernels and the same sums in the same order, with no fast-math."""
    model = small_model("pmb", n=6)  # a grid: most bonds along an axis or a face diagonal
    i, j, n_vec, coef = _bonds(model)
    n = model.body.n_points
    expected = stiffness.pair_matrix(i, j, n_vec, coef, n)
    zeros = int(np.count_nonzero(expected.data == 0))
    expected.eliminate_zeros()
    monkeypatch.setattr(stiffness, "PAIR_CHUNK_ENTRIES", chunk)
    got = stiffness.pair_matrix(i, j, n_vec, coef, n, drop_zeros=True)
    assert zeros > got.nnz // 10  # there were zeros to drop
    assert got.has_canonical_format and not np.any(got.data == 0)
    for attr in ("indptr", "indices", "data"):
        np.testing.assert_array_equal(getattr(got, attr), getattr(expected, attr))


def test_pair_matrix_without_bonds():
    got = stiffness.pair_matrix(np.zeros(0, int), np.zeros(0, np.int32), np.zeros((0, 3)), np.zeros(0), 4)
    assert got.shape == (12, 12) and got.nnz == 0
