"""Crack-tip tracking (Freimanis 2019, section 7.2).

The tip is the farthest coordinate along the growth axis, in the sense the crack grows, at which
every point through the depth (the points of one column: same coordinates on the two other axes)
has damage phi >= 0.385. The crack length is measured from where the crack starts: by default the
body's edge on the side it grows from (its outermost points minus half a spacing), or a given
coordinate (a notch root inside the body), in which case only the columns beyond it count.
"""

from __future__ import annotations

import numpy as np

from peridyn.errors import InputError

AXES = {"x": 0, "y": 1, "z": 2}

#: Damage at which a column counts as cracked through the depth (thesis section 7.2).
TIP_DAMAGE = 0.385


def crack_tip(
    points: np.ndarray,
    phi: np.ndarray,
    spacing: float,
    axis: str = "x",
    depth_axis: str = "z",
    threshold: float = TIP_DAMAGE,
    start: float | None = None,
    sense: str = "+",
) -> float:
    """Crack length (m) along ``axis``; 0 when no column is cracked through.

    Parameters
    ----------
    points : (n_points, 3) float64, m
    phi : (n_points,) damage index
    spacing : float, m (half of it is added for the edge cell)
    axis, depth_axis : "x", "y" or "z", different
    threshold : damage at which a column counts as cracked through the depth
    start : m, coordinate along ``axis`` where the crack starts; None: the body's edge on the
        side it grows from
    sense : "+" (the crack grows towards +axis) or "-"
    """
    if axis not in AXES or depth_axis not in AXES or axis == depth_axis:
        raise InputError(f"crack tip needs two different axes among x, y, z; got {axis!r}, {depth_axis!r}")
    if sense not in ("+", "-"):
        raise InputError(f"crack tip sense must be '+' or '-', got {sense!r}")
    a, d = AXES[axis], AXES[depth_axis]
    other = 3 - a - d
    key = np.round(points[:, [a, other]] / (0.25 * spacing)).astype(np.int64)
    _, column = np.unique(key, axis=0, return_inverse=True)
    column = column.ravel()
    n_col = column.max() + 1
    low = np.full(n_col, np.inf)
    np.minimum.at(low, column, phi)
    position = np.zeros(n_col)
    position[column] = points[:, a]
    grow = 1.0 if sense == "+" else -1.0
    # distance along the growth sense from the start (the edge: outermost points + half a cell)
    origin = (
        start
        if start is not None
        else (points[:, a].min() - 0.5 * spacing if sense == "+" else points[:, a].max() + 0.5 * spacing)
    )
    run = grow * (position - origin)
    cracked = (low >= threshold) & (run > 0.0)
    return float(run[cracked].max()) if cracked.any() else 0.0
