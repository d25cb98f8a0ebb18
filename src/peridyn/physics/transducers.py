"""Surface-bonded piezoelectric (PZT) patches: actuator models and the sensor signal.

A patch lies in the x-y plane on one surface layer of a plate. ``size`` is the
side of a square patch (edges along x and y) or the diameter of a circular
one; ``a = size / 2`` is its half size. With ``d = (x - x_c, y - y_c)`` the
offset of a point from the patch centre, the *patch radius* of a point is
``rho(d) = max(|d_x|, |d_y|)`` (square) or ``|d|`` (circle), so the patch is
``rho <= a`` and its perimeter ``rho = a``.

Actuators (each returns the body with a new node set and the boundary
conditions to pass to :class:`~peridyn.physics.loads.Loading`):

- :func:`pzt_radial_actuator`, Patra et al. 2018 (sec. 2.2, after its ref. 37): an
  in-plane *radial* displacement prescribed on the patch's points, zero at the
  centre and growing linearly along every ray to ``amplitude`` on the
  perimeter::

      u(d, t) = amplitude * (d / |d|) * (rho(d) / a) * f(t)      (u = 0 at d = 0)

  i.e. ``u = amplitude * d / r_p(d)`` with ``r_p(d) = a |d| / rho(d)`` the
  distance from the centre to the perimeter in the direction of ``d``. For a
  circle this is the uniform expansion ``amplitude * d / a``; for a square,
  points on the edges move by exactly ``amplitude`` and the lines of equal
  ``|u|`` are concentric squares. ``z`` stays free.
- :func:`pin_force_actuator`, the pin-force model (Crawley and de Luis 1987,
  AIAA J. 25:1373; Giurgiutiu 2005, J. Intell. Mater. Syst. Struct. 16:291):
  the shear stress under a thin bonded patch concentrates at its ends, so the
  patch acts on the plate as in-plane line forces of ``line_force`` (N/m)
  along its perimeter, normal to it and pointing outward (an expanding patch).

Sensor: :func:`pzt_sensor_signal` gives what a thin patch measures, the mean
in-plane normal strain sum over its area, by the divergence theorem::

    s(t) = (1/A) integral_A (eps_xx + eps_yy) dA = (1/A) contour_integral u . n ds

The open-circuit voltage of a thin sensor is proportional to ``s`` (Giurgiutiu
2005). The displacement is interpolated linearly (Delaunay triangulation) at
quadrature points on the perimeter, so ``s`` is exact for linear fields and
tends to the area mean for any field as the points get denser.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import Delaunay, cKDTree

from peridyn.discretization import geometry
from peridyn.discretization.body import Body
from peridyn.errors import InputError
from peridyn.physics.loads import BoundaryCondition
from peridyn.physics.timefunctions import TimeFunction

__all__ = [
    "SHAPES",
    "pin_force_actuator",
    "pzt_radial_actuator",
    "pzt_sensor_signal",
    "pzt_sensor_weights",
]

#: Patch shapes.
SHAPES = ("square", "circular")
#: Relative tolerance (of the body spacing) on points lying on the patch perimeter.
_ON_PERIMETER = 1e-6
#: Midpoint-rule nodes per square edge, and on a circle, for the sensor's contour integral.
_NODES_PER_EDGE = 256
_NODES_ON_CIRCLE = 1024
#: Points near the centre used to estimate the sensor's point spacing.
_SPACING_SAMPLE = 32


def pzt_radial_actuator(
    body: Body,
    center,
    size: float,
    function: TimeFunction,
    shape: str = "square",
    layer: int | None = -1,
    amplitude: float = 1e-6,
    name: str = "pzt",
    part: bool = False,
) -> tuple[Body, list[BoundaryCondition]]:
    """Radial in-plane displacement of a PZT patch (Patra et al. 2018), see the module docstring.

    Parameters
    ----------
    body : Body
        A layered plate (``geometry.plate``), or any body with ``layer=None``.
        Build the actuator after removing points (holes): removals re-index
        the node set but not the profile.
    center : 2 or 3 floats, m
        Patch centre; only x and y are used.
    size : float, m
        Side of a square patch or diameter of a circular one.
    function : TimeFunction
        Time history of the displacement, peak about 1 (e.g.
        ``ToneBurst(150e3, 3.5)`` or ``GaussianBurst(150e3, 3.5)``).
    shape : {"square", "circular"}
    layer : int or None
        Layer of the plate the patch is bonded to (-1: top, 0: bottom); None
        takes the points of every layer under the patch (2D bodies).
    amplitude : float, m
        Radial displacement of the perimeter points at ``function = 1``.
    name : str
        Name of the node set holding the patch's points.
    part : bool
        ``body`` is a rank's part of the plate (``peridyn.parallel``), which may hold none of
        the patch's points: the caller checks the whole patch over the ranks.

    Returns
    -------
    body : Body
        ``body`` with the node set ``name``.
    conditions : list of BoundaryCondition
        One ``displacement`` condition on x and y with ``profile``
        (n_set, 2), m: ``u[set, :2] = profile * function(t)``.

    Raises
    ------
    InputError
        Bad shape, size or layer, or no point under the patch.
    """
    mask = _footprint(body, center, size, shape, layer, part)
    body = body.with_node_set(name, mask, empty=part)
    d = _offsets(body.points[body.node_set(name, part)], center)
    profile = amplitude * d * _radius_over_distance(d, shape) / (0.5 * size)
    return body, [BoundaryCondition(name, "displacement", "xy", function, profile)]


def pin_force_actuator(
    body: Body,
    center,
    size: float,
    function: TimeFunction,
    shape: str = "square",
    layer: int | None = -1,
    line_force: float = 1.0,
    name: str = "pin_force",
) -> tuple[Body, list[BoundaryCondition]]:
    """Pin-force model of a PZT patch: outward line forces along its perimeter.

    Square: each edge carries ``line_force * size`` (N) normal to it, shared by
    the outermost points of the patch on that side in proportion to their
    volumes (a corner point takes a share of both edges). Circle: the
    perimeter carries ``line_force * pi * size`` (N) in all, shared by the
    patch's points less than one spacing inside it, each pushed along its radius.

    Parameters
    ----------
    body, center, size, function, shape, layer, name
        As in :func:`pzt_radial_actuator`; ``function`` scales the forces.
    line_force : float, N/m
        Force per unit length of perimeter at ``function = 1``.

    Returns
    -------
    body : Body
        ``body`` with the node set ``name`` (the loaded perimeter points).
    conditions : list of BoundaryCondition
        One ``body_force`` condition on x and y with ``profile`` (n_set, 2),
        N/m^3: the point force divided by the point's volume (a body force
        rather than ``force``, whose total is spread evenly, so that every
        point can carry its own direction).
    """
    mask = _footprint(body, center, size, shape, layer)
    index = np.flatnonzero(mask)
    d = _offsets(body.points[index], center)
    volumes = body.volumes[index]
    if shape == "square":
        forces = _edge_forces(d, volumes, size, line_force, _ON_PERIMETER * body.spacing)
    else:
        forces = _rim_forces(d, volumes, size, line_force, body.spacing)
    loaded = np.any(forces != 0.0, axis=1)
    body = body.with_node_set(name, index[loaded])
    profile = forces[loaded] / volumes[loaded, None]
    return body, [BoundaryCondition(name, "body_force", "xy", function, profile)]


def pzt_sensor_weights(points, center, size: float, shape: str = "square") -> np.ndarray:
    """Weights ``W`` with ``s = sum_i W_i . u_i[:2]``, the sensor signal of a patch.

    Parameters
    ----------
    points : (n_points, 2 or 3) float64, m
        Points of the surface the patch is bonded to (one layer), covering the
        patch and a margin of a few spacings around it.
    center : 2 or 3 floats, m
        Patch centre (x, y).
    size : float, m
        Side (square) or diameter (circular).
    shape : {"square", "circular"}

    Returns
    -------
    (n_points, 2) float64, 1/m
        Zero for points away from the patch.

    Raises
    ------
    InputError
        Bad shape or size, points from several layers under the patch, or a
        perimeter not covered by the points.
    """
    pts = _checked_points(points)
    xy = pts[:, :2]
    _check_patch(size, shape)
    local = _local_points(xy, center, size)
    if pts.shape[1] == 3 and np.ptp(pts[local, 2]) > 0.0:
        raise InputError(
            "pzt sensor: the points around the patch lie on several layers; "
            "pass the points of one surface layer"
        )
    nodes, normals_ds = _perimeter_quadrature(center, size, shape)
    triangulation = Delaunay(xy[local])
    simplex = triangulation.find_simplex(nodes)
    if np.any(simplex < 0):
        raise InputError(
            "pzt sensor: the patch perimeter is not inside the region of the points; "
            "the patch must lie on the plate, away from its edges"
        )
    vertices = triangulation.simplices[simplex]
    barycentric = _barycentric(triangulation, simplex, nodes)
    weights = np.zeros((len(xy), 2))
    area = size**2 if shape == "square" else 0.25 * np.pi * size**2
    contribution = barycentric[:, :, None] * normals_ds[:, None, :] / area
    np.add.at(weights, local[vertices], contribution)
    return weights


def pzt_sensor_signal(points, u, center, size: float, shape: str = "square") -> np.ndarray:
    """Mean in-plane normal strain ``eps_xx + eps_yy`` under a patch (module docstring).

    Parameters
    ----------
    points : (n_points, 2 or 3) float64, m
        Points of one surface layer (see :func:`pzt_sensor_weights`).
    u : (n_points, 2 or 3) or (n_t, n_points, 2 or 3) float, m
        Displacement of those points, one record or a time series.
    center, size, shape
        The patch, as in :func:`pzt_sensor_weights`.

    Returns
    -------
    () or (n_t,) float64
        The signal (strain, dimensionless) of each record.
    """
    u = np.asarray(u, dtype=float)
    n = len(np.asarray(points))
    if u.ndim not in (2, 3) or u.shape[-2] != n or u.shape[-1] < 2:
        raise InputError(f"pzt sensor: u must have shape ({n}, 3) or (n_t, {n}, 3), got {u.shape}")
    weights = pzt_sensor_weights(points, center, size, shape)
    return np.einsum("...pc,pc->...", u[..., :2], weights)


# -- patch geometry -------------------------------------------------------------------


def _check_patch(size: float, shape: str) -> None:
    if shape not in SHAPES:
        raise InputError(f"patch shape must be one of {SHAPES}, got {shape!r}")
    if not (np.isfinite(size) and size > 0):
        raise InputError(f"patch size must be a positive length (m), got {size!r}")


def _offsets(points: np.ndarray, center) -> np.ndarray:
    """(n, 2) in-plane offsets of ``points`` from the patch centre, m."""
    c = np.asarray(center, dtype=float)
    if c.shape not in ((2,), (3,)) or not np.all(np.isfinite(c)):
        raise InputError(f"patch center must be 2 or 3 finite coordinates (m), got {center!r}")
    return points[:, :2] - c[:2]


def _patch_radius(d: np.ndarray, shape: str) -> np.ndarray:
    """``rho(d)``: Chebyshev (square) or Euclidean (circle) length of offsets (n, 2)."""
    return np.max(np.abs(d), axis=1) if shape == "square" else np.hypot(d[:, 0], d[:, 1])


def _radius_over_distance(d: np.ndarray, shape: str) -> np.ndarray:
    """(n, 1) ``rho(d) / |d|``, 0 at the centre."""
    r = np.hypot(d[:, 0], d[:, 1])
    ratio = np.divide(_patch_radius(d, shape), r, out=np.zeros_like(r), where=r > 0)
    return ratio[:, None]


def _footprint(
    body: Body, center, size: float, shape: str, layer: int | None, part: bool = False
) -> np.ndarray:
    """Mask of the points under the patch (perimeter included) on ``layer`` (of a rank's part:
    ``part``, which may hold none)."""
    _check_patch(size, shape)
    on_layer = np.ones(body.n_points, bool) if layer is None else geometry.layer(body, layer)
    rho = _patch_radius(_offsets(body.points, center), shape)
    mask = on_layer & (rho <= 0.5 * size + _ON_PERIMETER * body.spacing)
    if not mask.any() and not part:
        raise InputError(
            f"no point of the body lies under the {shape} patch of size {size} m "
            f"at {list(center)} (layer {layer})"
        )
    return mask


def _edge_forces(d, volumes, size, line_force, tol) -> np.ndarray:
    """(n, 2) N: ``line_force * size`` per square edge, on its outermost points."""
    forces = np.zeros_like(d)
    for axis in (0, 1):
        for sign in (-1.0, 1.0):
            coord = sign * d[:, axis]
            edge = coord >= coord.max() - tol
            forces[edge, axis] += sign * line_force * size * volumes[edge] / volumes[edge].sum()
    return forces


def _rim_forces(d, volumes, size, line_force, spacing) -> np.ndarray:
    """(n, 2) N: ``line_force * pi * size`` over the points less than a spacing inside the rim."""
    r = np.hypot(d[:, 0], d[:, 1])
    rim = (r > 0.5 * size - (1.0 - _ON_PERIMETER) * spacing) & (r > 0)
    if not rim.any():
        raise InputError(f"pin-force actuator: no point on the rim of the circular patch of size {size} m")
    forces = np.zeros_like(d)
    share = line_force * np.pi * size * volumes[rim] / volumes[rim].sum()
    forces[rim] = share[:, None] * d[rim] / r[rim, None]
    return forces


# -- sensor quadrature ----------------------------------------------------------------


def _checked_points(points) -> np.ndarray:
    pts = np.asarray(points, dtype=float)
    if pts.ndim != 2 or pts.shape[1] not in (2, 3) or len(pts) < 3:
        raise InputError(f"pzt sensor: points must have shape (n >= 3, 2 or 3), got {pts.shape}")
    return pts


def _local_points(xy: np.ndarray, center, size: float) -> np.ndarray:
    """Indices of the points within the patch's circumcircle plus three spacings."""
    c = np.asarray(center, dtype=float)[:2]
    tree = cKDTree(xy)
    sample = tree.query(c, k=min(_SPACING_SAMPLE, len(xy)))[1]
    spacing = float(np.median(tree.query(xy[sample], k=2)[0][:, 1]))
    return np.asarray(tree.query_ball_point(c, size / np.sqrt(2.0) + 3.0 * spacing), dtype=np.int64)


