"""Linearised (small-displacement) force kernels: the exact action of the stiffness matrix.

With n = xi/|xi| and eta = u_j - u_i, the linearised extension is e = n . eta.

- PMB: f_i = sum_j (k_ij / |xi|) (n . eta) n;
- LPS: theta_i = (d / m_i) sum_j w |xi| (n . eta),
  f_i = sum_j [ w |xi| (P_i + P_j) + k_ij (n . eta) ] n, P_i = theta_i p_coef_i, k_ij the
  bond's deviatoric stiffness (see ``peridyn.kernels.lps``).

``K u = -V f_lin(u)`` holds to round-off for the matrices of ``peridyn.linalg.stiffness``.
"""

import numba
import numpy as np


@numba.njit(parallel=True, cache=True)
def bond_extension(x, u, offsets, nbr, length, intact, out):
    """``out`` (OUT, (n_bonds,)): linearised extension n . (u_j - u_i) of each intact bond."""
    n = x.shape[0]
    for i in numba.prange(n):
        for b in range(offsets[i], offsets[i + 1]):
            j = nbr[b]
            e = 0.0
            for a in range(3):
                e += (x[j, a] - x[i, a]) * (u[j, a] - u[i, a])
            out[b] = e / length[b] if intact[b] else 0.0
    return out


@numba.njit(parallel=True, cache=True)
def scatter_along_bonds(x, offsets, nbr, length, t, f):
    """``f`` (OUT): f_i = sum_j t_b n_b with n the reference unit vector of bond b."""
    n = x.shape[0]
    for i in numba.prange(n):
        for a in range(3):
            f[i, a] = 0.0
        for b in range(offsets[i], offsets[i + 1]):
            j = nbr[b]
            s = t[b] / length[b]
            for a in range(3):
                f[i, a] += s * (x[j, a] - x[i, a])
    return f


def lps_linear_force(x, u, offsets, nbr, length, w, dev, intact, theta_coef, p_coef):
    """Linearised LPS force density (n_points, 3), N/m^3."""
    e = bond_extension(x, u, offsets, nbr, length, intact, np.empty(len(nbr)))
    owners = np.repeat(np.arange(len(x)), np.diff(offsets))
    theta = theta_coef * np.bincount(owners, w * length * e, minlength=len(x))
    p = theta * p_coef
    t = np.where(intact, w * length * (p[owners] + p[nbr]) + dev * e, 0.0)
    return scatter_along_bonds(x, offsets, nbr, length, t, np.empty_like(x))
