"""Bond families in CSR form: search, influence functions, partial volumes, pre-cracks.

Every bond is stored twice, once in each end point's family (directed bonds),
so that a kernel looping over points needs no atomics. Point ``i``'s family
is ``neighbours[offsets[i]:offsets[i + 1]]``, sorted by index (on a rank's part of a body under
MPI, by the neighbours' global index: ``peridyn.parallel``).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import NamedTuple

import numpy as np
from scipy.spatial import cKDTree

from peridyn.discretization.body import Body
from peridyn.errors import InputError, did_you_mean
from peridyn.kernels.bond_search import bond_families, bond_geometry, box_fraction_in_ball
from peridyn.kernels.bond_search import family_sums as kernel_family_sums

#: Relative tolerance on the horizon: a neighbour at exactly ``delta`` is in.
HORIZON_RTOL = 1e-12


def _constant(r, delta):
    return np.ones_like(r)


def _inverse(r, delta):
    return delta / r


def _gaussian(r, delta):
    return np.exp(-(r**2) / delta**2)


def _conical(r, delta):
    return np.clip(1.0 - r / delta, 0.0, None)


#: Influence functions omega(|xi|, delta), dimensionless, normalised to 1 at |xi| = 0
#: (``inverse``: delta / |xi|, so it equals 1 at the horizon).
INFLUENCE_FUNCTIONS = {
    "constant": _constant,
    "inverse": _inverse,
    "gaussian": _gaussian,
    "conical": _conical,
}


def influence_function(name: str):
    """The influence function ``omega(r, delta)`` called ``name``."""
    if name not in INFLUENCE_FUNCTIONS:
        raise InputError(
            f"unknown influence function {name!r}{did_you_mean(name, INFLUENCE_FUNCTIONS)}; "
            f"choose one of {sorted(INFLUENCE_FUNCTIONS)}"
        )
    return INFLUENCE_FUNCTIONS[name]


@dataclass(frozen=True, eq=False)
class Bonds:
    """Directed bonds of a body in CSR layout.

    Attributes
    ----------
    offsets : (n_points + 1,) int64
    neighbours : (n_bonds,) int32
    length : (n_bonds,) float64, m
        Reference bond length ``|xi|``.
    influence : (n_bonds,) float64
        Influence function value ``omega(|xi|)``.
    volume_factor : (n_bonds,) float64
        Fraction of the neighbour's cell inside the horizon (1 without partial volumes).
    intact : (n_bonds,) bool
        False for bonds cut by a pre-crack or broken during a run.
    horizon : float, m
        The horizon; with ``point_horizon``, the largest of them.
    influence_name : str
    point_horizon : (n_points,) float64 or None, m
        Each point's own horizon in a body whose blocks have different horizons
        (docs/blocks.md): a bond joins i and j within the smaller of their horizons, which its
        influence function and partial volume use. None: every point's is ``horizon``.
    global_rows : (n_points,) int64 or None
        An MPI rank's part: each row's index in the whole body. None: the rows are the body's.
    row_blocks : (n_blocks + 1,) int64 or None
        An MPI rank's part: the whole body's row blocks (``discretization.pairs``, in whole-body
        rows), which fix the order of the PMB force's sums. None: from these bonds.
    """

    offsets: np.ndarray
    neighbours: np.ndarray
    length: np.ndarray
    influence: np.ndarray
    volume_factor: np.ndarray
    intact: np.ndarray
    horizon: float
    influence_name: str
    point_horizon: np.ndarray | None = None
    global_rows: np.ndarray | None = None
    row_blocks: np.ndarray | None = None

    def horizons(self):
        """Each point's horizon (m): ``point_horizon``, or the float ``horizon`` shared by all."""
        return self.horizon if self.point_horizon is None else self.point_horizon

    @property
    def n_bonds(self) -> int:
        """Number of directed bonds (twice the number of bonds)."""
        return len(self.neighbours)

    def owned_bond_counts(self, n_owned: int) -> tuple[int, int]:
        """(directed bonds, broken ones) of the points ``0 .. n_owned - 1`` (a rank's owned
        points come first, their families first in the bond arrays)."""
        owned = int(self.offsets[n_owned])
        return owned, int(np.count_nonzero(~self.intact[:owned]))

    def owners(self) -> np.ndarray:
        """(n_bonds,) int64: the point whose family holds each directed bond."""
        return np.repeat(np.arange(len(self.offsets) - 1), np.diff(self.offsets))

    def family_sum(self, values: np.ndarray) -> np.ndarray:
        """(n_points,) sum of a per-bond quantity over each point's family (0 for an empty one)."""
        return family_sums(self.offsets, values)

    def reverse(self) -> np.ndarray:
        """(n_bonds,) int64: index of the opposite directed bond j->i of each bond i->j."""
        owners = self.owners()
        # the k-th bond in (i, j) order is the reverse of the k-th bond in (j, i) order. Owners
        # ascend in storage order, so a stable sort by neighbour gives the (j, i) order (one
        # sort key instead of a lexsort of two). Families are usually sorted by neighbour (then
        # the (i, j) order is the storage order), but a rank's part (``peridyn.parallel``)
        # keeps the global order of its ghosts' indices
        by_neighbour = np.argsort(self.neighbours, kind="stable")
        same = owners[1:] == owners[:-1]
        if np.all(self.neighbours[1:][same] >= self.neighbours[:-1][same]):
            return by_neighbour
        by_owner = np.lexsort((self.neighbours, owners))
        rev = np.empty(self.n_bonds, dtype=np.int64)
        rev[by_owner] = by_neighbour
        return rev

    def __repr__(self) -> str:
        n = len(self.offsets) - 1
        return (
            f"Bonds(n_points={n}, n_bonds={self.n_bonds}, horizon={self.horizon:g} m, "
            f"influence={self.influence_name!r}, broken={int((~self.intact).sum())})"
        )


