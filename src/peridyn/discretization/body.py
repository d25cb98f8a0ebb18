"""The discretised body: material points, their volumes, cells and named node sets.

One array layout everywhere: points are ``(n_points, 3)`` float64 in metres,
also for 2D bodies (``dim == 2``), whose points lie in the plane ``z = 0`` and
whose volumes are cell area times ``thickness``. Kernels therefore have a single
3D form; 2D results are the first two columns.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace

import numpy as np

from peridyn.errors import InputError, did_you_mean


@dataclass(frozen=True, eq=False)
class Body:
    """Material points of a peridynamic body.

    Parameters
    ----------
    points : (n_points, 3) float64, m
        Reference positions (z = 0 for 2D bodies).
    volumes : (n_points,) float64, m^3
        Volume of each point's cell.
    cells : (n_points, 3) or (3,) float64, m
        Side lengths of each point's (box) cell, used for partial volumes.
        For 2D bodies the third side is the thickness. One row (a grid) is kept as a
        read-only (n_points, 3) view of it.
    dim : {2, 3}
        Spatial dimension of the model.
    spacing : float, m
        Reference spacing: horizons given as a multiple refer to it (the
        largest in-plane cell side of a grid).
    node_sets : mapping of str to (n,) int64
        Named sets of point indices.
    thickness : float or None, m
        Out-of-plane thickness of a 2D body.
    plane : {"stress", "strain"} or None
        Plane assumption of a 2D body.
    layer_index : (n_points,) int or None
        Through-thickness layer of each point for layered plates (0 = bottom; int8 up to 127
        layers).
    """

    points: np.ndarray
    volumes: np.ndarray
    cells: np.ndarray
    dim: int
    spacing: float
    node_sets: Mapping[str, np.ndarray] = field(default_factory=dict)
    thickness: float | None = None
    plane: str | None = None
    layer_index: np.ndarray | None = None

    def __post_init__(self):
        points = np.ascontiguousarray(self.points, dtype=np.float64)
        if points.ndim != 2 or points.shape[1] != 3:
            raise InputError(f"points must have shape (n_points, 3), got {points.shape}")
        n = len(points)
        if n == 0:
            raise InputError("a body needs at least one point")
        if not np.all(np.isfinite(points)):
            bad = int(np.flatnonzero(~np.isfinite(points).all(axis=1))[0])
            raise InputError(f"point {bad} has a non-finite coordinate {points[bad].tolist()}")
        volumes = np.ascontiguousarray(self.volumes, dtype=np.float64)
        if volumes.shape != (n,):
            raise InputError(f"volumes must have shape ({n},), got {volumes.shape}")
        if not np.all(volumes > 0):
            bad = int(np.flatnonzero(~(volumes > 0))[0])
            raise InputError(f"volume of point {bad} must be positive, got {volumes[bad]!r}")
        cells = np.asarray(self.cells, dtype=np.float64)
        # one cell for every point (a grid) stays one row seen n times: a read-only view that
        # spares 24 bytes a point; cells of their own are an (n, 3) array
        # (a body made from another, ``dataclasses.replace``, keeps that view: rows of stride 0)
        one_cell = cells.ndim == 1 or (cells.shape == (n, 3) and cells.strides[0] == 0)
        cells = (
            np.broadcast_to(cells if cells.ndim == 1 else cells[0], (n, 3))
            if one_cell
            else np.ascontiguousarray(np.broadcast_to(cells, (n, 3)))
        )
        if self.dim not in (2, 3):
            raise InputError(f"dim must be 2 or 3, got {self.dim!r}")
        if self.dim == 2:
            if self.thickness is None or not self.thickness > 0:
                raise InputError(f"a 2D body needs a positive thickness, got {self.thickness!r}")
            if self.plane not in ("stress", "strain"):
                raise InputError(f"plane must be 'stress' or 'strain', got {self.plane!r}")
            if np.any(points[:, 2] != 0.0):
                raise InputError("points of a 2D body must have z = 0")
        if not self.spacing > 0:
            raise InputError(f"spacing must be positive, got {self.spacing!r}")
        sets = {name: _as_index_array(name, idx, n) for name, idx in self.node_sets.items()}
        object.__setattr__(self, "points", points)
        object.__setattr__(self, "volumes", volumes)
        object.__setattr__(self, "cells", cells)
        object.__setattr__(self, "node_sets", sets)

    @property
    def n_points(self) -> int:
        """Number of material points."""
        return len(self.points)

    def __repr__(self) -> str:
        return (
            f"Body(n_points={self.n_points}, dim={self.dim}, spacing={self.spacing:g} m, "
            f"node_sets={sorted(self.node_sets)})"
        )

    def node_set(self, name: str, empty: bool = False) -> np.ndarray:
        """Indices of the named node set; a clear error when it does not exist or, unless
        ``empty`` (a rank's part, which may hold none of a set's points), is empty."""
        if name not in self.node_sets:
            raise InputError(
                f"unknown node set {name!r}{did_you_mean(name, self.node_sets)}; "
                f"defined sets: {sorted(self.node_sets)}"
            )
        idx = self.node_sets[name]
        if len(idx) == 0 and not empty:
            raise InputError(f"node set {name!r} is empty: its region contains no point")
        return idx

    def with_node_set(self, name: str, selection, empty: bool = False) -> Body:
        """A copy with one more named node set.

        Parameters
        ----------
        selection : (n_points,) bool mask, index array, or callable
            A callable receives ``points`` (n_points, 3) and returns a mask.
        empty : bool
            Allow a set without points (a rank's part that holds none of a set's points: the
            whole set is checked over the ranks).
        """
        if callable(selection):
            selection = selection(self.points)
        idx = _as_index_array(name, selection, self.n_points)
        if len(idx) == 0 and not empty:
            raise InputError(f"node set {name!r} is empty: its region contains no point")
        return replace(self, node_sets={**self.node_sets, name: idx})

    def subset(self, indices) -> Body:
        """A copy made of the points ``indices`` ((k,) int, distinct), in that order; node sets
        keep their points that are taken (a set may become empty) and are re-indexed."""
        idx = np.asarray(indices, dtype=np.int64)
        new_index = np.full(self.n_points, -1, dtype=np.int64)
        new_index[idx] = np.arange(len(idx))
        sets = {k: new_index[v][new_index[v] >= 0] for k, v in self.node_sets.items()}
        layers = None if self.layer_index is None else self.layer_index[idx]
        return replace(
            self,
            points=self.points[idx],
            volumes=self.volumes[idx],
            cells=self.cells[0] if self.cells.strides[0] == 0 else self.cells[idx],
            node_sets=sets,
            layer_index=layers,
        )

    def remove(self, mask_or_predicate) -> Body:
        """A copy without the points selected (e.g. a hole); node sets are re-indexed.

        Parameters
        ----------
        mask_or_predicate : (n_points,) bool or callable(points) -> bool mask
        """
        mask = mask_or_predicate(self.points) if callable(mask_or_predicate) else mask_or_predicate
        mask = np.asarray(mask, dtype=bool)
        if mask.shape != (self.n_points,):
            raise InputError(f"removal mask must have shape ({self.n_points},), got {mask.shape}")
        if mask.all():
            raise InputError("the removal takes away every point of the body")
        return self.subset(np.flatnonzero(~mask))


@dataclass(frozen=True)
class BodySize:
    """What a rank that does not hold the whole body knows of it (lattice storage under MPI,
    where rank 0 alone makes the whole body, for the recorder): its size.

    Attributes
    ----------
    n_points : int
    dim : {2, 3}
    spacing : float, m
    """

    n_points: int
    dim: int
    spacing: float


def _as_index_array(name: str, selection, n: int) -> np.ndarray:
    arr = np.asarray(selection)
    if arr.dtype == bool:
        if arr.shape != (n,):
            raise InputError(f"node set {name!r}: mask must have shape ({n},), got {arr.shape}")
        return np.flatnonzero(arr).astype(np.int64)
    arr = arr.astype(np.int64).ravel()
    if arr.size and (arr.min() < 0 or arr.max() >= n):
        raise InputError(f"node set {name!r}: indices must lie in [0, {n}), got {arr.min()}..{arr.max()}")
    if np.all(arr[1:] > arr[:-1]):  # already sorted and unique, as a body's own sets are
        return arr
    return np.unique(arr)


# -- region predicates: callables points (n, 3) -> bool mask (n,) -------------------------


def in_box(lower, upper) -> Callable[[np.ndarray], np.ndarray]:
    """Points inside the axis-aligned box ``lower <= x <= upper`` (m, 3 values each)."""
    lo = np.asarray(lower, dtype=float)
    hi = np.asarray(upper, dtype=float)
    return lambda x: np.all((x >= lo) & (x <= hi), axis=1)


def in_sphere(center, radius: float) -> Callable[[np.ndarray], np.ndarray]:
    """Points within ``radius`` (m) of ``center`` (m, 3 values)."""
    c = np.asarray(center, dtype=float)
    return lambda x: np.einsum("ij,ij->i", x - c, x - c) <= radius**2


def in_cylinder(center, radius: float, axis: str = "z") -> Callable[[np.ndarray], np.ndarray]:
    """Points within ``radius`` (m) of the line through ``center`` along ``axis`` (x, y or z)."""
    c = np.asarray(center, dtype=float)
    keep = [a for a in range(3) if a != "xyz".index(axis)]
    return lambda x: np.sum((x[:, keep] - c[keep]) ** 2, axis=1) <= radius**2
