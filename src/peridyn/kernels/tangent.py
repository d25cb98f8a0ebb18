"""Tangent-stiffness kernel: the CSR arrays of the per-bond 3 x 3 blocks of the consistent
tangent (``peridyn.linalg.tangent``)."""

import numba
import numpy as np


@numba.njit(cache=True)
def bond_blocks_csr(offsets, nbr, n_vec, stretch, geometric):
    """CSR arrays of ``peridyn.linalg.tangent._bond_blocks``: row 3 i + a holds the dofs of i and its family,
    in increasing order (families are sorted by neighbour)."""
    n = offsets.shape[0] - 1
    nnz = 9 * (offsets[n] + n)
    indptr = np.empty(3 * n + 1, dtype=np.int64)
    indices = np.empty(nnz, dtype=np.int64)
    data = np.zeros(nnz)
    indptr[0] = 0
    pos = 0
    for i in range(n):
        lo, hi = offsets[i], offsets[i + 1]
        width = 3 * (hi - lo + 1)
        # slot of point i among its sorted family
        self_slot = 0
        for b in range(lo, hi):
            if nbr[b] < i:
                self_slot += 1
        for a in range(3):
            row = 3 * i + a
            start = pos + a * width
            for b in range(lo, hi):
                slot = b - lo + (1 if b - lo >= self_slot else 0)
                for c in range(3):
                    indices[start + 3 * slot + c] = 3 * nbr[b] + c
                    block = (stretch[b] - geometric[b]) * n_vec[b, a] * n_vec[b, c]
                    if a == c:
                        block += geometric[b]
                    data[start + 3 * slot + c] += block
                    data[start + 3 * self_slot + c] -= block
            for c in range(3):
                indices[start + 3 * self_slot + c] = 3 * i + c
            indptr[row + 1] = start + width
        pos += 3 * width
    return indptr, indices, data


@numba.njit(parallel=True, cache=True)
def deformed_bonds(x, u, offsets, nbr, out):
    """``out`` (OUT, (n_bonds, 3), m): the deformed bond vectors (x_j - x_i + u_j) - u_i, rounded
    in that order (as NumPy's ``x[j] - x[i] + u[j] - u[i]``)."""
    n = x.shape[0]
    for i in numba.prange(n):
        for b in range(offsets[i], offsets[i + 1]):
            j = nbr[b]
            for a in range(3):
                out[b, a] = x[j, a] - x[i, a] + u[j, a] - u[i, a]
    return out


@numba.njit(parallel=True, cache=True)
def tangent_extension(offsets, nbr, n_vec, axial, v, e, theta):
    """First pass of the tangent's product with ``v`` (n_points, 3): ``e`` (OUT, (n_bonds,)) the
    extension n . (v_j - v_i) of each bond along its deformed unit vector ``n_vec`` (n_bonds, 3),
    and ``theta`` (OUT, (n_points,)) each point's sum of axial e (``peridyn.linalg.tangent``)."""
    n = offsets.shape[0] - 1
    for i in numba.prange(n):
        s = 0.0
        for b in range(offsets[i], offsets[i + 1]):
            j = nbr[b]
            eb = (
                n_vec[b, 0] * (v[j, 0] - v[i, 0])
                + n_vec[b, 1] * (v[j, 1] - v[i, 1])
                + n_vec[b, 2] * (v[j, 2] - v[i, 2])
            )
            e[b] = eb
            s += axial[b] * eb
        theta[i] = s


@numba.njit(parallel=True, cache=True)
def tangent_action(offsets, nbr, n_vec, axial, along, geometric, p, e, v, out):
    """Second pass: ``out`` (OUT, (n_points, 3)) = d f_i = sum_j [(axial (p_i + p_j) + along e) n
    + geometric (v_j - v_i)] over each point's bonds, with ``e`` and ``p`` (n_points,) from the
    first pass (``tangent_extension``; p = dilatation coefficient times theta)."""
    n = offsets.shape[0] - 1
    for i in numba.prange(n):
        f0 = 0.0
        f1 = 0.0
        f2 = 0.0
        for b in range(offsets[i], offsets[i + 1]):
            j = nbr[b]
            t = axial[b] * (p[i] + p[j]) + along[b] * e[b]
            g = geometric[b]
            f0 += t * n_vec[b, 0] + g * (v[j, 0] - v[i, 0])
            f1 += t * n_vec[b, 1] + g * (v[j, 1] - v[i, 1])
            f2 += t * n_vec[b, 2] + g * (v[j, 2] - v[i, 2])
        out[i, 0] = f0
        out[i, 1] = f1
        out[i, 2] = f2