def horizon_metres(horizon_m: float | None, horizon_factor: float | None, spacing: float) -> float:
    """The horizon (m): ``horizon_m`` when given, else ``horizon_factor`` times ``spacing`` (m).

    The one rule of the package (case files' ``horizon`` and ``horizon_m``, blocks, estimates,
    Bloch analysis, the Python API); whether exactly one was given is the caller's check.
    """
    return horizon_m if horizon_m is not None else horizon_factor * spacing


def find_bonds(
    body: Body,
    horizon: float,
    influence: str = "constant",
    partial_volumes: bool = True,
    quadrature_points: int = 8,
    required=None,
    box=None,
    point_horizon=None,
) -> Bonds:
    """Search the families of all points and build the CSR bond arrays.

    Parameters
    ----------
    body : Body
    horizon : float, m
        Bonds with ``|xi| <= horizon (1 + 1e-12)`` are kept; with partial volumes,
        every neighbour whose cell reaches into the horizon sphere is kept.
    influence : str
        Name of the influence function (see ``INFLUENCE_FUNCTIONS``).
    partial_volumes : bool
        Weigh each neighbour by the fraction of its cell inside the horizon
        sphere (computed by midpoint quadrature with ``quadrature_points`` per
        axis). On lattices with horizons of 2-3 spacings this is what makes the
        discrete long-wave speeds match the continuum (docs/reference-cases.md).
    required : (k,) int or None
        The points that must have a neighbour (default: every point). A rank's part of a
        body (``peridyn.parallel``) requires it of its owned points only: an outer ghost may
        see none of its neighbours.
    box : (3,) float or None, m
        Half-widths of a box neighbourhood instead of the sphere: the neighbours are the points
        with ``|x_j - x_i| <= box`` along every axis (Peridigm's PdQuickGrid families); no partial
        volumes, one horizon. The influence function still takes ``horizon``.
    point_horizon : (n_points,) float or None, m
        Each point's horizon (blocks of different horizons, docs/blocks.md); ``horizon`` must
        then be their largest. A bond i-j is kept, weighed and given its partial volume
        within min(point_horizon_i, point_horizon_j).

    Raises
    ------
    InputError
        When a required point has no neighbour (the horizon is smaller than the spacing; an
        empty ``required``: none must have one).
    """
    omega = influence_function(influence)
    x = body.points
    must_have = required is None or len(required) > 0  # some point must have a neighbour
    if must_have and horizon < 0.5 * float(np.min(body.cells[:, : body.dim])):
        raise InputError(
            f"horizon {horizon:g} m is smaller than half the spacing "
            f"{np.min(body.cells[:, : body.dim]):g} m: points would have no neighbours"
        )
    cells = search_cells(body)
    reach = search_reach(body, horizon, partial_volumes)
    if box is not None:
        if partial_volumes:
            raise InputError("a box neighbourhood has no partial volumes: set partial_volumes false")
        if point_horizon is not None:
            raise InputError("a box neighbourhood takes one horizon, not one per point")
        box = np.asarray(box, dtype=float) * (1 + HORIZON_RTOL)
        reach = float(np.linalg.norm(box))
    pairs = cKDTree(x).query_pairs(reach, output_type="ndarray")
    if box is not None:
        pairs = pairs[np.all(np.abs(x[pairs[:, 1]] - x[pairs[:, 0]]) <= box, axis=1)]
    offsets, j = bond_families(pairs, body.n_points)
    if point_horizon is None:
        radius = horizon * (1 + HORIZON_RTOL) if box is None else reach
        length, factor = bond_geometry(x, cells, offsets, j, radius, partial_volumes, quadrature_points)
    else:
        point_horizon = np.asarray(point_horizon, dtype=np.float64)
        if point_horizon.shape != (body.n_points,) or not horizon == np.max(point_horizon):
            raise InputError(
                f"point_horizon: one horizon per point ({body.n_points},), the largest equal to the "
                f"horizon {horizon:g} m; got shape {point_horizon.shape}"
            )
        bond_horizon = np.minimum(np.repeat(point_horizon, np.diff(offsets)), point_horizon[j])
        factor = np.zeros(len(j))
        for radius in np.unique(point_horizon):  # the kernel takes one radius: once per horizon
            length, within = bond_geometry(
                x, cells, offsets, j, radius * (1 + HORIZON_RTOL), partial_volumes, quadrature_points
            )
            factor = np.where(bond_horizon == radius, within, factor)
    # drop neighbours whose cell lies wholly outside the sphere (of the bond's horizon)
    if partial_volumes or point_horizon is not None:
        keep = factor > 0
        counts = family_sums(offsets, keep).astype(np.int64)
        offsets = np.concatenate([[0], np.cumsum(counts)])
        j, length, factor = j[keep], length[keep], factor[keep]
        if point_horizon is not None:
            bond_horizon = bond_horizon[keep]
    counts = np.diff(offsets)
    if required is not None:
        counts = counts[np.asarray(required, dtype=np.int64)]
    if np.any(counts == 0):
        lonely = int(np.flatnonzero(counts == 0)[0])
        lonely = lonely if required is None else int(np.asarray(required)[lonely])
        raise InputError(
            f"point {lonely} at {x[lonely].tolist()} has no neighbour within the horizon "
            f"{horizon:g} m (spacing {body.spacing:g} m): increase the horizon"
        )
    return Bonds(
        offsets=offsets,
        neighbours=j,
        length=length,
        influence=omega(length, horizon if point_horizon is None else bond_horizon),
        volume_factor=factor,
        intact=np.ones(len(j), dtype=bool),
        horizon=float(horizon),
        influence_name=influence,
        point_horizon=point_horizon,
    )


