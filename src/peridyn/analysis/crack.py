"""Crack paths from the damage field: polylines, length, angle and deviation.

A point is *cracked* when its damage index phi reaches ``threshold`` (default 0.35).
A straight crack between two rows of points leaves both rows at phi ~ 0.4 (the
share of the horizon disc across the crack line, 0.39 for a horizon of 3 spacings,
0.5 on the line itself), while a point ahead of a crack tip stays below ~0.3; 0.35
separates the two. Cracked points closer than ``link`` (1.5 spacings) form clusters.

Each cluster gives one main path, its mid-line: in the graph linking cracked points closer
than 2.5 spacings, find the point farthest from an arbitrary one (one end, e1), the point
farthest from e1 (the other end, e2) and the shortest route between them. Every cracked
point within three spacings of the route takes the arc length of its nearest route vertex;
points are binned by it two spacings wide and the bins' centroids joined (this folds the
damaged band, two rows wide in the bulk and up to about a horizon wide where a crack meets
a free edge or branches, onto its mid-line, while the points of a branch stay out of it).
The two end vertices move outwards (along the line from the centroid three bins in, so that
the fanned damage where a crack meets an edge does not tilt them) to the farthest point of
their bins, and the polyline is thinned to vertices at least a spacing apart. Cracked points farther than two
spacings from the main path that are themselves a cluster of at least ``min_points``
give further paths (branches), reported after the main one.

Per path: length (m, along the polyline), angle (deg, of the line from the start to
the end, start being the end with the smaller x, so the angle lies in (-90, 90]) and
the largest distance of the polyline from a reference line (the nearest pre-crack's
line, or the start-end line when there is none).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components, shortest_path
from scipy.spatial import cKDTree

from peridyn.errors import InputError

DEFAULT_THRESHOLD = 0.35
GEODESIC_LINK = 2.5  # spacings: links of the graph for path distances (near-Euclidean)
BIN_WIDTH = 2.0  # spacings: width of the level-set bins along a crack
BAND = 3.0  # spacings: half-width of the band of points around a route
END_SPAN = 3  # bins: the direction in which an end vertex moves out is over this many


@dataclass
class CrackPath:
    """One crack path.

    Attributes
    ----------
    points : (m, 2) float64, m
        Polyline from start (smaller x) to end.
    length_m, angle_deg, max_deviation_m : float
        See the module docstring.
    """

    points: np.ndarray
    length_m: float
    angle_deg: float
    max_deviation_m: float

    def summary(self) -> dict:
        """The run JSON entry: ``{"length_m", "angle_deg", "max_deviation_m"}``."""
        return {
            "length_m": self.length_m,
            "angle_deg": self.angle_deg,
            "max_deviation_m": self.max_deviation_m,
        }


def crack_paths(
    points: np.ndarray,
    phi: np.ndarray,
    spacing: float,
    threshold: float = DEFAULT_THRESHOLD,
    reference_lines=(),
    min_points: int = 3,
) -> list[CrackPath]:
    """Crack paths of a damage field, longest first.

    Parameters
    ----------
    points : (n, 2) or (n, 3) float64, m
        Reference positions (only x and y are used).
    phi : (n,) float64
        Damage index in [0, 1].
    spacing : float, m
        Grid spacing.
    threshold : float in (0, 1]
    reference_lines : sequence of (start, end) pairs of 2 floats, m
        Pre-crack segments: a path's deviation is measured from the line of the nearest one.
    min_points : int
        Smallest cluster (or branch) reported.
    """
    points = np.asarray(points, dtype=float)
    phi = np.asarray(phi, dtype=float)
    if points.ndim != 2 or points.shape[1] not in (2, 3) or phi.shape != (points.shape[0],):
        raise InputError(
            f"crack_paths needs points (n, 2|3) and phi (n,), got {points.shape} and {phi.shape}"
        )
    if not 0 < threshold <= 1:
        raise InputError(f"crack threshold must be in (0, 1], got {threshold!r}")
    if not spacing > 0:
        raise InputError(f"spacing must be positive, got {spacing!r}")
    cracked = points[phi >= threshold, :2]
    lines = [(np.asarray(a, float)[:2], np.asarray(b, float)[:2]) for a, b in reference_lines]
    paths = []
    for cluster in _clusters(cracked, 1.5 * spacing, min_points):
        paths += _paths_of_cluster(cluster, spacing, lines, min_points)
    return sorted(paths, key=lambda p: -p.length_m)


def path_from(paths, tip, reach: float) -> CrackPath | None:
    """The longest of ``paths`` with an end within ``reach`` (m) of ``tip`` (m, x and y), or
    None when no path ends there."""
    tip = np.asarray(tip, dtype=float)[:2]
    ending = [p for p in paths if np.linalg.norm(p.points[[0, -1]] - tip, axis=1).min() <= reach]
    return max(ending, key=lambda p: p.length_m, default=None)


def departure_angle(path: CrackPath, tip, run: float) -> float:
    """Angle (deg from +x, in (-180, 180]) at which ``path`` leaves ``tip`` (m, x and y): the
    direction of the least-squares line through its vertices within ``run`` (m) of the tip,
    pointing away from the tip."""
    tip = np.asarray(tip, dtype=float)[:2]
    pts = path.points
    if np.linalg.norm(pts[-1] - tip) < np.linalg.norm(pts[0] - tip):
        pts = pts[::-1]
    near = pts[np.linalg.norm(pts - tip, axis=1) <= run]
    if len(near) < 2:
        raise InputError(f"fewer than two crack-path vertices within {run!r} m of the tip {tip}")
    direction = np.linalg.svd(near - near.mean(axis=0))[2][0]
    if direction @ (near[-1] - near[0]) < 0:
        direction = -direction
    return float(np.degrees(np.arctan2(direction[1], direction[0])))


def total_crack_length(points, phi, spacing, threshold=DEFAULT_THRESHOLD) -> float:
    """Sum of the lengths of every crack path, m."""
    return float(sum(p.length_m for p in crack_paths(points, phi, spacing, threshold)))


def _clusters(xy: np.ndarray, link: float, min_points: int) -> list[np.ndarray]:
    """Groups of points connected by links shorter than ``link`` (each with >= min_points)."""
    if len(xy) < max(min_points, 2):
        return []
    graph = _link_graph(xy, link)
    n, labels = connected_components(graph, directed=False)
    groups = [xy[labels == k] for k in range(n)]
    return [g for g in groups if len(g) >= min_points]


def _link_graph(xy: np.ndarray, link: float):
    pairs = cKDTree(xy).query_pairs(link, output_type="ndarray")
    d = np.linalg.norm(xy[pairs[:, 0]] - xy[pairs[:, 1]], axis=1)
    n = len(xy)
    return coo_matrix((d, (pairs[:, 0], pairs[:, 1])), shape=(n, n)).tocsr()


def _paths_of_cluster(xy, spacing, lines, min_points) -> list[CrackPath]:
    link = 1.5 * spacing
    main = _main_polyline(xy, link, spacing)
    found = [_describe(main, lines)]
    # branches: cracked points more than two spacings away from the main path
    dist = _distance_to_polyline(xy, main)
    rest = xy[dist > 2.0 * spacing]
    for branch in _clusters(rest, link, min_points):
        found.append(_describe(_main_polyline(branch, link, spacing), lines))
    return found


def _main_polyline(xy: np.ndarray, link: float, spacing: float) -> np.ndarray:
    """Mid-line polyline of a connected cluster (module docstring)."""
    if len(xy) == 1:
        return xy.copy()
    graph = _link_graph(xy, GEODESIC_LINK * spacing)
    first = int(np.argmax(_geodesic(graph, 0)[0]))
    from_first, predecessors = _geodesic(graph, first)
    order = [int(np.argmax(from_first))]
    while order[-1] != first:
        order.append(int(predecessors[order[-1]]))
    route = xy[order]
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(route, axis=0), axis=1))])
    dist, nearest = cKDTree(route).query(xy)
    near = dist <= BAND * spacing
    xy = xy[near]
    level = np.floor(arc[nearest[near]] / (BIN_WIDTH * spacing)).astype(np.int64)
    counts = np.bincount(level)
    used = counts > 0
    mid = np.stack([np.bincount(level, weights=xy[:, a])[used] / counts[used] for a in (0, 1)], axis=1)
    if len(mid) > 1:
        inner = min(END_SPAN, len(mid) - 1)
        mid[0] = _extended_end(mid[0], mid[inner], xy[level == level.min()])
        mid[-1] = _extended_end(mid[-1], mid[-1 - inner], xy[level == level.max()])
    mid = _thin(mid, spacing)
    if mid[-1, 0] < mid[0, 0] or (mid[-1, 0] == mid[0, 0] and mid[-1, 1] < mid[0, 1]):
        mid = mid[::-1]
    return mid


def _extended_end(end: np.ndarray, inner: np.ndarray, end_points: np.ndarray) -> np.ndarray:
    """``end`` moved outwards, along the direction from ``inner`` to it, to the farthest of its
    bin's points."""
    direction = end - inner
    norm = np.linalg.norm(direction)
    if norm == 0:
        return end
    direction /= norm
    reach = float(np.max((end_points - end) @ direction))
    return end + max(reach, 0.0) * direction


