"""Plain NumPy versions of the force kernels, for tests (slow, obviously correct).

Same arguments as the numba kernels, vectorised over bonds with ``np.add.at``.
"""

import numpy as np


def _deformed_bonds(x, u, offsets, nbr):
    owners = np.repeat(np.arange(len(offsets) - 1), np.diff(offsets))
    y = (x[nbr] - x[owners]) + (u[nbr] - u[owners])
    return owners, y, np.linalg.norm(y, axis=1)


def pmb_force(x, u, offsets, nbr, inv_len, k, intact):
    """f_i = sum_j k_ij (1/|xi| - 1/|Y|) Y over intact bonds."""
    owners, y, r = _deformed_bonds(x, u, offsets, nbr)
    t = np.where(intact, k * (inv_len - 1.0 / r), 0.0)
    f = np.zeros_like(x)
    np.add.at(f, owners, t[:, None] * y)
    return f


def lps_force(x, u, offsets, nbr, length, w, dev, intact, theta_coef, p_coef):
    """LPS force density from its definition (see ``peridyn.kernels.lps``)."""
    owners, y, r = _deformed_bonds(x, u, offsets, nbr)
    e = r - length
    theta = theta_coef * np.bincount(owners, np.where(intact, w * length * e, 0.0), minlength=len(x))
    p = theta * p_coef
    t = (w * length * (p[owners] + p[nbr]) + dev * e) / r
    t = np.where(intact, t, 0.0)
    f = np.zeros_like(x)
    np.add.at(f, owners, t[:, None] * y)
    return f
