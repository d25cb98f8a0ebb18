"""Oracle of ``test_kernel_chunks``: the float64 force kernels as they were before the chunks.

One loop over each family, compiled with the kernels' ``FASTMATH``: LLVM keeps such a
loop's sums in the written order (it does not vectorise them). Copied from
``peridyn.kernels.pmb`` and ``peridyn.kernels.lps`` before the two-loop form (not cached).
"""

import numba
import numpy as np

from peridyn.kernels import FASTMATH, bond_differences


@numba.njit(parallel=True, fastmath=FASTMATH)
def pmb_force(x, u, offsets, nbr, inv_len, k, intact, f):
    """Internal force density ``f`` (OUT, overwritten) of the PMB model ("length form").

    ``s = k (1/|xi| - 1/|Y|)`` with the stored ``inv_len = 1/|xi|``: one square root
    and one division per bond. Used for float64 (see the package docstring).
    """
    n = x.shape[0]
    zero = f.dtype.type(0.0)
    one = f.dtype.type(1.0)
    xf = x.reshape(3 * n)
    uf = u.reshape(3 * n)
    for i in numba.prange(n):
        xi0, xi1, xi2 = xf[3 * i], xf[3 * i + 1], xf[3 * i + 2]
        ui0, ui1, ui2 = uf[3 * i], uf[3 * i + 1], uf[3 * i + 2]
        lo = offsets[i]
        hi = offsets[i + 1]
        fam = nbr[lo:hi]
        il = inv_len[lo:hi]
        kb = k[lo:hi]
        ok = intact[lo:hi]
        f0 = zero
        f1 = zero
        f2 = zero
        for q in range(hi - lo):
            j = 3 * np.uint64(np.uint32(fam[q]))
            _, _, y0 = bond_differences(xf[j], xi0, uf[j], ui0)
            _, _, y1 = bond_differences(xf[j + 1], xi1, uf[j + 1], ui1)
            _, _, y2 = bond_differences(xf[j + 2], xi2, uf[j + 2], ui2)
            s = kb[q] * (il[q] - one / np.sqrt(y0 * y0 + y1 * y1 + y2 * y2))
            s = s if ok[q] else zero
            f0 += s * y0
            f1 += s * y1
            f2 += s * y2
        f[i, 0] = f0
        f[i, 1] = f1
        f[i, 2] = f2
    return f


@numba.njit(parallel=True, fastmath=FASTMATH)
def lps_dilatation(x, u, offsets, nbr, length, w, intact, theta_coef, theta):
    """Dilatation ``theta`` (OUT): theta_i = theta_coef_i sum_j w_ij |xi| e_ij, coef = d / m_i.

    Length form, e = |Y| - |xi| with the stored ``length`` (float64; see ``peridyn.kernels``).
    """
    n = x.shape[0]
    zero = theta.dtype.type(0.0)
    xf = x.reshape(3 * n)
    uf = u.reshape(3 * n)
    for i in numba.prange(n):
        xi0, xi1, xi2 = xf[3 * i], xf[3 * i + 1], xf[3 * i + 2]
        ui0, ui1, ui2 = uf[3 * i], uf[3 * i + 1], uf[3 * i + 2]
        lo = offsets[i]
        hi = offsets[i + 1]
        fam = nbr[lo:hi]
        lb = length[lo:hi]
        wb = w[lo:hi]
        ok = intact[lo:hi]
        acc = zero
        for q in range(hi - lo):
            j = 3 * np.uint64(np.uint32(fam[q]))
            _, _, y0 = bond_differences(xf[j], xi0, uf[j], ui0)
            _, _, y1 = bond_differences(xf[j + 1], xi1, uf[j + 1], ui1)
            _, _, y2 = bond_differences(xf[j + 2], xi2, uf[j + 2], ui2)
            r = np.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
            t = wb[q] * lb[q] * (r - lb[q])
            acc += t if ok[q] else zero
        theta[i] = theta_coef[i] * acc
    return theta


@numba.njit(parallel=True, fastmath=FASTMATH)
def lps_pair_force(x, u, offsets, nbr, length, w, dev, intact, p, f):
    """Force density ``f`` (OUT) from the per-point ``p`` = P_i and per-bond ``dev`` (see module).

    Length form (float64).
    """
    n = x.shape[0]
    zero = f.dtype.type(0.0)
    xf = x.reshape(3 * n)
    uf = u.reshape(3 * n)
    for i in numba.prange(n):
        xi0, xi1, xi2 = xf[3 * i], xf[3 * i + 1], xf[3 * i + 2]
        ui0, ui1, ui2 = uf[3 * i], uf[3 * i + 1], uf[3 * i + 2]
        lo = offsets[i]
        hi = offsets[i + 1]
        fam = nbr[lo:hi]
        lb = length[lo:hi]
        wb = w[lo:hi]
        kb = dev[lo:hi]
        ok = intact[lo:hi]
        pi = p[i]
        f0 = zero
        f1 = zero
        f2 = zero
        for q in range(hi - lo):
            jp = np.uint32(fam[q])
            j = 3 * np.uint64(jp)
            _, _, y0 = bond_differences(xf[j], xi0, uf[j], ui0)
            _, _, y1 = bond_differences(xf[j + 1], xi1, uf[j + 1], ui1)
            _, _, y2 = bond_differences(xf[j + 2], xi2, uf[j + 2], ui2)
            r = np.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
            L = lb[q]
            t = (wb[q] * L * (pi + p[jp]) + kb[q] * (r - L)) / r
            t = t if ok[q] else zero
            f0 += t * y0
            f1 += t * y1
            f2 += t * y2
        f[i, 0] = f0
        f[i, 1] = f1
        f[i, 2] = f2
    return f