def search_cells(body: Body) -> np.ndarray:
    """(n_points, 3) cell sides of the partial-volume test, m (2D cells: rectangles, third side 0)."""
    cells = body.cells.copy()
    if body.dim == 2:
        cells[:, 2] = 0.0
    return cells


def search_reach(body: Body, horizon: float, partial_volumes: bool = True) -> float:
    """Distance (m) within which ``find_bonds`` looks for neighbours: the horizon (with its
    tolerance), plus half the largest cell diagonal with partial volumes."""
    reach = horizon * (1 + HORIZON_RTOL)
    if partial_volumes:
        reach += 0.5 * float(np.max(np.linalg.norm(search_cells(body), axis=1)))
    return reach


def reorder_bonds(bonds: Bonds, order: np.ndarray, n_points: int) -> Bonds:
    """The bonds of the points ``order`` (old indices, in their new order), neighbours renumbered.

    Each family keeps its bonds in their order. Every neighbour of a kept point must be kept;
    ``n_points`` is the old number of points.
    """
    order = np.asarray(order, dtype=np.int64)
    new_index = np.full(n_points, -1, dtype=np.int64)
    new_index[order] = np.arange(len(order))
    counts = np.diff(bonds.offsets)[order]
    offsets = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
    rows = np.repeat(bonds.offsets[order] - offsets[:-1], counts) + np.arange(offsets[-1])
    neighbours = new_index[bonds.neighbours[rows]]
    if np.any(neighbours < 0):
        raise InputError("reorder_bonds: a kept point has a neighbour that is not kept")
    return Bonds(
        offsets=offsets,
        neighbours=neighbours.astype(np.int32),
        length=bonds.length[rows],
        influence=bonds.influence[rows],
        volume_factor=bonds.volume_factor[rows],
        intact=bonds.intact[rows],
        horizon=bonds.horizon,
        influence_name=bonds.influence_name,
        point_horizon=None if bonds.point_horizon is None else bonds.point_horizon[order],
    )


