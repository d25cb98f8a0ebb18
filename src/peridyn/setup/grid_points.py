"""The points of a case's generated grid (box, plate, rectangle), all of them or a range of
planes across x, and the case file's regions of points.

A region that depends on the whole body's extent (a ``face``) takes the whole body's bounds
when the body is a part of it (a rank's slab of grid planes: ``peridyn.parallel.lattice_domain``).
"""

from __future__ import annotations

import numpy as np

from peridyn.discretization import geometry
from peridyn.discretization.body import Body, in_box, in_cylinder, in_sphere
from peridyn.errors import InputError
from peridyn.io.case import Case, Region


def grid_points(case: Case, planes=None) -> Body:
    """The points of the case's box, plate or rectangle, before removals: all, or with
    ``planes`` = (first, stop) the grid's planes of cells across x ``first .. stop - 1``
    (``geometry.planes_of``), with the values the whole grid has."""
    g, d = case.geometry, case.discretization
    if g.type == "box":
        return geometry.box(g.size, d.spacing, g.origin or (0.0, 0.0, 0.0), planes)
    if g.type == "plate":
        return geometry.plate(
            *g.size,
            spacing=d.spacing,
            layers=g.layers,
            origin=g.origin or (0.0, 0.0, 0.0),
            layer_placement=g.layer_placement,
            planes=planes,
        )
    return geometry.rectangle(
        *g.size,
        spacing=d.spacing,
        thickness=g.thickness,
        plane=g.plane,
        origin=(g.origin or (0.0, 0.0))[:2],
        planes=planes,
    )


def grid_planes(case: Case) -> int:
    """The number of planes of cells across x of the case's box, plate or rectangle."""
    d = case.discretization
    spacing = np.asarray(d.spacing, dtype=float).reshape(-1)[:1]
    return int(geometry.cell_counts(np.asarray(case.geometry.size[:1], dtype=float), spacing, warn=False)[0])


def region_mask(body: Body, region: Region, where: str, bounds=None) -> np.ndarray:
    """(n_points,) bool mask of a case-file region; ``bounds`` ((2, 3) m, the lowest and highest
    coordinates of the whole body of which ``body`` is a part, None: ``body``'s own) place the
    faces."""
    pad = pad3
    if region.type == "all":
        return np.ones(body.n_points, dtype=bool)
    if region.type == "box":
        return in_box(pad(region.min), pad(region.max))(body.points)
    if region.type == "sphere":
        return in_sphere(pad(region.center), region.radius)(body.points)
    if region.type == "cylinder":
        return in_cylinder(pad(region.center), region.radius, region.axis)(body.points)
    if region.type == "face":
        return geometry.face(body, region.face, region.depth, bounds)
    if region.type == "points":
        return point_mask(body, region.indices, where)
    try:
        return geometry.layer(body, region.index)
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None


def point_mask(body: Body, indices: list[int], where: str) -> np.ndarray:
    """(n_points,) bool mask of 0-based point ``indices``; an index past the body is refused."""
    idx = np.asarray(indices, dtype=np.int64)
    if idx.max() >= body.n_points:
        raise InputError(
            f"{where}.indices: point {int(idx.max())} does not exist (the body has {body.n_points} points)"
        )
    mask = np.zeros(body.n_points, dtype=bool)
    mask[idx] = True
    return mask


def pad3(v) -> list:
    """A 2- or 3-component coordinate as 3 components (z = 0 for 2D input)."""
    return list(v) + [0.0] * (3 - len(v))
