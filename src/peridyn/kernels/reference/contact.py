"""References of ``peridyn.kernels.contact``: bond look-up of contact pairs, the short-range
force and the largest squared move (definitions in ``peridyn.kernels.contact``)."""

import numpy as np

from peridyn.kernels.reference import as64, bond_index


def pair_bond_index(offsets, nbr, first, second):
    """(n_pairs,) int64: index of the directed bond first[p] -> second[p], or -1."""
    return bond_index(offsets, nbr, first, second)


def add_contact_force(y, first, second, bond, intact, volumes, stiffness, radius, f):
    """``(f + contact force, touching)``: f (n_points, 3) float64, N/m^3, and the number of
    pairs in contact.

    A pair acts when it is unbonded (``bond`` -1) or its bond is broken, and
    ``0 < |Y| < radius``, Y = y_j - y_i: then f_i -= c (d_c - |Y|) V_j Y / |Y| and
    f_j += c (d_c - |Y|) V_i Y / |Y|, c = ``stiffness``.
    """
    y, volumes, f = as64(y, volumes, f)
    unbonded = (bond < 0) | ~intact[np.maximum(bond, 0)]
    d = y[second] - y[first]
    r = np.linalg.norm(d, axis=1)
    acts = unbonded & (r > 0) & (r < radius)
    i, j, d, r = first[acts], second[acts], d[acts], r[acts]
    along = (stiffness * (radius - r) / r)[:, None] * d
    out = f.copy()
    np.add.at(out, i, -volumes[j][:, None] * along)
    np.add.at(out, j, volumes[i][:, None] * along)
    return out, int(acts.sum())


def largest_squared_move(u, u_ref):
    """max_k |u_k - u_ref_k|^2 (m^2) over the points of (n_points, 3) ``u`` and ``u_ref``."""
    u, u_ref = as64(u, u_ref)
    return float(np.max(np.sum((u - u_ref) ** 2, axis=1)))
