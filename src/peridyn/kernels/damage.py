"""Bond-breaking kernel."""

import numba
import numpy as np


@numba.njit(parallel=True, cache=True)
def break_stretched_bonds(x, u, offsets, nbr, length, critical_stretch, breakable, intact):
    """Break (IN/OUT ``intact``) every breakable bond whose stretch exceeds its critical value.

    Both directed copies of a bond see the same stretch, so they break in the
    same call. Returns the number of directed bonds broken.
    """
    n = x.shape[0]
    count = np.zeros(n, dtype=np.int64)
    for i in numba.prange(n):
        x0, x1, x2 = x[i, 0], x[i, 1], x[i, 2]
        u0, u1, u2 = u[i, 0], u[i, 1], u[i, 2]
        broken = 0
        for b in range(offsets[i], offsets[i + 1]):
            j = nbr[b]
            d0 = (x[j, 0] - x0) + (u[j, 0] - u0)
            d1 = (x[j, 1] - x1) + (u[j, 1] - u1)
            d2 = (x[j, 2] - x2) + (u[j, 2] - u2)
            limit = length[b] * (1.0 + critical_stretch[b])
            # squared lengths: no square root, and the cheap test first
            if d0 * d0 + d1 * d1 + d2 * d2 > limit * limit and intact[b] and breakable[b]:
                intact[b] = False
                broken += 1
        count[i] = broken
    return count.sum()


@numba.njit(parallel=True, cache=True)
def damage_index(offsets, weight, intact, phi):
    """``phi`` (OUT): 1 - (intact weight) / (total weight) of each family."""
    n = offsets.shape[0] - 1
    for i in numba.prange(n):
        total = 0.0
        alive = 0.0
        for b in range(offsets[i], offsets[i + 1]):
            total += weight[b]
            if intact[b]:
                alive += weight[b]
        phi[i] = 1.0 - alive / total if total > 0 else 0.0
    return phi
