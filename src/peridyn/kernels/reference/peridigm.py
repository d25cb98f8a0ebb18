"""Reference of ``peridyn.kernels.peridigm``: the LPS dilatation and force of Peridigm's
"Elastic" material from the deformed positions y, vectorised over the bonds.

Over intact bonds i->j, with ``Y = y_j - y_i``, ``|xi| = |x_j - x_i|``, ``e = |Y| - |xi|``:

- ``theta_i = sum_j 3 omega |xi| e V_j / m_i``;
- ``t_ij = omega theta_i p_i |xi| + omega alpha_i e`` and the force density
  ``f_i = sum_j t_ij (Y / |Y|) V_j - sum_j t_ji (Y_ji / |Y_ji|) V_j`` (the second sum: the bonds
  j->i of the other points' families, each adding to both of its ends), N/m^3.
"""

import numpy as np

from peridyn.kernels.reference import owners


def peridigm_lps_force(x, y, offsets, nbr, volume, influence, intact, m, alpha, p_coef):
    """``(theta (n,), f (n, 3))`` float64."""
    i = owners(offsets)
    j = np.asarray(nbr, dtype=np.int64)
    n = len(offsets) - 1
    zeta = np.linalg.norm(x[j] - x[i], axis=1)
    Y = y[j] - y[i]
    r = np.linalg.norm(Y, axis=1)
    e = r - zeta
    theta = np.bincount(i, np.where(intact, 3.0 * influence * zeta * e * volume[j] / m[i], 0.0), minlength=n)
    t = np.where(intact, influence * theta[i] * p_coef[i] * zeta + influence * alpha[i] * e, 0.0)
    pull = (t / r)[:, None] * Y
    f = np.zeros((n, 3))
    np.add.at(f, i, pull * volume[j][:, None])
    np.add.at(f, j, -pull * volume[i][:, None])
    return theta, f
