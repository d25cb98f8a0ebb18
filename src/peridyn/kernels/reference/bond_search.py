"""References of ``peridyn.kernels.bond_search``: CSR families from i<j pairs, bond lengths,
the partial-volume factor (the fraction of a neighbour's cell inside the horizon ball) and the
reference bond vectors."""

import numpy as np

from peridyn.kernels.reference import as64, bond_vectors, owners


def bond_families(pairs, n):
    """``(offsets, nbr)``: (n+1,) int64 and (n_bonds,) int32 CSR families holding every pair
    (i, j) twice, j in i's family and i in j's, each family sorted by neighbour."""
    pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    owner = np.concatenate([pairs[:, 0], pairs[:, 1]])
    other = np.concatenate([pairs[:, 1], pairs[:, 0]])
    order = np.lexsort((other, owner))
    offsets = np.concatenate([[0], np.cumsum(np.bincount(owner, minlength=n))]).astype(np.int64)
    return offsets, other[order].astype(np.int32)


def initial_bond_vectors(x, offsets, nbr):
    """(n_bonds, 3) float64, m: ``x_j - x_i`` of every directed bond i->j."""
    xi, _, _ = bond_vectors(x, np.zeros_like(x), offsets, nbr)
    return xi


def box_fraction_in_ball(centre, sides, radius, q):
    """(m,) float64: fraction of each box (``centre``, ``sides`` (m, 3), m; a zero third side
    makes it a rectangle in its plane z) inside the ball of ``radius`` at the origin.

    The integral over the box of the ball's indicator, exact along x (the chord of the ball
    through (y, z) is |x| <= sqrt(radius^2 - y^2 - z^2)) and by the midpoint rule with q x q
    samples across y and z: the samples of a rectangle all lie in its plane, so their mean is
    its one row of y samples.
    """
    centre, sides = as64(np.atleast_2d(centre), np.atleast_2d(sides))
    mid = (np.arange(q) + 0.5) / q - 0.5  # (q,) midpoints of [-1/2, 1/2]
    y = centre[:, 1, None, None] + sides[:, 1, None, None] * mid[None, :, None]
    z = centre[:, 2, None, None] + sides[:, 2, None, None] * mid[None, None, :]
    chord = np.sqrt(np.clip(radius**2 - y**2 - z**2, 0.0, None))  # (m, q, q)
    lo = (centre[:, 0] - 0.5 * sides[:, 0])[:, None, None]
    hi = (centre[:, 0] + 0.5 * sides[:, 0])[:, None, None]
    inside = np.clip(np.minimum(hi, chord) - np.maximum(lo, -chord), 0.0, None)
    return inside.mean(axis=(1, 2)) / sides[:, 0]


def bond_geometry(x, cells, offsets, nbr, radius, partial, q):
    """``(length, factor)`` (n_bonds,) float64: |x_j - x_i| (m) and the volume factor, the
    fraction of j's cell (``cells`` (n_points, 3) sides, m) inside the ball of ``radius``
    around i if ``partial``, else 1 for |xi| <= radius and 0 beyond."""
    (x,) = as64(x)
    xi = x[nbr] - x[owners(offsets)]
    length = np.linalg.norm(xi, axis=1)
    if partial:
        return length, box_fraction_in_ball(xi, np.asarray(cells)[nbr], radius, q)
    return length, (length <= radius).astype(np.float64)


def family_sums(offsets, values, out):
    """Sum of ``values`` over each family, by ``np.bincount`` over the bonds' owners."""
    out[:] = np.bincount(
        owners(offsets), weights=np.asarray(values, dtype=np.float64), minlength=len(offsets) - 1
    )