class FusedPlan(NamedTuple):
    """Row order of ``kernels.lps.lps_force_fused`` (int64 arrays), made by :func:`fused_plan`.

    parts : (n_parts, 4)
        First row, end row, first block, end block of each part (one a thread).
    inner : (n_parts, 2)
        The part's inner rows [inner[t, 0], inner[t, 1]): the rows that no row of another
        part reads (a row's force reads the dilatation of its neighbours and its own).
    blocks : (n_blocks + 1,)
        Row bounds of the blocks; every part bound is one.
    need : (n_blocks,)
        1 + the largest row whose dilatation a block's forces read.
    """

    parts: np.ndarray
    inner: np.ndarray
    blocks: np.ndarray
    need: np.ndarray


def fused_plan(offsets: np.ndarray, neighbours: np.ndarray, n_parts: int, block_rows: int) -> FusedPlan:
    """The :class:`FusedPlan` of the families ``offsets``, ``neighbours`` for ``n_parts`` parts of
    about equal bonds, in blocks of ``block_rows`` rows. A neighbour at row ``n = len(offsets) -
    1`` or after is a row outside the plan whose dilatation is known before the fused kernel
    runs (an MPI rank's rows next to its ghosts): it orders nothing."""
    n = len(offsets) - 1
    lowest = np.minimum(np.arange(n, dtype=np.int64), _family_extreme(np.minimum, offsets, neighbours, n))
    inside = np.where(neighbours < n, neighbours, -1)  # a row past the plan orders nothing
    need_row = np.maximum(
        np.arange(1, n + 1, dtype=np.int64), _family_extreme(np.maximum, offsets, inside, -1) + 1
    )
    reach_up = np.maximum.accumulate(need_row)  # 1 + the largest row read by rows 0 .. r
    reach_down = np.minimum.accumulate(lowest[::-1])[::-1]  # the smallest row read by rows r ..
    bounds = np.searchsorted(offsets, np.linspace(0, offsets[-1], n_parts + 1)).astype(np.int64)
    bounds[0], bounds[-1] = 0, n
    parts = np.empty((n_parts, 4), np.int64)
    inner = np.empty((n_parts, 2), np.int64)
    blocks = [0]
    for t in range(n_parts):
        lo, hi = bounds[t], bounds[t + 1]
        inner_lo = lo if lo == 0 else min(max(reach_up[lo - 1], lo), hi)
        inner_hi = hi if hi == n else min(max(reach_down[hi], inner_lo), hi)
        inner[t] = inner_lo, inner_hi
        parts[t] = lo, hi, len(blocks) - 1, 0
        blocks.extend(range(lo + block_rows, hi, block_rows))
        if hi > lo:
            blocks.append(hi)
        parts[t, 3] = len(blocks) - 1
    blocks = np.array(blocks, np.int64)
    need = np.maximum.reduceat(need_row, blocks[:-1]) if n else np.zeros(0, np.int64)
    return FusedPlan(parts, inner, blocks, need)