def _perimeter_quadrature(center, size: float, shape: str) -> tuple[np.ndarray, np.ndarray]:
    """Midpoint-rule nodes (m, 2) on the perimeter and outward normals times ds, (m, 2) m."""
    c, a = np.asarray(center, dtype=float)[:2], 0.5 * size
    if shape == "circular":
        theta = 2.0 * np.pi * np.arange(_NODES_ON_CIRCLE) / _NODES_ON_CIRCLE
        normal = np.stack([np.cos(theta), np.sin(theta)], axis=1)
        return c + a * normal, normal * (np.pi * size / _NODES_ON_CIRCLE)
    s = -a + (np.arange(_NODES_PER_EDGE) + 0.5) * size / _NODES_PER_EDGE
    nodes, normals = [], []
    for axis in (0, 1):
        for sign in (-1.0, 1.0):
            node = np.empty((_NODES_PER_EDGE, 2))
            node[:, axis], node[:, 1 - axis] = sign * a, s
            normal = np.zeros((_NODES_PER_EDGE, 2))
            normal[:, axis] = sign
            nodes.append(c + node)
            normals.append(normal)
    return np.concatenate(nodes), np.concatenate(normals) * (size / _NODES_PER_EDGE)


def _barycentric(triangulation: Delaunay, simplex: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    """(m, 3) barycentric coordinates of ``nodes`` in their triangles."""
    transform = triangulation.transform[simplex]
    b = np.einsum("mij,mj->mi", transform[:, :2], nodes - transform[:, 2])
    return np.column_stack([b, 1.0 - b.sum(axis=1)])
