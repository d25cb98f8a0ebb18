"""Fill-reducing order of sparse unknowns attached to points, by geometric nested dissection.

Every coupling of the stiffness (a bond, or a point's dilatation with its family)
joins points at most one horizon apart, so a slab one horizon wide across the
middle of a point cloud separates its two sides: ordering the sides first
(recursively) and the slab last confines the factor's fill to the separators
(George 1973, nested dissection). On peridynamic grids this gives less fill and
faster sparse LU than SuperLU's own graph orderings, which see neither the
geometry nor the symmetry.
"""

from __future__ import annotations

import numpy as np

#: Parts with at most this many points are not split further.
LEAF_POINTS = 48


def nested_dissection(points: np.ndarray, reach: float, leaf: int = LEAF_POINTS) -> np.ndarray:
    """Order of the points (n,) int64: each part's halves first, then their separator.

    Parameters
    ----------
    points : (n, 3) float64, m
    reach : float, m
        Largest distance between two coupled points (the horizon).
    """
    order: list[np.ndarray] = []
    stack = [(np.arange(len(points)), False)]
    # iterative post-order: a part is replaced by (separator, done) and its two halves
    while stack:
        idx, is_separator = stack.pop()
        p = points[idx]
        extent = np.ptp(p, axis=0) if len(idx) else np.zeros(3)
        axis = int(np.argmax(extent))
        if is_separator or len(idx) <= leaf or extent[axis] <= 2 * reach:
            order.append(idx)
            continue
        middle = np.median(p[:, axis])
        coordinate = p[:, axis]
        below = coordinate < middle - reach / 2
        above = coordinate > middle + reach / 2
        stack.append((idx[~below & ~above], True))
        stack.append((idx[above], False))
        stack.append((idx[below], False))
    return np.concatenate(order)


def order_unknowns(unknown_points: np.ndarray, points: np.ndarray, reach: float) -> np.ndarray:
    """Permutation of unknowns (m,) int64 following the nested-dissection rank of their point.

    ``unknown_points`` (m,) int: the point each unknown belongs to.
    """
    rank = np.empty(len(points), dtype=np.int64)
    rank[nested_dissection(points, reach)] = np.arange(len(points))
    return np.argsort(rank[unknown_points], kind="stable")
