"""Linear peridynamic solid (LPS, Silling et al. 2007) kernels, in d = 2 or 3 dimensions.

Per point: weighted volume m_i = sum_j w_ij |xi|^2 with w_ij = omega beta V_j,
dilatation theta_i = (d / m_i) sum_j w_ij |xi| e_ij, extension e = |Y| - |xi|.
Scalar force state t_ij = (d kappa theta_i / m_i) omega |xi| + alpha_i omega e^d_ij,
e^d = e - theta_i |xi| / d, alpha = 15 mu / m (3D) or 8 mu / m (2D). The pair
force on i is (t_ij + t_ji) Y/|Y| beta V_j, which the kernel writes as

    sum_j w_ij [ |xi| (P_i + P_j) + (alpha_i + alpha_j) e_ij ] Y / |Y|,
    P_i = theta_i (d kappa_i / m_i - alpha_i / d).
"""

import numba
import numpy as np

from peridyn.kernels import FASTMATH


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def lps_dilatation(x, u, offsets, nbr, length, w, intact, theta_coef, theta):
    """Dilatation ``theta`` (OUT): theta_i = theta_coef_i sum_j w_ij |xi| e_ij, coef = d / m_i."""
    n = x.shape[0]
    for i in numba.prange(n):
        acc = theta.dtype.type(0.0)
        for b in range(offsets[i], offsets[i + 1]):
            j = nbr[b]
            y0 = (x[j, 0] - x[i, 0]) + (u[j, 0] - u[i, 0])
            y1 = (x[j, 1] - x[i, 1]) + (u[j, 1] - u[i, 1])
            y2 = (x[j, 2] - x[i, 2]) + (u[j, 2] - u[i, 2])
            r = np.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
            e = r - length[b]
            acc += w[b] * length[b] * e if intact[b] else 0 * e
        theta[i] = theta_coef[i] * acc
    return theta


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def lps_pair_force(x, u, offsets, nbr, length, w, intact, p, alpha, f):
    """Force density ``f`` (OUT) from the per-point ``p`` = P_i and ``alpha`` (see module)."""
    n = x.shape[0]
    for i in numba.prange(n):
        f0 = f.dtype.type(0.0)
        f1 = f.dtype.type(0.0)
        f2 = f.dtype.type(0.0)
        pi = p[i]
        ai = alpha[i]
        for b in range(offsets[i], offsets[i + 1]):
            j = nbr[b]
            y0 = (x[j, 0] - x[i, 0]) + (u[j, 0] - u[i, 0])
            y1 = (x[j, 1] - x[i, 1]) + (u[j, 1] - u[i, 1])
            y2 = (x[j, 2] - x[i, 2]) + (u[j, 2] - u[i, 2])
            r = np.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
            L = length[b]
            t = w[b] * (L * (pi + p[j]) + (ai + alpha[j]) * (r - L)) / r
            t = t if intact[b] else 0 * t
            f0 += t * y0
            f1 += t * y1
            f2 += t * y2
        f[i, 0] = f0
        f[i, 1] = f1
        f[i, 2] = f2
    return f


@numba.njit(parallel=True, cache=True)
def lps_deviatoric_energy(x, u, offsets, nbr, length, w, intact, theta, dim, out):
    """``out`` (OUT): sum_j w_ij (e_ij - theta_i |xi| / d)^2 per point (m^5)."""
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
            ed = np.sqrt(r2) - length[b] - theta[i] * length[b] / dim
            acc += w[b] * ed * ed
        out[i] = acc
    return out
