"""Point generators (boxes, layered plates, 2D rectangles, text meshes) and face/layer sets.

Grids put points at cell centres, ordered lexicographically with the last
axis fastest, which keeps neighbours close in memory for the kernels.
"""

from __future__ import annotations

import os
import resource
import warnings

import numpy as np

from peridyn.discretization.body import Body
from peridyn.errors import InputError


def _positive_triplet(name: str, value, count: int = 3) -> np.ndarray:
    arr = np.broadcast_to(np.asarray(value, dtype=float), (count,)).copy()
    if not np.all(np.isfinite(arr)) or np.any(arr <= 0):
        raise InputError(f"{name} must be positive and finite, got {np.asarray(value).tolist()}")
    return arr


#: Relative change of a side, from rounding it to whole cells, above which a warning says so.
ROUNDING_WARNING = 1e-4


def cell_counts(lengths: np.ndarray, spacing: np.ndarray, warn: bool = True) -> np.ndarray:
    """Whole cells along each side (the nearest count); warns when a side changes length."""
    with np.errstate(over="ignore", invalid="ignore"):
        ratio = lengths / spacing
    if not np.all(ratio < 2**62):
        raise InputError(f"spacing {spacing.tolist()} m is too small for the body {lengths.tolist()} m")
    counts = np.rint(ratio).astype(np.int64)
    if np.any(counts < 1):
        raise InputError(f"spacing {spacing.tolist()} m is larger than the body {lengths.tolist()} m")
    built = counts * spacing
    changed = np.abs(built - lengths) > ROUNDING_WARNING * lengths
    if warn and np.any(changed):
        sides = ", ".join(
            f"{lengths[a]:g} m -> {built[a]:g} m ({counts[a]} cells)" for a in np.flatnonzero(changed)
        )
        warnings.warn(
            f"the spacing does not divide the body: sides rounded to whole cells: {sides}", stacklevel=3
        )
    return counts


#: Bytes per point a grid builder holds at its peak: the (n, 3) points, the meshgrid copies
#: and the stacked result (float64), the volumes, the (n, 3) cells of the Body, layer indices.
GRID_BYTES_PER_POINT = 128


def memory_limit() -> float:
    """Bytes this process may use: the physical memory, or less under an address-space limit
    (``ulimit -v``); infinite where the system says neither."""
    try:
        physical = float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):
        physical = float("inf")
    soft = resource.getrlimit(resource.RLIMIT_AS)[0]
    return min(physical, float(soft)) if soft != resource.RLIM_INFINITY else physical


def check_grid_fits(n_points: float, what: str) -> None:
    """Refuse, before allocating, a grid whose arrays would not fit in memory.

    Raises
    ------
    InputError
        Naming the number of points and the bytes needed against those available.
    """
    needed = GRID_BYTES_PER_POINT * float(n_points)
    available = memory_limit()
    if needed > available:
        raise InputError(
            f"{what} of {float(n_points):.3g} points would need {needed / 2**30:.3g} GiB for its "
            f"arrays alone; this machine has {available / 2**30:.3g} GiB: use a coarser spacing"
        )


def _grid(counts, spacing, origin, planes=None) -> np.ndarray:
    """The cell centres of a grid of ``counts`` cells, x slowest; with ``planes`` = (first,
    stop), only the planes across x ``first .. stop - 1``, with the values the whole grid has."""
    ranges = [(0, int(n)) for n in counts]
    if planes is not None:
        ranges[0] = planes
    axes = [origin[a] + (np.arange(*ranges[a]) + 0.5) * spacing[a] for a in range(len(counts))]
    mesh = np.meshgrid(*axes, indexing="ij")
    return np.stack([m.ravel() for m in mesh], axis=1)


def planes_of(counts, planes) -> tuple[int, int]:
    """(first, stop): the planes across x of a grid of ``counts`` cells that a generator makes,
    all of them (``planes`` None) or ``planes`` = (first, stop) (a rank's slab of the grid)."""
    n = int(counts[0])
    first, stop = (0, n) if planes is None else (int(planes[0]), int(planes[1]))
    if not 0 <= first < stop <= n:
        raise InputError(f"planes {first} to {stop - 1} across x: the grid has planes 0 to {n - 1}")
    return first, stop


def box(lengths, spacing, origin=(0.0, 0.0, 0.0), planes=None) -> Body:
    """A 3D box of cubic (or box) cells.

    Parameters
    ----------
    lengths : 3 floats, m
        Edge lengths along x, y, z; rounded to a whole number of cells.
    spacing : float or 3 floats, m
        Cell size per axis.
    origin : 3 floats, m
        Lower corner of the box.
    planes : (first, stop) or None
        Make only the planes of cells across x ``first .. stop - 1`` (``planes_of``).
    """
    h = _positive_triplet("spacing", spacing)
    lengths = _positive_triplet("lengths", lengths)
    counts = cell_counts(lengths, h)
    first, stop = planes_of(counts, planes)
    check_grid_fits(np.prod(counts[1:].astype(float)) * (stop - first), "a box")
    points = _grid(counts, h, np.asarray(origin, dtype=float), (first, stop))
    return Body(points=points, volumes=np.full(len(points), h.prod()), cells=h, dim=3, spacing=float(h.max()))


