"""References of ``peridyn.kernels.lps``: LPS dilatation, pair force and deviatoric energy.

From the definitions (Silling et al. 2007; ``peridyn.kernels.lps``), over intact bonds,
with extension ``e = |Y| - |xi|``:

- dilatation ``theta_i = theta_coef_i sum_j w_ij |xi| e_ij``;
- force density ``f_i = sum_j [w_ij |xi| (P_i + P_j) + dev_ij e_ij] Y / |Y|`` (N/m^3);
- deviatoric sum ``sum_j w_ij (e_ij - theta_i |xi| / d)^2`` (m^5).

The ``*_cf`` kernels take ``|xi| = |x_j - x_i|`` from the points, the others the stored
bond vectors ``xi`` (n_bonds, 3) and ``length``.
"""

import numpy as np

from peridyn.kernels.reference import as64, extension, family_sum, owners, stored_extension


def _dilatation(offsets, length, e, w, intact, theta_coef):
    w, theta_coef = as64(w, theta_coef)
    return theta_coef * family_sum(offsets, np.where(intact, w * length * e, 0.0))


def _pair_force(offsets, nbr, length, e, y, w, dev, intact, p):
    w, dev, p = as64(w, dev, p)
    t = w * length * (p[owners(offsets)] + p[nbr]) + dev * e
    t = np.where(intact, t / np.linalg.norm(y, axis=1), 0.0)
    return family_sum(offsets, t[:, None] * y)


def lps_dilatation(xi, u, offsets, nbr, length, w, intact, theta_coef):
    """(n_points,) float64: theta from the stored bond vectors ``xi`` (n_bonds, 3) and |xi| =
    ``length``."""
    length, e, _ = stored_extension(xi, u, offsets, nbr, length)
    return _dilatation(offsets, length, e, w, intact, theta_coef)


def lps_dilatation_cf(x, u, offsets, nbr, w, intact, theta_coef):
    """(n_points,) float64: theta with |xi| = |x_j - x_i|."""
    length, e, _ = extension(x, u, offsets, nbr)
    return _dilatation(offsets, length, e, w, intact, theta_coef)


def lps_pair_force(xi, u, offsets, nbr, length, w, dev, intact, p):
    """(n_points, 3) float64, N/m^3: the pair force from the stored bond vectors ``xi``
    (n_bonds, 3) and |xi| = ``length``."""
    length, e, y = stored_extension(xi, u, offsets, nbr, length)
    return _pair_force(offsets, nbr, length, e, y, w, dev, intact, p)


def lps_pair_force_cf(x, u, offsets, nbr, w, dev, intact, p):
    """(n_points, 3) float64, N/m^3: the pair force with |xi| = |x_j - x_i|."""
    length, e, y = extension(x, u, offsets, nbr)
    return _pair_force(offsets, nbr, length, e, y, w, dev, intact, p)


def lps_force(xi, u, offsets, nbr, length, w, dev, intact, theta_coef, p_coef):
    """(n_points, 3) float64, N/m^3: the whole LPS force, P_i = theta_i ``p_coef``_i (what
    ``LPSModel.force`` computes with the two kernels), from the stored bond vectors ``xi``."""
    theta = lps_dilatation(xi, u, offsets, nbr, length, w, intact, theta_coef)
    p = theta * np.asarray(p_coef, np.float64)
    return lps_pair_force(xi, u, offsets, nbr, length, w, dev, intact, p)


def lps_deviatoric_energy(x, u, offsets, nbr, length, w, intact, theta, dim):
    """(n_points,) float64, m^5: sum_j w (e - theta_i |xi| / d)^2 over intact bonds."""
    length, e, _ = extension(x, u, offsets, nbr, length)
    w, theta = as64(w, theta)
    deviatoric = e - theta[owners(offsets)] * length / dim
    return family_sum(offsets, np.where(intact, w * deviatoric**2, 0.0))


def lps_stiffness_bound(offsets, nbr, intact, w, length, dev, bulk, theta_coef):
    """Block-Gershgorin bound of the LPS stiffness, per point, in NumPy (peridyn's form
    before the kernel)."""
    w = np.where(intact, w, 0.0)
    s = theta_coef * family_sum(offsets, w * length)
    pair = 2.0 * np.where(intact, np.asarray(dev, dtype=np.float64), 0.0)
    dil = 2.0 * bulk[nbr] * theta_coef[nbr] * w * length * s[nbr]
    return family_sum(offsets, pair + dil) + 2.0 * bulk * s**2
