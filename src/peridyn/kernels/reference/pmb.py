"""References of ``peridyn.kernels.pmb``: PMB force density and strain energy density.

From the definitions: stretch ``s = (|Y| - |xi|) / |xi|`` of each intact bond, force density
``f_i = sum_j k_ij s_ij Y / |Y|`` (N/m^3), energy density ``W_i = sum_j k_ij s_ij^2 |xi| / 4``
(J/m^3). The kernels differ only in where ``xi`` and ``|xi|`` come from (stored per bond, or the points).
"""

import numpy as np

from peridyn.kernels.reference import as64, extension, family_sum, stored_extension


def _force(offsets, length, e, y, k, intact):
    """f_i = sum_j k s Y / |Y| over intact bonds."""
    (k,) = as64(k)
    t = np.where(intact, k * (e / length) / np.linalg.norm(y, axis=1), 0.0)
    return family_sum(offsets, t[:, None] * y)


def pmb_force(xi, u, offsets, nbr, inv_len, k, intact):
    """(n_points, 3) float64, N/m^3: the PMB force from the stored bond vectors ``xi``
    (n_bonds, 3), with |xi| = 1 / ``inv_len``."""
    length = 1.0 / np.asarray(inv_len, dtype=np.float64)
    return _force(offsets, *stored_extension(xi, u, offsets, nbr, length), k, intact)


def pmb_force_cf(x, u, offsets, nbr, k, intact):
    """(n_points, 3) float64, N/m^3: the PMB force with |xi| = |x_j - x_i|."""
    return _force(offsets, *extension(x, u, offsets, nbr), k, intact)


def pmb_force_baseline(x, u, offsets, nbr, length, c, intact):
    """(n_points, 3) float64, N/m^3: the PMB force with the stored |xi| = ``length``."""
    return _force(offsets, *extension(x, u, offsets, nbr, length), c, intact)


def pmb_energy(x, u, offsets, nbr, length, k, intact):
    """(n_points,) float64, J/m^3: W_i = sum_j k s^2 |xi| / 4 over intact bonds."""
    length, e, _ = extension(x, u, offsets, nbr, length)
    (k,) = as64(k)
    return 0.25 * family_sum(offsets, np.where(intact, k * (e / length) ** 2 * length, 0.0))