def _family_extreme(ufunc, offsets: np.ndarray, values: np.ndarray, empty: int) -> np.ndarray:
    """(n_points,) int64: ``ufunc.reduce`` (np.minimum or np.maximum) of ``values`` over each
    family of ``offsets``; ``empty`` for a family without bonds."""
    n = len(offsets) - 1
    sizes = np.diff(offsets)
    out = np.full(n, empty, dtype=np.int64)
    full = sizes > 0
    if full.any():
        out[full] = ufunc.reduceat(values.astype(np.int64), offsets[:-1][full])
    return out


def fused_ring_columns(offsets: np.ndarray, plan: FusedPlan) -> int:
    """Columns (bonds) of each part's ring in ``kernels.lps.lps_force_fused``: the most bonds of
    inner rows whose dilatation is done and force not yet, at any block, plus two families.

    Families are written one after the other and start again at column 0 when the next would
    not fit before the end (``kernels.lps.ring_slot``), so the live ones span at most their
    bonds plus one gap shorter than a family: less than the ring, which is thus never
    overwritten before it is read. The smallest such ring keeps the least data in the cache.
    """
    widest = 0
    for t, (lo, hi) in enumerate(plan.inner):
        done = lo
        for k in range(plan.parts[t, 2], plan.parts[t, 3]):
            done = max(done, min(plan.need[k], hi))
            first = min(max(plan.blocks[k], lo), hi)
            widest = max(widest, offsets[max(done, first)] - offsets[first])
    return int(widest + 2 * np.diff(offsets).max(initial=0))


def cell_fraction_in_ball(
    xi: np.ndarray, cell: np.ndarray, radius: float, quadrature_points: int = 8
) -> np.ndarray:
    """Fraction of each box cell (centre ``xi``, sides ``cell``) inside a ball at the origin.

    Parameters
    ----------
    xi : (n, 3) float64, m
        Cell centres relative to the ball centre.
    cell : (n, 3) float64, m
        Cell sides (a zero third side makes the cell a rectangle, for 2D).
    radius : float, m
    quadrature_points : int
        Samples per axis across the two transverse axes (exact along x).

    Returns
    -------
    (n,) float64 in [0, 1]
    """
    return np.array(
        [box_fraction_in_ball(*xi[k], *cell[k], radius, quadrature_points) for k in range(len(xi))]
    )


# -- pre-cracks ---------------------------------------------------------------------------


