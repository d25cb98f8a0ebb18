"""Per-point deformation and stress kernels: the sums over each point's intact bonds behind the
nonlocal deformation gradient and the peridynamic partial stress (float64).

Bond i->j: reference vector xi = x_j - x_i, deformed vector Y = xi + u_j - u_i (from
:func:`peridyn.kernels.bond_differences`, as in the force kernels), r = |Y|, and |xi| the
stored reference length L.

- :func:`shape_tensors`: K_i = sum_j w_ij xi (x) xi and N_i = sum_j w_ij Y (x) xi
  (Silling, Epton, Weckner, Xu, Askari 2007, eq. 102: F_i = N_i K_i^-1);
- :func:`partial_stress`: sigma_i = sum_j t_ij (Y / r) (x) xi with the owner's scalar force
  state t_ij = axial_ij P_i + owner_ij (r - L) (the ordinary state-based form of every shipped
  material, ``peridyn.physics.materials.linearisation``).

A broken bond (``intact`` False) adds nothing to either sum. The kernels run in parallel over
the points, without fast-math (these are output quantities, not the time-stepping hot loop).
"""

import numba
import numpy as np

from peridyn.kernels import bond_differences


@numba.njit(parallel=True, cache=True)
def shape_tensors(x, u, offsets, nbr, w, intact, K, N):
    """Shape tensor ``K`` and deformed tensor ``N`` (OUT, (n_points, 3, 3), m^5 for w in m^3).

    K_i[a, b] = sum_j w_ij xi_a xi_b and N_i[a, b] = sum_j w_ij Y_a xi_b over the intact bonds.
    """
    n = x.shape[0]
    for i in numba.prange(n):
        k = np.zeros((3, 3))
        m = np.zeros((3, 3))
        d = np.empty(3)
        y = np.empty(3)
        for q in range(offsets[i], offsets[i + 1]):
            if not intact[q]:
                continue
            j = nbr[q]
            for a in range(3):
                d[a], _, y[a] = bond_differences(x[j, a], x[i, a], u[j, a], u[i, a])
            for a in range(3):
                for b in range(3):
                    k[a, b] += w[q] * d[a] * d[b]
                    m[a, b] += w[q] * y[a] * d[b]
        K[i] = k
        N[i] = m
    return K, N


@numba.njit(parallel=True, cache=True)
def partial_stress(x, u, offsets, nbr, length, axial, owner, intact, p, sigma):
    """Partial stress ``sigma`` (OUT, (n_points, 3, 3), Pa): sigma_i[a, b] = sum_j t_ij Y_a xi_b / r.

    t_ij = axial_ij p_i + owner_ij (r - length_ij) over the intact bonds: ``axial`` (n_bonds,)
    m^4 and ``p`` (n_points,) Pa/m^5 (zeros for a bond-based material), ``owner`` (n_bonds,)
    N/m^5, the owner's share of the bond's force per unit extension.
    """
    n = x.shape[0]
    for i in numba.prange(n):
        s = np.zeros((3, 3))
        d = np.empty(3)
        y = np.empty(3)
        for q in range(offsets[i], offsets[i + 1]):
            if not intact[q]:
                continue
            j = nbr[q]
            for a in range(3):
                d[a], _, y[a] = bond_differences(x[j, a], x[i, a], u[j, a], u[i, a])
            r = np.sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2])
            t = (axial[q] * p[i] + owner[q] * (r - length[q])) / r
            for a in range(3):
                for b in range(3):
                    s[a, b] += t * y[a] * d[b]
        sigma[i] = s
    return sigma
