"""Bond-based prototype microelastic brittle (PMB) kernels.

Force density on point i (N/m^3):

    f_i = sum_j k_ij (1/|xi| - 1/|Y|) Y,     Y = xi + u_j - u_i,

which is c s Y/|Y| V_j with stretch s = |Y|/|xi| - 1, folded so that each
bond costs one square root and one division. ``k_ij = c omega beta V_j g``
(micromodulus, influence, volume factor, neighbour volume, surface factor).
"""

import numba
import numpy as np

from peridyn.kernels import FASTMATH


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def pmb_force(x, u, offsets, nbr, inv_len, k, intact, f):
    """Internal force density ``f`` (OUT, overwritten) of the PMB model."""
    n = x.shape[0]
    for i in numba.prange(n):
        xi0, xi1, xi2 = x[i, 0], x[i, 1], x[i, 2]
        f0 = f.dtype.type(0.0)
        f1 = f.dtype.type(0.0)
        f2 = f.dtype.type(0.0)
        for b in range(offsets[i], offsets[i + 1]):
            j = nbr[b]
            y0 = (x[j, 0] - xi0) + (u[j, 0] - u[i, 0])
            y1 = (x[j, 1] - xi1) + (u[j, 1] - u[i, 1])
            y2 = (x[j, 2] - xi2) + (u[j, 2] - u[i, 2])
            r = np.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
            s = k[b] * (inv_len[b] - 1 / r) if intact[b] else 0 * r
            f0 += s * y0
            f1 += s * y1
            f2 += s * y2
        f[i, 0] = f0
        f[i, 1] = f1
        f[i, 2] = f2
    return f


@numba.njit(parallel=True, cache=True)
def pmb_energy(x, u, offsets, nbr, length, k, intact, w):
    """Strain energy density ``w`` (OUT, J/m^3): W_i = sum_j k_ij s^2 |xi| / 4."""
    n = x.shape[0]
    for i in numba.prange(n):
        acc = 0.0
        for b in range(offsets[i], offsets[i + 1]):
            if not intact[b]:
                continue
            j = nbr[b]
            r2 = 0.0
            for a in range(3):
                d = (x[j, a] - x[i, a]) + (u[j, a] - u[i, a])
                r2 += d * d
            s = np.sqrt(r2) / length[b] - 1.0
            acc += k[b] * s * s * length[b]
        w[i] = 0.25 * acc
    return w


@numba.njit(parallel=True, cache=True)
def pmb_force_baseline(x, u, offsets, nbr, length, c, intact, f):
    """The straightforward PMB loop kept as the benchmark baseline (not used by solvers).

    Reads a stored reference length per bond, computes the stretch with a divide,
    and the unit vector with another divide.
    """
    n = x.shape[0]
    for i in numba.prange(n):
        for a in range(3):
            f[i, a] = 0.0
        for b in range(offsets[i], offsets[i + 1]):
            if not intact[b]:
                continue
            j = nbr[b]
            y0 = x[j, 0] + u[j, 0] - x[i, 0] - u[i, 0]
            y1 = x[j, 1] + u[j, 1] - x[i, 1] - u[i, 1]
            y2 = x[j, 2] + u[j, 2] - x[i, 2] - u[i, 2]
            r = np.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
            s = (r - length[b]) / length[b]
            t = c[b] * s / r
            f[i, 0] += t * y0
            f[i, 1] += t * y1
            f[i, 2] += t * y2
    return f
