"""Short-range (contact) force kernels.

A contact pair (i, j), i < j, is a pair of points close enough in the deformed
configuration to touch; ``bond`` holds the index of the directed bond i->j in the CSR
families, or -1 when the two points were never bonded. A pair acts only when it is not
bonded or its bond is broken (both directed copies of a bond break together).

Force density on i (N/m^3), repulsive only, for |Y| < d_c with Y = y_j - y_i:

    f_i = -c_sr (d_c - |Y|) / delta V_j Y / |Y|,    f_j = +c_sr (d_c - |Y|) / delta V_i Y / |Y|,

so that f_i V_i + f_j V_j = 0 exactly (Newton's third law).
"""

import numba
import numpy as np


@numba.njit(cache=True)
def pair_bond_index(offsets, nbr, first, second):
    """(n_pairs,) int64: index of the directed bond first[p] -> second[p], or -1 if none.

    Families are sorted by neighbour index, so each look-up is a binary search.
    """
    out = np.empty(first.shape[0], dtype=np.int64)
    for p in range(first.shape[0]):
        i, j = first[p], second[p]
        lo, hi = offsets[i], offsets[i + 1]
        while lo < hi:
            mid = (lo + hi) // 2
            if nbr[mid] < j:
                lo = mid + 1
            else:
                hi = mid
        out[p] = lo if (lo < offsets[i + 1] and nbr[lo] == j) else -1
    return out


@numba.njit(cache=True)
def add_contact_force(y, first, second, bond, intact, volumes, stiffness, radius, f):
    """Add (IN/OUT ``f``) the short-range force density of every touching, unbonded pair.

    Parameters
    ----------
    y : (n_points, 3) float64, m
        Deformed positions x + u.
    first, second : (n_pairs,) int64
        Candidate pairs (from the Verlet list).
    bond : (n_pairs,) int64
        Directed bond index of each pair or -1.
    intact : (n_bonds,) bool
    volumes : (n_points,) float64, m^3
    stiffness : float, N/m^7 (3D)
        c_sr / delta.
    radius : float, m
        Contact distance d_c.
    f : (n_points, 3) float64 or float32, N/m^3

    Returns the number of pairs in contact.
    """
    touching = 0
    r2max = radius * radius
    for p in range(first.shape[0]):
        b = bond[p]
        if b >= 0 and intact[b]:
            continue
        i, j = first[p], second[p]
        d0 = y[j, 0] - y[i, 0]
        d1 = y[j, 1] - y[i, 1]
        d2 = y[j, 2] - y[i, 2]
        r2 = d0 * d0 + d1 * d1 + d2 * d2
        if r2 >= r2max or r2 == 0.0:
            continue
        r = np.sqrt(r2)
        t = stiffness * (radius - r) / r
        ti = t * volumes[j]
        tj = t * volumes[i]
        f[i, 0] -= ti * d0
        f[i, 1] -= ti * d1
        f[i, 2] -= ti * d2
        f[j, 0] += tj * d0
        f[j, 1] += tj * d1
        f[j, 2] += tj * d2
        touching += 1
    return touching


@numba.njit(parallel=True, cache=True)
def largest_squared_move(u, u_ref):
    """max_k |u_k - u_ref_k|^2 over the points of (n_points, 3) ``u`` and ``u_ref`` (m^2),
    without temporaries."""
    largest = 0.0
    for k in numba.prange(u.shape[0]):
        d0 = u[k, 0] - u_ref[k, 0]
        d1 = u[k, 1] - u_ref[k, 1]
        d2 = u[k, 2] - u_ref[k, 2]
        largest = max(largest, d0 * d0 + d1 * d1 + d2 * d2)
    return largest