def crossing_rectangle(x_from: np.ndarray, x_to: np.ndarray, origin, edge_u, edge_v) -> np.ndarray:
    """Mask of segments ``x_from -> x_to`` that cross the planar rectangle.

    The rectangle is ``origin + a edge_u + b edge_v`` with a, b in [0, 1] (m).
    A segment touching the plane only at an end point does not cross it.

    Parameters
    ----------
    x_from, x_to : (n, 3) float64, m
    """
    o = np.asarray(origin, float)
    eu = np.asarray(edge_u, float)
    ev = np.asarray(edge_v, float)
    normal = np.cross(eu, ev)
    if np.linalg.norm(normal) == 0:
        raise InputError("pre-crack rectangle edges must not be parallel or zero")
    d0 = (x_from - o) @ normal
    d1 = (x_to - o) @ normal
    crosses = d0 * d1 < 0
    t = np.where(crosses, d0 / np.where(crosses, d0 - d1, 1.0), 0.0)
    hit = x_from + t[:, None] * (x_to - x_from) - o
    # coordinates of the hit point in the (eu, ev) basis
    gram = np.array([[eu @ eu, eu @ ev], [eu @ ev, ev @ ev]])
    ab = np.linalg.solve(gram, np.stack([hit @ eu, hit @ ev]))
    return crosses & (ab[0] >= 0) & (ab[0] <= 1) & (ab[1] >= 0) & (ab[1] <= 1)


def crossing_segment(x_from: np.ndarray, x_to: np.ndarray, start, end) -> np.ndarray:
    """Mask of in-plane segments ``x_from -> x_to`` that cross the 2D segment ``start-end``.

    Parameters
    ----------
    x_from, x_to : (n, 3) float64, m (only x and y are used)
    start, end : 2 floats, m
    """
    p = np.asarray(start, float)[:2]
    q = np.asarray(end, float)[:2]
    a, b = x_from[:, :2], x_to[:, :2]

    def side(o, u, w):
        return (u[..., 0] - o[..., 0]) * (w[..., 1] - o[..., 1]) - (u[..., 1] - o[..., 1]) * (
            w[..., 0] - o[..., 0]
        )

    s1 = side(p, q, a)
    s2 = side(p, q, b)
    s3 = side(a, b, p)
    s4 = side(a, b, q)
    return (s1 * s2 < 0) & (s3 * s4 < 0)


def listed_pairs(pairs, tolerance: float):
    """``crossing(x_from, x_to)`` of the bonds listed in ``pairs``: True where ``x_from`` and
    ``x_to`` lie within ``tolerance`` (m) of the two ends of a listed pair, in either order: in
    the x-y plane for pairs of in-plane ends (in a plate: the bonds between two columns of
    points, at every pair of layers), in space for pairs of 3D ends (the bonds between two
    points).

    Parameters
    ----------
    pairs : (k, 4) or (k, 6) float64, m, each bond's ends (x_a, y_a, x_b, y_b) or (x_a, y_a,
        z_a, x_b, y_b, z_b)
    tolerance : float, m, less than half the distance between two listed ends
    """
    pairs = np.asarray(pairs, dtype=float)
    dim = pairs.shape[1] // 2
    ends = np.concatenate([pairs[:, :dim], pairs[:, dim:]])
    tree = cKDTree(ends)
    # each listed end is known by the first listed end within the tolerance
    first = np.array([min(group) for group in tree.query_ball_point(ends, tolerance)], dtype=np.int64)
    k = len(pairs)
    a, b = first[:k], first[k:]
    keys = np.unique(np.minimum(a, b) * len(ends) + np.maximum(a, b))

    def crossing(x_from: np.ndarray, x_to: np.ndarray) -> np.ndarray:
        ia, ib = (_listed_end(tree, first, x[:, :dim], tolerance) for x in (x_from, x_to))
        key = np.minimum(ia, ib) * len(ends) + np.maximum(ia, ib)
        return (ia >= 0) & (ib >= 0) & np.isin(key, keys)

    return crossing


def _listed_end(tree: cKDTree, first: np.ndarray, xy: np.ndarray, tolerance: float) -> np.ndarray:
    """(n,) int64: the listed end (its first index) within ``tolerance`` of each of ``xy`` ((n, 2)
    or (n, 3), m, as the ends), -1 for none."""
    d, i = tree.query(xy, distance_upper_bound=tolerance)
    found = np.isfinite(d)
    return np.where(found, first[np.where(found, i, 0)], -1)


