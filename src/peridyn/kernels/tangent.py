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
