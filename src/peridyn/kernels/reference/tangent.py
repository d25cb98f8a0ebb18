"""Reference of ``peridyn.kernels.tangent``: the CSR arrays of the bond-block matrix of the
consistent tangent (``peridyn.linalg.tangent._bond_blocks``)."""

import numpy as np

from peridyn.kernels.reference import as64, owners


def bond_blocks_csr(offsets, nbr, n_vec, stretch, geometric):
    """``(indptr, indices, data)`` of the (3 n, 3 n) matrix with, for every bond b = (i, j),
    ``B_b = stretch_b n n^T + geometric_b (I - n n^T)`` (n = ``n_vec[b]``) added on block
    (i, j) and subtracted on block (i, i).

    Stored with full 3 x 3 blocks: row 3 i + a holds the columns 3 k + c of k = i and of
    i's family, in increasing order (zeros included).
    """
    n = len(offsets) - 1
    i = owners(offsets)
    j = np.asarray(nbr, dtype=np.int64)
    n_vec, stretch, geometric = as64(n_vec, stretch, geometric)
    outer = n_vec[:, :, None] * n_vec[:, None, :]
    block = stretch[:, None, None] * outer + geometric[:, None, None] * (np.eye(3) - outer)
    blocks = np.zeros((n, n, 3, 3))
    np.add.at(blocks, (i, j), block)
    np.add.at(blocks, (i, i), -block)
    dense = blocks.transpose(0, 2, 1, 3).reshape(3 * n, 3 * n)
    pattern = np.eye(n, dtype=bool)
    pattern[i, j] = True
    rows, cols = np.nonzero(np.kron(pattern, np.ones((3, 3), dtype=bool)))
    indptr = np.concatenate([[0], np.cumsum(np.bincount(rows, minlength=3 * n))])
    return indptr, cols, dense[rows, cols]


def deformed_bonds(x, u, offsets, nbr):
    """(n_bonds, 3): x_j - x_i + u_j - u_i of every directed bond, rounded in that order."""
    i, j = owners(offsets), np.asarray(nbr, dtype=np.int64)
    return x[j] - x[i] + u[j] - u[i]


def tangent_extension(offsets, nbr, n_vec, axial, v):
    """``(e, theta)``: e_b = n_b . (v_j - v_i) per bond, theta_i = sum over i's bonds of
    axial_b e_b."""
    i, j = owners(offsets), np.asarray(nbr, dtype=np.int64)
    n_vec, axial, v = as64(n_vec, axial, v)
    e = np.einsum("ba,ba->b", n_vec, v[j] - v[i])
    return e, np.bincount(i, weights=axial * e, minlength=len(offsets) - 1)


def tangent_action(offsets, nbr, n_vec, axial, along, geometric, p, e, v):
    """(n, 3): sum over each point i's bonds b = (i, j) of (axial_b (p_i + p_j) + along_b e_b) n_b
    + geometric_b (v_j - v_i)."""
    i, j = owners(offsets), np.asarray(nbr, dtype=np.int64)
    n_vec, axial, along, geometric, p, e, v = as64(n_vec, axial, along, geometric, p, e, v)
    t = axial * (p[i] + p[j]) + along * e
    terms = t[:, None] * n_vec + geometric[:, None] * (v[j] - v[i])
    out = np.zeros((len(offsets) - 1, 3))
    np.add.at(out, i, terms)
    return out