def _geodesic(graph, source: int):
    """Link-path distance (m) of every point of a connected cluster from ``source``, and the
    predecessors along the shortest paths."""
    dist, pred = shortest_path(graph, directed=False, indices=source, return_predecessors=True)
    return np.where(np.isfinite(dist), dist, 0.0), pred


def _thin(polyline: np.ndarray, step: float) -> np.ndarray:
    """Vertices at least ``step`` apart along the polyline, keeping both ends."""
    kept = [polyline[0]]
    for p in polyline[1:-1]:
        if np.linalg.norm(p - kept[-1]) >= step:
            kept.append(p)
    if len(polyline) > 1:
        if len(kept) > 1 and np.linalg.norm(polyline[-1] - kept[-1]) < 0.5 * step:
            kept[-1] = polyline[-1]
        else:
            kept.append(polyline[-1])
    return np.array(kept)


def _describe(polyline: np.ndarray, lines) -> CrackPath:
    length = float(np.sum(np.linalg.norm(np.diff(polyline, axis=0), axis=1)))
    chord = polyline[-1] - polyline[0]
    angle = float(np.degrees(np.arctan2(chord[1], chord[0]))) if length > 0 else 0.0
    if lines:
        a, b = min(lines, key=lambda ab: _distance_to_segment(polyline, *ab).min())
    else:
        a, b = polyline[0], polyline[-1]
    deviation = float(_distance_to_line(polyline, a, b).max())
    return CrackPath(polyline, length, angle, deviation)


def _distance_to_line(xy, a, b) -> np.ndarray:
    """Distance of each point from the infinite line through a and b (from a if a == b)."""
    d = b - a
    norm = np.linalg.norm(d)
    if norm == 0:
        return np.linalg.norm(xy - a, axis=1)
    return np.abs(d[0] * (xy[:, 1] - a[1]) - d[1] * (xy[:, 0] - a[0])) / norm


def _distance_to_segment(xy, a, b) -> np.ndarray:
    d = b - a
    t = np.clip(((xy - a) @ d) / max(d @ d, 1e-300), 0.0, 1.0)
    return np.linalg.norm(xy - (a + t[:, None] * d), axis=1)


def _distance_to_polyline(xy, polyline) -> np.ndarray:
    if len(polyline) == 1:
        return np.linalg.norm(xy - polyline[0], axis=1)
    return np.min(
        [_distance_to_segment(xy, a, b) for a, b in zip(polyline[:-1], polyline[1:], strict=True)], axis=0
    )
