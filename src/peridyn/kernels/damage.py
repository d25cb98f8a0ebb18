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
        for b in range(offsets[i], offsets[i + 1]):
            if not (intact[b] and breakable[b]):
                continue
            j = nbr[b]
            r2 = 0.0
            for a in range(3):
                d = (x[j, a] - x[i, a]) + (u[j, a] - u[i, a])
                r2 += d * d
            if np.sqrt(r2) > length[b] * (1.0 + critical_stretch[b]):
                intact[b] = False
                count[i] += 1
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
