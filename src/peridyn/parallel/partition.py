"""Partition of the points over ranks by recursive coordinate bisection (RCB).

The box of the points is cut across its longest side at the point count that splits the ranks
in proportion (a part for ``p`` ranks is cut into ``p // 2`` and ``p - p // 2`` ranks), and each
half again, until there is one part per rank. Ties along the cut axis are broken by the point
index, so the partition depends on the coordinates alone: every rank computes the same one.

Why RCB and not METIS (pymetis): peridynamic families are balls of a fixed radius on a nearly
uniform grid, so the halo a rank needs is proportional to the area of its part's boundary; RCB
gives compact boxes whose boundary is within a small factor of the graph partitioner's cut on
such grids, balanced to one point, with no bond graph needed (the bonds do not exist before the
partition: no rank ever holds them all), no extra dependency, and a result that is deterministic
and the same on every machine. METIS needs the whole graph (every bond) on one process.
"""

from __future__ import annotations

import numpy as np

from peridyn.errors import InputError


def rcb(points: np.ndarray, n_parts: int) -> np.ndarray:
    """The part (0 .. n_parts - 1) of each point, (n_points,) int64.

    Parameters
    ----------
    points : (n_points, 3) float64, m
        2D bodies (z = 0) are cut in the plane: a zero extent is never the longest.
    n_parts : int
        At least 1 and at most n_points.

    Part sizes differ by at most one point from n_points / n_parts (rounded at each cut).
    """
    points = np.asarray(points, dtype=np.float64)
    n = len(points)
    if not 1 <= n_parts <= n:
        raise InputError(f"cannot split {n} points into {n_parts} parts: use 1 to {n} ranks")
    part = np.empty(n, dtype=np.int64)
    _bisect(points, np.arange(n), 0, n_parts, part)
    return part


def _bisect(points: np.ndarray, idx: np.ndarray, first: int, n_parts: int, part: np.ndarray) -> None:
    """Assign the points ``idx`` to parts ``first .. first + n_parts - 1``."""
    if n_parts == 1:
        part[idx] = first
        return
    x = points[idx]
    axis = int(np.argmax(np.ptp(x, axis=0)))
    order = np.lexsort((idx, x[:, axis]))  # by coordinate, then by point index
    left = n_parts // 2
    cut = (len(idx) * left) // n_parts
    _bisect(points, idx[order[:cut]], first, left, part)
    _bisect(points, idx[order[cut:]], first + left, n_parts - left, part)
