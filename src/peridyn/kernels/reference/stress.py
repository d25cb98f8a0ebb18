"""References of ``peridyn.kernels.stress``: shape tensors and partial stress, from their
definitions, vectorised over the bonds.

K_i = sum_j w xi (x) xi and N_i = sum_j w Y (x) xi; sigma_i = sum_j t_ij (Y / |Y|) (x) xi with
t_ij = axial_ij p_i + owner_ij (|Y| - length_ij); broken bonds add nothing.
"""

import numpy as np

from peridyn.kernels.reference import as64, bond_vectors, family_sum, owners


def shape_tensors(x, u, offsets, nbr, w, intact):
    """``(K, N)``, each (n_points, 3, 3) float64."""
    xi, _, y = bond_vectors(x, u, offsets, nbr)
    (w,) = as64(w)
    w = np.where(intact, w, 0.0)
    K = family_sum(offsets, w[:, None, None] * np.einsum("ba,bc->bac", xi, xi))
    N = family_sum(offsets, w[:, None, None] * np.einsum("ba,bc->bac", y, xi))
    return K, N


def partial_stress(x, u, offsets, nbr, length, axial, owner, intact, p):
    """(n_points, 3, 3) float64, Pa."""
    xi, _, y = bond_vectors(x, u, offsets, nbr)
    length, axial, owner, p = as64(length, axial, owner, p)
    r = np.linalg.norm(y, axis=1)
    t = np.where(intact, axial * p[owners(offsets)] + owner * (r - length), 0.0)
    return family_sum(offsets, (t / r)[:, None, None] * np.einsum("ba,bc->bac", y, xi))
