"""Bond-based prototype microelastic brittle (PMB) kernels.

Force density on point i (N/m^3):

    f_i = sum_j k_ij (1/|xi| - 1/|Y|) Y,     Y = xi + u_j - u_i,

which is c s Y/|Y| V_j with stretch s = |Y|/|xi| - 1, folded so that each
bond costs one square root and one division. ``k_ij = c omega beta V_j g``
(micromodulus, influence, volume factor, neighbour volume, surface factor).

``pmb_force`` (float64) and ``pmb_force_cf`` (float32) compute the same force; see
``peridyn.kernels`` for the two forms and what makes them fast. ``pmb_force_baseline``
is the straightforward loop kept as the reference row of ``peridyn bench``.
"""

import numba
import numpy as np

from peridyn.kernels import (
    CHUNK,
    CHUNK_BUFFER,
    FASTMATH,
    bond_differences,
    deformed_component,
    stack_array,
)


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def pmb_force(xi, u, offsets, nbr, inv_len, k, intact, f, first=0, stop=-1):
    """Internal force density ``f`` (OUT: the rows ``first .. stop - 1``, see ``peridyn.kernels``)
    of the PMB model ("length form").

    ``s = k (1/|xi| - 1/|Y|)`` with the stored ``inv_len = 1/|xi|`` and bond vectors ``xi``
    (n_bonds, 3), m (``bond_search.initial_bond_vectors``): one square root and one division
    per bond, and only ``u_j`` gathered. Used for float64 (see the package docstring).
    """
    n = u.shape[0]
    zero = f.dtype.type(0.0)
    one = f.dtype.type(1.0)
    uf = u.reshape(3 * n)
    xif = xi.reshape(3 * xi.shape[0])
    end = n if stop < 0 else stop
    for i in numba.prange(first, end):
        ui0, ui1, ui2 = uf[3 * i], uf[3 * i + 1], uf[3 * i + 2]
        buf = stack_array(CHUNK_BUFFER, f.dtype)
        hi = offsets[i + 1]
        f0 = zero
        f1 = zero
        f2 = zero
        for c in range(offsets[i], hi, CHUNK):
            m = min(CHUNK, hi - c)
            fam = nbr[c : c + m]
            xib = xif[3 * c : 3 * (c + m)]
            il = inv_len[c : c + m]
            kb = k[c : c + m]
            ok = intact[c : c + m]
            for q in range(m):
                j = 3 * np.uint64(np.uint32(fam[q]))
                y0 = deformed_component(xib[3 * q], uf[j], ui0)
                y1 = deformed_component(xib[3 * q + 1], uf[j + 1], ui1)
                y2 = deformed_component(xib[3 * q + 2], uf[j + 2], ui2)
                s = kb[q] * (il[q] - one / np.sqrt(y0 * y0 + y1 * y1 + y2 * y2))
                buf[q] = s if ok[q] else zero
                buf[CHUNK + q] = y0
                buf[2 * CHUNK + q] = y1
                buf[3 * CHUNK + q] = y2
            for q in range(m):
                s = buf[q]
                f0 += s * buf[CHUNK + q]
                f1 += s * buf[2 * CHUNK + q]
                f2 += s * buf[3 * CHUNK + q]
        f[i, 0] = f0
        f[i, 1] = f1
        f[i, 2] = f2
    return f


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def pmb_force_cf(x, u, offsets, nbr, k, intact, f, first=0, stop=-1):
    """PMB force density ``f`` (OUT), cancellation-free form (used for float32).

    Same force as :func:`pmb_force`, written
    ``s = k (|Y|^2 - |xi|^2) / (|Y| |xi| (|Y| + |xi|))`` with
    ``|Y|^2 - |xi|^2 = du . (Y + xi)`` and ``|xi|`` recomputed from ``x``: no per-bond
    length is read and the stretch keeps full relative precision however small it is.
    """
    n = x.shape[0]
    zero = f.dtype.type(0.0)
    xf = x.reshape(3 * n)
    uf = u.reshape(3 * n)
    end = n if stop < 0 else stop
    for i in numba.prange(first, end):
        xi0, xi1, xi2 = xf[3 * i], xf[3 * i + 1], xf[3 * i + 2]
        ui0, ui1, ui2 = uf[3 * i], uf[3 * i + 1], uf[3 * i + 2]
        buf = stack_array(CHUNK_BUFFER, f.dtype)
        hi = offsets[i + 1]
        f0 = zero
        f1 = zero
        f2 = zero
        for c in range(offsets[i], hi, CHUNK):
            m = min(CHUNK, hi - c)
            fam = nbr[c : c + m]
            kb = k[c : c + m]
            ok = intact[c : c + m]
            for q in range(m):
                j = 3 * np.uint64(np.uint32(fam[q]))
                d0, e0, y0 = bond_differences(xf[j], xi0, uf[j], ui0)
                d1, e1, y1 = bond_differences(xf[j + 1], xi1, uf[j + 1], ui1)
                d2, e2, y2 = bond_differences(xf[j + 2], xi2, uf[j + 2], ui2)
                r = np.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
                length = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
                ext2 = e0 * (y0 + d0) + e1 * (y1 + d1) + e2 * (y2 + d2)
                s = kb[q] * ext2 / (r * length * (r + length))
                buf[q] = s if ok[q] else zero
                buf[CHUNK + q] = y0
                buf[2 * CHUNK + q] = y1
                buf[3 * CHUNK + q] = y2
            for q in range(m):
                s = buf[q]
                f0 += s * buf[CHUNK + q]
                f1 += s * buf[2 * CHUNK + q]
                f2 += s * buf[3 * CHUNK + q]
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