def plate(
    length,
    width,
    thickness,
    spacing,
    layers,
    origin=(0.0, 0.0, 0.0),
    layer_placement: str = "cell",
    planes=None,
) -> Body:
    """A 3D plate in the x-y plane with ``layers`` layers of points through its thickness.

    Parameters
    ----------
    length, width, thickness : float, m
        Plate size along x, y and z; the plate spans z in [origin_z, origin_z + thickness].
    spacing : float, m
        In-plane spacing (x and y).
    layers : int
        Number of point layers through the thickness (>= 1).
    layer_placement : {"cell", "surface"}
        ``"cell"``: layers at the centres of ``layers`` equal slabs (dz = t / layers),
        volumes add up to the plate volume. ``"surface"``: the first and last layers
        lie on the faces (dz = t / (layers - 1)) and every point has volume
        dx dy dz, as in Patra et al. 2018 (3 layers 1 mm apart in a 2 mm plate).
    planes : (first, stop) or None
        Make only the planes of cells across x ``first .. stop - 1`` (``planes_of``).

    Notes
    -----
    ``layer_index`` holds each point's layer (0 = bottom, ``layers - 1`` = top).

    Examples
    --------
    The demo plate: 60 x 40 mm at 0.5 mm, four layers through 2 mm; the cells fill the plate.

    >>> body = plate(0.06, 0.04, 0.002, spacing=0.5e-3, layers=4)
    >>> body.n_points, sorted(set(body.layer_index.tolist()))
    (38400, [0, 1, 2, 3])
    >>> round(float(body.volumes.sum()) * 1e9, 6)  # mm^3
    4800.0
    """
    if int(layers) != layers or layers < 1:
        raise InputError(f"layers must be a positive integer, got {layers!r}")
    layers = int(layers)
    h = float(_positive_triplet("spacing", spacing, 1)[0])
    length, width, thickness = _positive_triplet("plate size", (length, width, thickness))
    counts_xy = cell_counts(np.array([length, width]), np.array([h, h]))
    first, stop = planes_of(counts_xy, planes)
    check_grid_fits(float(counts_xy[1]) * (stop - first) * layers, "a plate")
    if layer_placement == "cell":
        dz = thickness / layers
        z = (np.arange(layers) + 0.5) * dz
    elif layer_placement == "surface":
        if layers < 2:
            raise InputError("layer_placement 'surface' needs at least 2 layers")
        dz = thickness / (layers - 1)
        z = np.arange(layers) * dz
    else:
        raise InputError(f"layer_placement must be 'cell' or 'surface', got {layer_placement!r}")
    xy = _grid(counts_xy, np.array([h, h]), np.asarray(origin[:2], dtype=float), (first, stop))
    n_xy = len(xy)
    points = np.empty((n_xy * layers, 3))
    points[:, :2] = np.repeat(xy, layers, axis=0)
    points[:, 2] = origin[2] + np.tile(z, n_xy)
    layer_index = np.tile(np.arange(layers, dtype=np.int8 if layers <= 127 else np.int64), n_xy)
    cell = np.array([h, h, dz])
    return Body(
        points=points,
        volumes=np.full(len(points), cell.prod()),
        cells=cell,
        dim=3,
        spacing=h,
        layer_index=layer_index,
    )


def rectangle(
    length, width, spacing, thickness, plane: str = "stress", origin=(0.0, 0.0), planes=None
) -> Body:
    """A 2D rectangle (plane stress or plane strain) of square cells.

    Parameters
    ----------
    length, width : float, m
        Size along x and y.
    spacing : float, m
        Cell size.
    thickness : float, m
        Out-of-plane thickness (volumes are cell area times thickness).
    plane : {"stress", "strain"}
    planes : (first, stop) or None
        Make only the planes of cells across x ``first .. stop - 1`` (``planes_of``).
    """
    h = float(_positive_triplet("spacing", spacing, 1)[0])
    t = float(_positive_triplet("thickness", thickness, 1)[0])
    counts = cell_counts(_positive_triplet("rectangle size", (length, width), 2), np.array([h, h]))
    first, stop = planes_of(counts, planes)
    check_grid_fits(float(counts[1]) * (stop - first), "a rectangle")
    xy = _grid(counts, np.array([h, h]), np.asarray(origin, dtype=float), (first, stop))
    points = np.zeros((len(xy), 3))
    points[:, :2] = xy
    return Body(
        points=points,
        volumes=np.full(len(points), h * h * t),
        cells=np.array([h, h, t]),
        dim=2,
        spacing=h,
        thickness=t,
        plane=plane,
    )


def face(body: Body, which: str, depth: float | None = None, bounds=None) -> np.ndarray:
    """Mask of the points within ``depth`` (default: half a cell) of a bounding-box face.

    Parameters
    ----------
    which : {"x-", "x+", "y-", "y+", "z-", "z+"}
    depth : float, m
        Thickness of the selected slab, measured from the outermost points.
    bounds : (2, 3) float64 or None, m
        The lowest and highest coordinates of the whole body of which ``body`` is a part (a
        rank's slab); None: ``body``'s own.
    """
    if which not in {"x-", "x+", "y-", "y+", "z-", "z+"}:
        raise InputError(f"face must be one of x-, x+, y-, y+, z-, z+, got {which!r}")
    axis = "xyz".index(which[0])
    coord = body.points[:, axis]
    tol = 0.5 * float(np.min(body.cells[:, axis])) if depth is None else depth
    low, high = (coord.min(), coord.max()) if bounds is None else (bounds[0][axis], bounds[1][axis])
    if which[1] == "-":
        return coord <= low + tol
    return coord >= high - tol


def layer(body: Body, index: int) -> np.ndarray:
    """Mask of the points of through-thickness layer ``index`` of a plate (negative counts from the top)."""
    if body.layer_index is None:
        raise InputError("this body has no layers (only plates made by geometry.plate do)")
    n_layers = int(body.layer_index.max()) + 1
    if not -n_layers <= index < n_layers:
        raise InputError(f"layer {index} out of range for a plate with {n_layers} layers")
    return body.layer_index == (index % n_layers)