def _dot3(rows: np.ndarray, vector: np.ndarray) -> np.ndarray:
    """(n,) ``rows . vector`` of (n, 3) rows, summed x + y then + z, each product and sum rounded
    once (as Peridigm's bond filters write them; a matrix product may fuse or reorder them)."""
    return (rows[:, 0] * vector[0] + rows[:, 1] * vector[1]) + rows[:, 2] * vector[2]


def crossing_finite_plane(
    x_from: np.ndarray,
    x_to: np.ndarray,
    corner,
    normal,
    bottom,
    bottom_length: float,
    side_length: float,
    tolerance: float = 1e-15,
) -> np.ndarray:
    """Mask of segments ``x_from -> x_to`` ((n, 3), m) that meet a finite plane as Peridigm's
    "Rectangular_Plane" bond filter finds them (its ``PdBondFilter::FinitePlane``): the line
    meets the plane through ``corner`` of ``normal`` at t in [0, 1] (a segment touching it at
    an end counts; one parallel to it, |(x_to - x_from) . n| < 1e-14, does not), at a point
    whose coordinates a = (x - corner) . (bottom x normal) and b = (x - corner) . bottom
    satisfy -tol < a < (1 + tol) ``side_length`` and -tol < b < (1 + tol) ``bottom_length``
    (Peridigm's tolerance, 1e-15). ``normal`` and ``bottom`` are taken as given (Peridigm does
    not normalise them). Every quantity is rounded as Peridigm's ``FinitePlane`` rounds it, so a
    bond that meets an edge exactly (decided by the last bits of its points' coordinates) is
    decided as there."""
    r0, n, ub = (np.asarray(v, float) for v in (corner, normal, bottom))
    ua = np.cross(ub, n)
    numerator = _dot3(r0 - x_from, n)
    denominator = _dot3(x_to - x_from, n)
    parallel = np.abs(denominator) < 1e-14
    t = np.where(parallel, np.inf, numerator / np.where(parallel, 1.0, denominator))
    meets = (t >= 0.0) & (t <= 1.0)
    hit = (x_from + np.where(meets, t, 0.0)[:, None] * (x_to - x_from)) - r0
    a, b = _dot3(hit, ua), _dot3(hit, ub)
    inside = (-tolerance < a) & (a / side_length < 1 + tolerance)
    inside &= (-tolerance < b) & (b / bottom_length < 1 + tolerance)
    return meets & inside


def crossing_triangles(x_from: np.ndarray, x_to: np.ndarray, triangles: np.ndarray, tolerance: float = 1e-15):
    """Mask of segments ``x_from -> x_to`` ((n, 3), m) that meet any of ``triangles`` ((m, 3, 3),
    m: the corners v1, v2, v3 of each), as Peridigm's triangle bond filter finds them: the line
    meets the triangle's plane at t in [0, 1] (not when parallel to it, |(x_to - x_from) . n| <
    1e-14 |n|), at a point of barycentric coordinates alpha (along v3 - v1), beta (along
    v2 - v1) with alpha > -tol, beta > -tol and alpha + beta < 1 + 2 tol."""
    out = np.zeros(len(x_from), dtype=bool)
    low, high = np.minimum(x_from, x_to), np.maximum(x_from, x_to)
    for v1, v2, v3 in np.asarray(triangles, dtype=float):
        near = np.all(
            (low <= np.maximum(np.maximum(v1, v2), v3)) & (high >= np.minimum(np.minimum(v1, v2), v3)), axis=1
        )
        idx = np.flatnonzero(near & ~out)
        if len(idx) == 0:
            continue
        p0, p1 = x_from[idx], x_to[idx]
        a, b = v3 - v1, v2 - v1
        n = np.cross(b, a)
        denominator = (p1 - p0) @ n
        parallel = np.abs(denominator) < 1e-14 * np.linalg.norm(n)
        t = ((v1 - p0) @ n) / np.where(parallel, 1.0, denominator)
        c = p0 + t[:, None] * (p1 - p0) - v1
        d00, d01, d11 = a @ a, a @ b, b @ b
        d02, d12 = c @ a, c @ b
        det = d00 * d11 - d01 * d01
        alpha = (d11 * d02 - d01 * d12) / det
        beta = (d00 * d12 - d01 * d02) / det
        inside = (alpha > -tolerance) & (beta > -tolerance) & (alpha + beta < 1.0 + 2.0 * tolerance)
        out[idx] = ~parallel & (t >= 0.0) & (t <= 1.0) & inside
    return out


