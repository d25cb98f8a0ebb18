"""References of ``peridyn.kernels.linear``: the linearised (small-displacement) bond operations.

With the reference unit vector ``n = xi / |xi|`` and ``eta = u_j - u_i``, the linearised
extension of an intact bond is ``e = n . eta`` (0 for a broken one), and a bond force ``t``
along ``n`` gives ``f_i = sum_j t n``. PMB: ``t = (k / |xi|) e``; LPS:
``theta_i = theta_coef_i sum_j w |xi| e``, ``t = w |xi| (P_i + P_j) + dev e`` over intact
bonds, ``P_i = theta_i p_coef_i``.
"""

import numpy as np

from peridyn.kernels.reference import as64, bond_vectors, family_sum, owners, unit_vectors


def bond_extension(x, u, offsets, nbr, length, intact):
    """(n_bonds,) float64, m: n . (u_j - u_i) of intact bonds, 0 for broken ones."""
    _, du, _ = bond_vectors(x, u, offsets, nbr)
    e = np.einsum("ba,ba->b", unit_vectors(x, offsets, nbr, length), du)
    return np.where(intact, e, 0.0)


def scatter_along_bonds(x, offsets, nbr, length, t):
    """(n_points, 3) float64: f_i = sum_j t_b n_b (every bond, intact or not)."""
    (t,) = as64(t)
    return family_sum(offsets, t[:, None] * unit_vectors(x, offsets, nbr, length))


def lps_linear_force(x, u, offsets, nbr, length, w, dev, intact, theta_coef, p_coef):
    """(n_points, 3) float64, N/m^3: linearised LPS force (module docstring)."""
    length, w, dev, theta_coef, p_coef = as64(length, w, dev, theta_coef, p_coef)
    e = bond_extension(x, u, offsets, nbr, length, intact)
    p = theta_coef * family_sum(offsets, w * length * e) * p_coef
    t = np.where(intact, w * length * (p[owners(offsets)] + p[nbr]) + dev * e, 0.0)
    return scatter_along_bonds(x, offsets, nbr, length, t)
