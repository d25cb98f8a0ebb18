"""A rank's slab of a case's generated grid, made without the whole body (lattice storage
under MPI: ``peridyn.parallel.lattice_domain``, docs/mpi.md "Lattice storage under MPI").

Two passes over the grid's planes of cells across x, the generators' slowest axis:

1. ``grid_plan``: each rank makes an equal share of the planes, a few at a time, takes the
   removals away (a face placed by the whole grid's bounds) and counts the points each plane
   keeps. The counts (an allgather) number every plane's points as the whole body does (a
   slab's points are one range, after the points of the planes before it), and the kept points'
   lowest and highest coordinates (an allreduce; min and max are exact) give the whole grid's
   origin, shape and bounds as ``grid_layout`` and ``geometry.face`` find them on the whole body.
2. ``slab_points``: the rank makes its planes and its ghost planes and takes the removals away.

The points, volumes and layers so made are the whole body's, bit for bit: every coordinate is
computed by the same expression as when the whole grid is made (``geometry.planes_of``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from peridyn.discretization.body import Body
from peridyn.errors import InputError
from peridyn.io.case import Case
from peridyn.parallel.lattice_domain import slab_bounds
from peridyn.setup.grid_points import grid_planes, grid_points, region_mask

#: Points the counting pass makes at a time (a few planes of a large grid).
CHUNK_POINTS = 1 << 17


def slab_refusals(case: Case) -> list[str]:
    """What keeps ``case`` from being made slab by slab (each rank then makes the whole body
    first, as for bond lists): regions of listed point numbers (they number the whole body)
    and pin-force actuators (their forces go to the patch's outermost points)."""
    why = []
    regions = [*case.removals, *case.node_sets.values()]
    if any(r.type == "points" for r in regions):
        why.append("a region of listed point numbers")
    if any(a.type != "pzt_radial" for a in case.actuators.values()):
        why.append("a pin-force actuator")
    return why


@dataclass(frozen=True)
class GridPlan:
    """The whole grid of a case as the counting pass finds it.

    Attributes
    ----------
    counts : (n_planes,) int64
        Points each of the generator's planes across x keeps after the removals.
    first : int
        The first plane that keeps a point: the whole grid's plane 0.
    origin : (3,) float64, m
        The whole body's lowest coordinates (``grid_layout``'s origin).
    shape : (3,) int64
        The whole grid's (``grid_layout``'s shape).
    bounds : (2, 3) float64, m
        The whole body's lowest and highest coordinates (``geometry.face``).
    removal_bounds : (2, 3) float64, m
        The same before the removals (the faces of a removal).
    n_layers : int or None
        A plate's layers (``geometry.layer``), None for other bodies.
    """

    counts: np.ndarray
    first: int
    origin: np.ndarray
    shape: np.ndarray
    bounds: np.ndarray
    removal_bounds: np.ndarray
    n_layers: int | None

    @property
    def n_points(self) -> int:
        """Points of the whole body."""
        return int(self.counts.sum())

    def offset(self, plane: int) -> int:
        """Points of the whole body before the whole grid's plane ``plane``."""
        return int(self.counts[: self.first + plane].sum())


def kept(case: Case, body: Body, removal_bounds: np.ndarray) -> np.ndarray:
    """(n_points,) bool: the points of ``body`` (planes of the case's grid) that no removal
    takes; ``removal_bounds`` (2, 3) m: the whole grid's before removals."""
    keep = np.ones(body.n_points, dtype=bool)
    for k, region in enumerate(case.removals):
        keep &= ~region_mask(body, region, f"removals[{k}]", removal_bounds)
    return keep


def _extent(points: np.ndarray) -> np.ndarray:
    """(2, 3): the lowest and highest coordinates of ``points`` (inf and -inf without any)."""
    if not len(points):
        return np.array([[np.inf] * 3, [-np.inf] * 3])
    return np.array([points.min(axis=0), points.max(axis=0)])


def grid_plan(case: Case, comm) -> GridPlan:
    """The ``GridPlan`` of the case's box, plate or rectangle (the counting pass: module
    docstring). Collective.

    Raises
    ------
    InputError
        When the removals leave no point.
    """
    n = grid_planes(case)
    ends = [grid_points(case, (0, 1)), grid_points(case, (n - 1, n))]
    removal_bounds = _extent(np.concatenate([b.points for b in ends]))
    per_plane = ends[0].n_points
    step = max(1, CHUNK_POINTS // per_plane)
    share = slab_bounds(n, comm.size)
    lo, hi = int(share[comm.rank]), int(share[comm.rank + 1])
    counts = np.zeros(hi - lo, dtype=np.int64)
    extent = _extent(np.zeros((0, 3)))
    top = -1
    for a in range(lo, hi, step):
        b = min(hi, a + step)
        body = grid_points(case, (a, b))
        keep = kept(case, body, removal_bounds)
        counts[a - lo : b - lo] = keep.reshape(b - a, per_plane).sum(axis=1)
        ext = _extent(body.points[keep])
        extent = np.array([np.minimum(extent[0], ext[0]), np.maximum(extent[1], ext[1])])
        if body.layer_index is not None and keep.any():
            top = max(top, int(body.layer_index[keep].max()))
    counts = np.concatenate(comm.allgather(counts))
    low, high = comm.allreduce(extent[0], "min"), comm.allreduce(extent[1], "max")
    top = comm.allreduce(top, "max")
    if not counts.any():
        raise InputError("the removals take away every point of the body")
    spacing = ends[0].cells[0].copy()
    if ends[0].dim == 2:
        spacing[2] = ends[0].thickness
    shape = np.rint((high - low) / spacing).astype(np.int64) + 1
    first = int(np.flatnonzero(counts)[0])
    layers = None if ends[0].layer_index is None else top + 1
    return GridPlan(counts, first, low, shape, np.array([low, high]), removal_bounds, layers)


def slab_points(case: Case, plan: GridPlan, first: int, stop: int) -> tuple[Body, np.ndarray]:
    """The points of the whole grid's planes across x ``first .. stop - 1`` (``plan``'s
    numbering: plane 0 is the first with a point) without the removed ones, and their numbers
    in the whole body ((k,) int64, ascending).

    Raises
    ------
    InputError
        When the planes hold no point, or no point of a plate's top layer (``geometry.layer``
        would count fewer layers than the whole plate has).
    """
    planes = (plan.first + first, plan.first + stop)
    body = grid_points(case, planes)
    keep = kept(case, body, plan.removal_bounds)
    if not keep.any():
        raise InputError(
            f"lattice storage under MPI: the grid's planes {first} to {stop - 1} across x hold no "
            "point: use fewer ranks, or discretization.storage: bonds"
        )
    body = body.subset(np.flatnonzero(keep))
    if plan.n_layers is not None and int(body.layer_index.max()) + 1 != plan.n_layers:
        raise InputError(
            f"lattice storage under MPI: the grid's planes {first} to {stop - 1} across x hold no "
            "point of the plate's top layer: use fewer ranks, or discretization.storage: bonds"
        )
    start = plan.offset(first)
    return body, np.arange(start, start + body.n_points, dtype=np.int64)
