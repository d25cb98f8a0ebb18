"""Block kernels: the linearised bond operations applied to ``k`` displacement fields at once
(``u`` of shape (n_points, 3, k)), each bond visited once per block (``peridyn.linalg.block_operator``)."""

import numba


@numba.njit(parallel=True, cache=True)
def block_extension(x, u, offsets, nbr, length, intact, out):
    """``out`` (OUT, (n_bonds, k)): extension n . (u_j - u_i) of each intact bond, per vector.

    ``u`` (n_points, 3, k).
    """
    n, k = x.shape[0], u.shape[2]
    for i in numba.prange(n):
        for b in range(offsets[i], offsets[i + 1]):
            j = nbr[b]
            for c in range(k):
                out[b, c] = 0.0
            if not intact[b]:
                continue
            for a in range(3):
                na = (x[j, a] - x[i, a]) / length[b]
                for c in range(k):
                    out[b, c] += na * (u[j, a, c] - u[i, a, c])
    return out


@numba.njit(parallel=True, cache=True)
def block_family_sum(offsets, weight, e, out):
    """``out`` (OUT, (n_points, k)): sum over each point's bonds of weight_b e_b."""
    n, k = out.shape
    for i in numba.prange(n):
        for c in range(k):
            out[i, c] = 0.0
        for b in range(offsets[i], offsets[i + 1]):
            for c in range(k):
                out[i, c] += weight[b] * e[b, c]
    return out


@numba.njit(parallel=True, cache=True)
def block_bond_force(x, e, offsets, nbr, length, axial, extension_coef, intact, p, f):
    """``f`` (OUT, (n_points, 3, k)): linearised force density, N/m^3, of bond forces along n

        t = axial (P_i + P_j) + extension_coef e,

    as in ``kernels.linear``: LPS has axial = w |xi|, extension_coef = ``LPSModel.dev`` and
    ``p`` (n_points, k) = theta p_coef; PMB has axial = 0, extension_coef = k / |xi|.
    """
    n, k = x.shape[0], e.shape[1]
    for i in numba.prange(n):
        for a in range(3):
            for c in range(k):
                f[i, a, c] = 0.0
        for b in range(offsets[i], offsets[i + 1]):
            if not intact[b]:
                continue
            j = nbr[b]
            n0 = (x[j, 0] - x[i, 0]) / length[b]
            n1 = (x[j, 1] - x[i, 1]) / length[b]
            n2 = (x[j, 2] - x[i, 2]) / length[b]
            for c in range(k):
                t = axial[b] * (p[i, c] + p[j, c]) + extension_coef[b] * e[b, c]
                f[i, 0, c] += t * n0
                f[i, 1, c] += t * n1
                f[i, 2, c] += t * n2
    return f
