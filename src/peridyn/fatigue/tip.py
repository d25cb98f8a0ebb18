"""Crack-tip tracking (thesis seed 002, section 7.2).

The tip is the largest coordinate along the growth axis at which every point through the depth
(the points of one column: same coordinates on the two other axes) has damage phi >= 0.385.
The crack length is measured from the body's edge on the low side of the growth axis (its
outermost points minus half a spacing).
"""

from __future__ import annotations

import numpy as np

from peridyn.errors import InputError

AXES = {"x": 0, "y": 1, "z": 2}

#: Damage at which a column counts as cracked through the depth (thesis section 7.2).
TIP_DAMAGE = 0.385


def crack_tip(points: np.ndarray, phi: np.ndarray, spacing: float, axis: str = "x",
              depth_axis: str = "z", threshold: float = TIP_DAMAGE) -> float:
    """Crack length (m) along ``axis`` from the low edge; 0 when no column is cracked through.

    Parameters
    ----------
    points : (n_points, 3) float64, m
    phi : (n_points,) damage index
    spacing : float, m (half of it is added for the edge cell)
    axis, depth_axis : "x", "y" or "z", different
    """
    if axis not in AXES or depth_axis not in AXES or axis == depth_axis:
        raise InputError(f"crack tip needs two different axes among x, y, z; got {axis!r}, "
                         f"{depth_axis!r}")
    a, d = AXES[axis], AXES[depth_axis]
    other = 3 - a - d
    key = np.round(points[:, [a, other]] / (0.25 * spacing)).astype(np.int64)
    _, column = np.unique(key, axis=0, return_inverse=True)
    column = column.ravel()
    n_col = column.max() + 1
    low = np.full(n_col, np.inf)
    np.minimum.at(low, column, phi)
    cracked = low >= threshold
    edge = points[:, a].min() - 0.5 * spacing
    if not cracked.any():
        return 0.0
    tip = np.full(n_col, -np.inf)
    np.maximum.at(tip, column, points[:, a])
    return float(tip[cracked].max() - edge)
