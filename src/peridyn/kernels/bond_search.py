"""Bond search kernels: CSR families from neighbour pairs, bond lengths and partial-volume
factors (the fraction of a neighbour's cell inside the horizon ball), the reference bond
vectors that the float64 force kernels read, and sums over each family."""

import numba
import numpy as np


@numba.njit(cache=True)
def bond_families(pairs, n):
    """CSR families (offsets (n+1,) int64, neighbours int32 sorted per family) from i<j pairs."""
    counts = np.zeros(n + 1, dtype=np.int64)
    for p in range(pairs.shape[0]):
        counts[pairs[p, 0] + 1] += 1
        counts[pairs[p, 1] + 1] += 1
    offsets = np.cumsum(counts)
    cursor = offsets[:-1].copy()
    nbr = np.empty(offsets[-1], dtype=np.int32)
    for p in range(pairs.shape[0]):
        a, b = pairs[p, 0], pairs[p, 1]
        nbr[cursor[a]] = b
        cursor[a] += 1
        nbr[cursor[b]] = a
        cursor[b] += 1
    for i in range(n):
        nbr[offsets[i] : offsets[i + 1]].sort()
    return offsets, nbr


@numba.njit(parallel=True, cache=True)
def bond_geometry(x, cells, offsets, nbr, radius, partial, q):
    """Bond lengths and volume factors (fraction of the neighbour's cell inside the ball)."""
    n = x.shape[0]
    length = np.empty(nbr.shape[0])
    factor = np.empty(nbr.shape[0])
    for i in numba.prange(n):
        for b in range(offsets[i], offsets[i + 1]):
            j = nbr[b]
            d0 = x[j, 0] - x[i, 0]
            d1 = x[j, 1] - x[i, 1]
            d2 = x[j, 2] - x[i, 2]
            length[b] = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            if partial:
                factor[b] = box_fraction_in_ball(d0, d1, d2, cells[j, 0], cells[j, 1], cells[j, 2], radius, q)
            else:
                factor[b] = 1.0 if length[b] <= radius else 0.0
    return length, factor


@numba.njit(parallel=True, cache=True)
def initial_bond_vectors(x, offsets, nbr, xi):
    """Reference bond vectors ``xi`` (OUT, (n_bonds, 3), m): ``x_j - x_i`` of every directed bond,
    rounded as the force kernels' ``bond_differences`` rounds it (one subtraction)."""
    n = x.shape[0]
    for i in numba.prange(n):
        for b in range(offsets[i], offsets[i + 1]):
            j = nbr[b]
            for a in range(3):
                xi[b, a] = x[j, a] - x[i, a]
    return xi


@numba.njit(cache=True)
def box_fraction_in_ball(c0, c1, c2, h0, h1, h2, radius, q):
    """Fraction of the box centred at (c0, c1, c2) with sides (h0, h1, h2) inside the ball
    of ``radius`` at the origin (h2 = 0: a rectangle in the plane z = c2).

    Exact along x, midpoint rule with ``q`` samples along y and z (1 along z if h2 = 0).
    """
    half = 0.5 * np.sqrt(h0 * h0 + h1 * h1 + h2 * h2)
    r = np.sqrt(c0 * c0 + c1 * c1 + c2 * c2)
    if r + half <= radius:
        return 1.0
    if r - half >= radius:
        return 0.0
    qz = q if h2 > 0 else 1
    lo, hi = c0 - 0.5 * h0, c0 + 0.5 * h0
    total = 0.0
    for a in range(q):
        y = c1 + h1 * ((a + 0.5) / q - 0.5)
        for e in range(qz):
            z = c2 + h2 * ((e + 0.5) / qz - 0.5)
            rest = radius * radius - y * y - z * z
            if rest > 0:
                s = np.sqrt(rest)
                total += max(0.0, min(hi, s) - max(lo, -s))
    return total / (h0 * q * qz)


@numba.njit(parallel=True, cache=True)
def family_sums(offsets, values, out):
    """``out[i]`` = the sum of ``values[offsets[i]:offsets[i + 1]]``, added one bond after the
    other from 0 (an empty family sums to 0): the order, and so the bits, of ``np.bincount``
    over the bonds' owners. ``values`` (n_bonds,) and ``out`` (n_points,) float64."""
    for i in numba.prange(len(out)):
        total = 0.0
        for b in range(offsets[i], offsets[i + 1]):
            total += values[b]
        out[i] = total
