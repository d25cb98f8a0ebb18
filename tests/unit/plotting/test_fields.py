"""Triangles of the field maps (peridyn.plotting.fields._triangulation)."""

from __future__ import annotations

import numpy as np
import pytest

from peridyn.discretization import geometry
from peridyn.plotting.fields import _triangulation


def _areas(tri) -> np.ndarray:
    x, y = tri.x[tri.triangles], tri.y[tri.triangles]
    return 0.5 * ((x[:, 1] - x[:, 0]) * (y[:, 2] - y[:, 0]) - (x[:, 2] - x[:, 0]) * (y[:, 1] - y[:, 0]))


def test_grid_triangles_tile_the_plate_counter_clockwise():
    """On a plate layer (a regular grid) the triangles are counter-clockwise, each half a grid
    cell, and together cover the rectangle through the outer points: its area exactly (the sum
    of the cells), like the Delaunay triangulation of the same points."""
    body = geometry.plate(0.012, 0.008, 0.002, spacing=1e-3, layers=2)
    top = body.points[body.points[:, 2] >= body.points[:, 2].max() - 1e-9]
    xs, ys = top[:, 0] * 1e3, top[:, 1] * 1e3
    tri = _triangulation(top, xs, ys, 2.01 * np.sqrt(2))
    areas = _areas(tri)
    np.testing.assert_allclose(areas, 0.5, rtol=1e-9)  # mm^2: half of a 1 mm cell
    rectangle = (xs.max() - xs.min()) * (ys.max() - ys.min())
    np.testing.assert_allclose(areas.sum(), rectangle, rtol=1e-12)


def test_grid_with_a_missing_point_leaves_only_its_diamond_blank():
    """A point removed from the grid: the four cells around it keep one triangle each (three
    corners present), so the blank is the diamond of area 2 cells' halves = 2 mm^2."""
    body = geometry.plate(0.012, 0.008, 0.002, spacing=1e-3, layers=2)
    top = body.points[body.points[:, 2] >= body.points[:, 2].max() - 1e-9]
    middle = np.argmin(np.hypot(top[:, 0] - 0.0055, top[:, 1] - 0.0035))
    kept = np.delete(top, middle, axis=0)
    xs, ys = kept[:, 0] * 1e3, kept[:, 1] * 1e3
    tri = _triangulation(kept, xs, ys, 2.01 * np.sqrt(2))
    rectangle = (xs.max() - xs.min()) * (ys.max() - ys.min())
    np.testing.assert_allclose(_areas(tri).sum(), rectangle - 2.0, rtol=1e-12)


@pytest.mark.bitwise
def test_scattered_points_use_delaunay_without_long_triangles():
    """Points off a grid: Delaunay triangles, those with an edge longer than ``longest`` masked. The
    mask is compared exactly with the same edge lengths computed here: the same differences and
    ``np.hypot``, the same bits."""
    rng = np.random.default_rng(3)
    points = rng.uniform(0.0, 0.01, size=(200, 2))
    xs, ys = points[:, 0] * 1e3, points[:, 1] * 1e3
    tri = _triangulation(points, xs, ys, 1.5)
    x, y = tri.x[tri.triangles], tri.y[tri.triangles]
    longest = np.max(np.hypot(x - np.roll(x, 1, axis=1), y - np.roll(y, 1, axis=1)), axis=1)
    np.testing.assert_array_equal(tri.mask, longest > 1.5)
    assert tri.mask.any() and not tri.mask.all()