CUT_CHUNK = 1_000_000  # bonds tested at a time: bounds the (chunk, 3) temporaries of ``crossing``


def cut_bonds(body: Body, bonds: Bonds, crossing) -> int:
    """Break (in place) every bond for which ``crossing(x_i, x_j)`` is True; returns the count cut.

    ``crossing`` is e.g. ``lambda a, b: crossing_rectangle(a, b, o, u, v)``; it is called on
    CUT_CHUNK bonds at a time.
    """
    mask = crossing_mask(body, bonds, crossing)
    bonds.intact[mask] = False
    return int(mask.sum())


def crossing_mask(body: Body, bonds: Bonds, crossing) -> np.ndarray:
    """(n_bonds,) bool: ``crossing(x_i, x_j)`` of every bond, on both copies of a bond where
    either has it (``both_copies``), CUT_CHUNK bonds at a time."""
    owners = bonds.owners()
    mask = np.zeros(bonds.n_bonds, dtype=bool)
    for start in range(0, bonds.n_bonds, CUT_CHUNK):
        chunk = slice(start, start + CUT_CHUNK)
        mask[chunk] = crossing(body.points[owners[chunk]], body.points[bonds.neighbours[chunk]])
    return both_copies(mask, bonds.reverse())


def without_bonds(bonds: Bonds, mask: np.ndarray) -> Bonds:
    """``bonds`` less the directed bonds of ``mask`` ((n_bonds,) bool, both copies of a bond
    set): they leave the families, as Peridigm's bond filters take them out of its neighbour
    lists (no neighbour, no weighted volume, no damage), where a cut bond stays a broken one."""
    keep = ~np.asarray(mask, dtype=bool)
    counts = np.bincount(bonds.owners()[keep], minlength=len(bonds.offsets) - 1)
    return replace(
        bonds,
        offsets=np.concatenate([[0], np.cumsum(counts)]).astype(bonds.offsets.dtype),
        neighbours=bonds.neighbours[keep],
        length=bonds.length[keep],
        influence=bonds.influence[keep],
        volume_factor=bonds.volume_factor[keep],
        intact=bonds.intact[keep],
    )


def both_copies(mask: np.ndarray, reverse: np.ndarray) -> np.ndarray:
    """(n_bonds,) bool: ``mask`` set on both directed copies of a bond where either has it.

    A crossing test of i->j and of j->i can disagree when the bond ends exactly on a crack's
    edge (round-off); a bond cut in one direction only would make the force and the stiffness
    of LPS differ. ``reverse`` is ``Bonds.reverse()``.
    """
    return mask | mask[reverse]


def family_sums(offsets: np.ndarray, values: np.ndarray) -> np.ndarray:
    """(n_points,) float64 sums of ``values`` (n_bonds,) over the CSR families ``offsets``.

    Unlike ``np.add.reduceat``, an empty family sums to 0. Each family is summed in its bonds'
    order (``kernels.bond_search.family_sums``: the bits of ``np.bincount`` over the owners).
    """
    out = np.empty(len(offsets) - 1)
    offsets = np.asarray(offsets, dtype=np.int64)
    kernel_family_sums(offsets, np.ascontiguousarray(values, dtype=np.float64), out)
    return out
