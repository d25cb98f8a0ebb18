"""Geometry of a transducer network and of a crack: the paths, which of them a crack crosses,
and a crack's polyline cut to a length.

A crack is a polyline of its (x, y) vertices, m, from where it starts (the notch root) to its tip.
"""

from __future__ import annotations

from itertools import combinations

import numpy as np

from peridyn.errors import InputError

__all__ = [
    "crossed_paths",
    "network_paths",
    "path_lengths",
    "polyline_centre",
    "polyline_length",
    "truncated",
]


def network_paths(n: int) -> np.ndarray:
    """(n (n - 1) / 2, 2) int: every pair ``(i, j)``, ``i < j``, of ``n`` transducers (pitch-catch
    paths; the signal of ``i`` firing recorded at ``j`` and the reverse are one path by reciprocity
    and are averaged by the monitoring job)."""
    if n < 2:
        raise InputError(f"a transducer network needs at least 2 transducers, got {n}")
    return np.array(list(combinations(range(n), 2)), dtype=int)


def path_lengths(transducers, paths) -> np.ndarray:
    """(n_paths,) distances (m) between each path's transducers ((n, 2) m)."""
    xy = np.asarray(transducers, dtype=float)
    p = np.asarray(paths, dtype=int)
    return np.hypot(*(xy[p[:, 1]] - xy[p[:, 0]]).T)


def _segments_cross(a, b, c, d) -> bool:
    """Whether segments a-b and c-d ((2,) each) cross (touching counts)."""

    def side(p, q, r):
        return np.sign((q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]))

    d1, d2, d3, d4 = side(c, d, a), side(c, d, b), side(a, b, c), side(a, b, d)
    return bool(d1 * d2 <= 0 and d3 * d4 <= 0)


def crossed_paths(transducers, paths, polyline) -> np.ndarray:
    """(n_paths,) bool: paths whose straight line crosses the crack ``polyline`` ((m, 2), m)."""
    xy = np.asarray(transducers, dtype=float)
    line = np.asarray(polyline, dtype=float)
    if line.ndim != 2 or line.shape[1] != 2 or len(line) < 2:
        raise InputError(f"a crack polyline needs (m >= 2, 2) vertices, got shape {line.shape}")
    out = np.zeros(len(paths), dtype=bool)
    for k, (i, j) in enumerate(np.asarray(paths, dtype=int)):
        out[k] = any(_segments_cross(xy[i], xy[j], line[m], line[m + 1]) for m in range(len(line) - 1))
    return out


def polyline_length(polyline) -> float:
    """Length (m) of a polyline ((m, 2), m)."""
    line = np.asarray(polyline, dtype=float)
    return float(np.hypot(*np.diff(line, axis=0).T).sum())


def truncated(polyline, length: float) -> np.ndarray:
    """The first ``length`` (m) of ``polyline`` ((m, 2), m), its last vertex moved onto the cut;
    the whole polyline when it is shorter."""
    line = np.asarray(polyline, dtype=float)
    if not length > 0:
        raise InputError(f"a crack length to cut a polyline at must be > 0, got {length!r}")
    steps = np.hypot(*np.diff(line, axis=0).T)
    ends = np.cumsum(steps)
    k = int(np.searchsorted(ends, length))
    if k >= len(steps):
        return line.copy()
    before = ends[k] - steps[k]
    cut = line[k] + (line[k + 1] - line[k]) * (length - before) / steps[k]
    return np.vstack([line[: k + 1], cut])


def polyline_centre(polyline) -> np.ndarray:
    """(2,) point (m) halfway along ``polyline`` ((m, 2), m)."""
    line = np.asarray(polyline, dtype=float)
    half = polyline_length(line) / 2
    if half <= 0:
        return line[0].copy()
    return truncated(line, half)[-1]
