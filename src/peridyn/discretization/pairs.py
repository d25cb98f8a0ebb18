"""Bond pairs, each bond once, and the row blocks that fix the order of the PMB force's sums.

A half list holds each bond (i, j) once, at its lower row i: the float64 PMB force computes a
pair's term once and adds it to both rows (``kernels.pmb.pmb_pair_force``), streaming about
half the per-bond bytes of the full list. Its sums arrive at a row from rows run on other
threads, so their order is fixed by row blocks instead of the family order alone:

- the rows are cut into :func:`row_blocks`, each at least the index bandwidth (the largest
  ``|j - i|`` of a bond) long, so a row's neighbours lie in its own block or the ones beside it;
- row i sums its family in two chains, each in the written (ascending j) order: ``h`` over the
  neighbours in earlier blocks, ``g`` over the others, and ``f_i = h + g``;
  :func:`block_split` gives where ``h`` ends in each family.

The full-list kernel (``kernels.pmb.pmb_force`` with ``split``) sums in the same order, row by
row: an MPI rank, which runs it on its own rows, gives the serial run's bits. A rank's part
numbers its rows differently, so it takes the blocks and the split from the whole body's row
numbers (``Bonds.global_rows``, ``Bonds.row_blocks``, set by ``setup.build``).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from peridyn.discretization.bonds import family_sums


def index_bandwidth(offsets: np.ndarray, neighbours: np.ndarray, rows: np.ndarray | None = None) -> int:
    """max ``|j - i|`` over the bonds (i, j) of the CSR families; ``rows`` (n_points,) int: each
    row's number to use instead of its index (a rank's global rows); 0 without bonds."""
    owners = np.repeat(np.arange(len(offsets) - 1), np.diff(offsets))
    nbr = neighbours.astype(np.int64)
    if rows is not None:
        owners, nbr = rows[owners], rows[nbr]
    return int(np.max(np.abs(nbr - owners), initial=0))


def row_blocks(n_points: int, bandwidth: int) -> np.ndarray:
    """(n_blocks + 1,) int64 bounds of ``n_points // bandwidth`` blocks of about equal rows (at
    least one), each at least ``bandwidth`` rows long."""
    n_blocks = max(1, n_points // max(bandwidth, 1))
    return (np.arange(n_blocks + 1, dtype=np.int64) * n_points) // n_blocks


def block_split(
    offsets: np.ndarray, neighbours: np.ndarray, blocks: np.ndarray, rows: np.ndarray | None = None
) -> np.ndarray | None:
    """(n_points,) int64: the index of the first bond of each family whose neighbour is in the
    row's block or after (the end of the ``h`` chain); ``rows`` as in :func:`index_bandwidth`,
    ``blocks`` in those numbers. None when those bonds are not all after the others in some
    family (families not in ascending order): the families are then summed in one chain."""
    n = len(offsets) - 1
    counts = np.diff(offsets)
    own = np.arange(n, dtype=np.int64) if rows is None else np.asarray(rows, dtype=np.int64)
    start = blocks[np.searchsorted(blocks, own, side="right") - 1]
    nbr = neighbours if rows is None else own[neighbours]
    before = nbr < np.repeat(start, counts)
    first = np.zeros(len(before), dtype=bool)  # each family's first bond
    first[offsets[:-1][counts > 0]] = True
    if np.any(before[1:] & ~before[:-1] & ~first[1:]):  # an earlier-block neighbour after another
        return None
    return offsets[:-1] + family_sums(offsets, before).astype(np.int64)


class HalfList(NamedTuple):
    """The pairs (i, j), j > i, of full-list families, at row i in ascending j; per pair the full
    list's values. Arrays: ``offsets`` (n_points + 1,) int64, ``neighbours`` (n_pairs,) int32,
    ``xi`` (n_pairs, 3) m, ``inv_len`` 1/m, ``k`` and ``k_rev`` (n_pairs,) (the stiffness of
    i -> j and of j -> i), ``intact_at`` (n_points,) int64 (the full-list index of row i's
    first pair: the pair's ``intact`` is read there), ``blocks`` (:func:`row_blocks`)."""

    offsets: np.ndarray
    neighbours: np.ndarray
    xi: np.ndarray
    inv_len: np.ndarray
    k: np.ndarray
    k_rev: np.ndarray
    intact_at: np.ndarray
    blocks: np.ndarray


def half_list(
    bonds, x: np.ndarray, inv_len: np.ndarray, k: np.ndarray, blocks: np.ndarray
) -> HalfList | None:
    """The :class:`HalfList` of ``bonds`` (``Bonds`` of a whole body of points ``x`` (n_points, 3)
    m) with the per-bond ``inv_len`` and ``k`` (n_bonds,); None unless every family is in
    strictly ascending order and every bond has its reverse with the same ``1/|xi|`` (the half
    list reproduces the full list's sums only then). A pair's ``xi`` is ``x_j - x_i``, the
    subtraction of ``kernels.bond_search.initial_bond_vectors``. Its temporaries hold about
    30 B a directed bond."""
    offsets, nbr = bonds.offsets, bonds.neighbours
    n = len(offsets) - 1
    counts = np.diff(offsets)
    owners = np.repeat(np.arange(n, dtype=np.int32), counts)
    same = owners[1:] == owners[:-1]
    if np.any((nbr[1:] <= nbr[:-1]) & same):
        return None
    upper = nbr > owners
    i_up, j_up = owners[upper], nbr[upper]
    lower = np.flatnonzero(~upper)  # the bonds j -> i, j > i: in (j, i) order
    if len(lower) != len(j_up):
        return None
    by_j = np.argsort(j_up, kind="stable")  # the pairs in (j, i) order
    if not (np.array_equal(owners[lower], j_up[by_j]) and np.array_equal(nbr[lower], i_up[by_j])):
        return None
    rev = np.empty(len(j_up), dtype=np.int64)
    rev[by_j] = lower
    del owners, lower, by_j
    inv_up = inv_len[upper]
    if not np.array_equal(inv_len[rev], inv_up):
        return None
    xi = np.empty((len(j_up), 3))
    for a in range(3):  # a column at a time: small temporaries
        xi[:, a] = x[j_up, a] - x[i_up, a]
    n_upper = family_sums(offsets, upper).astype(np.int64)
    return HalfList(
        offsets=np.concatenate([[0], np.cumsum(n_upper)]).astype(np.int64),
        neighbours=np.ascontiguousarray(j_up),
        xi=xi,
        inv_len=inv_up,
        k=k[upper],
        k_rev=k[rev],
        intact_at=offsets[1:] - n_upper,
        blocks=blocks,
    )
