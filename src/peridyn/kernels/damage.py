"""Bond-breaking kernel."""

import numba
import numpy as np

from peridyn.kernels import FASTMATH, bond_differences


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def break_stretched_bonds(x, u, offsets, nbr, length, critical_stretch, breakable, intact):
    """Break (IN/OUT ``intact``) every breakable bond whose stretch exceeds its critical value.

    Both directed copies of a bond see the same stretch, so they break in the
    same call. Returns the number of directed bonds broken. Laid out like the force
    kernels (flat arrays, per-family slices, squared lengths) so that the stretch test
    vectorises; the rare write is the only branch.
    """
    n = x.shape[0]
    xf = x.reshape(3 * n)
    uf = u.reshape(3 * n)
    count = np.zeros(n, dtype=np.int64)
    for i in numba.prange(n):
        xi0, xi1, xi2 = xf[3 * i], xf[3 * i + 1], xf[3 * i + 2]
        ui0, ui1, ui2 = uf[3 * i], uf[3 * i + 1], uf[3 * i + 2]
        lo = offsets[i]
        hi = offsets[i + 1]
        fam = nbr[lo:hi]
        ln = length[lo:hi]
        sc = critical_stretch[lo:hi]
        broken = 0
        for q in range(hi - lo):
            j = 3 * np.uint64(np.uint32(fam[q]))
            _, _, y0 = bond_differences(xf[j], xi0, uf[j], ui0)
            _, _, y1 = bond_differences(xf[j + 1], xi1, uf[j + 1], ui1)
            _, _, y2 = bond_differences(xf[j + 2], xi2, uf[j + 2], ui2)
            limit = ln[q] * (1.0 + sc[q])
            if y0 * y0 + y1 * y1 + y2 * y2 > limit * limit and intact[lo + q] and breakable[lo + q]:
                intact[lo + q] = False
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
