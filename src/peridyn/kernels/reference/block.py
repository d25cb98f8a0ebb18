"""References of ``peridyn.kernels.block``: the linearised bond operations of
``peridyn.kernels.linear`` on ``k`` displacement fields at once (``u`` (n_points, 3, k)).

Reference unit vector ``n = xi / |xi|`` (stored |xi| = ``length``); extension
``e = n . (u_j - u_i)`` of each intact bond (0 if broken); bond force
``t = axial (P_i + P_j) + extension_coef e`` along n, summed over the intact bonds.
"""

import numpy as np

from peridyn.kernels.reference import as64, family_sum, owners, unit_vectors


def block_extension(x, u, offsets, nbr, length, intact):
    """(n_bonds, k) float64, m: e = n . (u_j - u_i) per vector, 0 for broken bonds."""
    (u,) = as64(u)
    du = u[nbr] - u[owners(offsets)]
    e = np.einsum("ba,bak->bk", unit_vectors(x, offsets, nbr, length), du)
    return np.where(np.asarray(intact)[:, None], e, 0.0)


def block_family_sum(offsets, weight, e):
    """(n_points, k) float64: sum over each family of weight_b e_b."""
    weight, e = as64(weight, e)
    return family_sum(offsets, weight[:, None] * e)


def block_bond_force(x, e, offsets, nbr, length, axial, extension_coef, intact, p):
    """(n_points, 3, k) float64, N/m^3: f_i = sum_j t n over intact bonds (module docstring)."""
    e, axial, extension_coef, p = as64(e, axial, extension_coef, p)
    t = axial[:, None] * (p[owners(offsets)] + p[nbr]) + extension_coef[:, None] * e
    t = np.where(np.asarray(intact)[:, None], t, 0.0)
    return family_sum(offsets, unit_vectors(x, offsets, nbr, length)[:, :, None] * t[:, None, :])
