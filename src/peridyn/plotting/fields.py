"""Figures of a run read back from its results.h5: sensor signals, B-scans, fields, damage."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.tri import Triangulation  # noqa: E402

from peridyn.analysis.fk import point_grid  # noqa: E402
from peridyn.discretization.body import Body  # noqa: E402
from peridyn.errors import InputError  # noqa: E402
from peridyn.io.results import Results  # noqa: E402

COMPONENT_NAMES = ("x", "y", "z")


def plot_run(results: Results, body: Body) -> list[Path]:
    """Draw every figure the ``results`` of a run of ``body`` support, in the results' folder;
    returns the PNG paths written."""
    directory = Path(results.path).parent
    written = []
    series = results.series_names()
    if "sensor_u" in series:
        written.append(plot_sensors(results, directory / "sensors.png"))
    for key in series:
        if key.startswith("line_"):
            name = key.removeprefix("line_")
            written.append(plot_bscan(results, name, directory / f"bscan_{name}.png"))
    u = results.array("final/u")
    damage = results.array("final/damage") if results.has("final/damage") else None
    if body.dim == 3:
        written.append(
            plot_field(
                body, u[:, 2], "final u_z (m)", directory / "displacement.png", cmap="RdBu_r", symmetric=True
            )
        )
    else:
        written.append(
            plot_field(body, np.linalg.norm(u, axis=1), "final |u| (m)", directory / "displacement.png")
        )
    if damage is not None and damage.max() > 0:
        written.append(
            plot_field(
                body, damage, "damage index", directory / "damage.png", cmap="inferno", limits=(0.0, 1.0)
            )
        )
    return written


def plot_sensors(results: Results, path: Path) -> Path:
    """Displacement components against time at each sensor (series ``sensor_u``), each labelled
    with its name and position (the grid point it reads, mm)."""
    attrs = results.series_attrs("sensor_u")
    names = [str(n) for n in attrs["names"]]
    where = results.array("geometry/points")[attrs["points"]] * 1e3
    _, t, data = results.series("sensor_u")
    t = t * 1e6
    fig, axes = plt.subplots(len(names), 1, figsize=(7, 1.8 + 1.6 * len(names)), squeeze=False, sharex=True)
    for k, (ax, name) in enumerate(zip(axes[:, 0], names, strict=True)):
        for c in range(3):
            ax.plot(t, data[:, k, c], label=f"u{COMPONENT_NAMES[c]}")
        position = ", ".join(f"{v:.4g}" for v in where[k])
        ax.set_ylabel(f"{name}\n({position}) mm\nu (m)", fontsize=8)
        ax.grid(alpha=0.3)
    axes[0, 0].legend(loc="upper right", ncol=3, fontsize=8)
    axes[-1, 0].set_xlabel("time (us)")
    return _save(fig, path)


def plot_bscan(results: Results, name: str, path: Path) -> Path:
    """Space-time map (B-scan) of each displacement component along a line probe (series
    ``line_<name>``; a profile plot when the line holds a single record, as after a static
    solve)."""
    _, t, data = results.series(f"line_{name}")
    t = t * 1e6
    points = results.array("geometry/points")[results.series_attrs(f"line_{name}")["points"]]
    distance = np.linalg.norm(points - points[0], axis=1) * 1e3
    if len(t) < 2:  # a static result: the displacement profile along the line
        fig, ax = plt.subplots(figsize=(7, 4))
        for c in range(3):
            ax.plot(distance, data[-1, :, c], label=f"u{COMPONENT_NAMES[c]}")
        ax.set_xlabel("distance along the line (mm)")
        ax.set_ylabel("u (m)")
        ax.set_title(f"displacement along line '{name}'")
        ax.legend()
        ax.grid(alpha=0.3)
        return _save(fig, path)
    fig, axes = plt.subplots(1, 3, figsize=(13, 4), sharey=True, layout="constrained")
    lim = float(np.max(np.abs(data))) or 1.0  # one scale: the components compare at a glance
    for c, ax in enumerate(axes):
        field = data[:, :, c]
        image = ax.imshow(
            field,
            aspect="auto",
            origin="lower",
            cmap="RdBu_r",
            vmin=-lim,
            vmax=lim,
            extent=(distance[0], distance[-1], t[0], t[-1]),
        )
        ax.set_title(f"u{COMPONENT_NAMES[c]} along line '{name}'")
        ax.set_xlabel("distance along the line (mm)")
    axes[0].set_ylabel("time (us)")
    fig.colorbar(image, ax=axes, label="displacement (m)", shrink=0.9)
    return _save(fig, path)


def plot_field(
    body: Body,
    values: np.ndarray,
    label: str,
    path: Path,
    cmap="viridis",
    limits=None,
    symmetric: bool = False,
) -> Path:
    """Colour map of a point field: the whole body in 2D, the top layer (largest z) in 3D.

    The points are triangulated; triangles longer than two spacings (holes, cracks'
    removed points, concave outlines) are left blank.
    """
    x = body.points
    sel = np.ones(body.n_points, dtype=bool)
    if body.dim == 3:
        sel = x[:, 2] >= x[:, 2].max() - 0.5 * np.min(body.cells[:, 2])
    xs, ys, vs = x[sel, 0] * 1e3, x[sel, 1] * 1e3, values[sel]
    tri = _triangulation(x[sel], xs, ys, 2.01 * body.spacing * 1e3 * np.sqrt(2))
    if limits is None and symmetric:
        lim = float(np.max(np.abs(vs))) or 1.0
        limits = (-lim, lim)
    vmin, vmax = limits if limits is not None else (None, None)
    fig, ax = plt.subplots(figsize=(7, 5))
    sc = ax.tripcolor(tri, vs, cmap=cmap, vmin=vmin, vmax=vmax, shading="gouraud")
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_title(label + (" (top layer)" if body.dim == 3 else ""))
    fig.colorbar(sc, ax=ax, label=label)
    return _save(fig, path)


def _triangulation(points: np.ndarray, xs: np.ndarray, ys: np.ndarray, longest: float) -> Triangulation:
    """Triangles of the points at ``xs``, ``ys`` (mm): on a regular grid (``points``, m, on
    :func:`peridyn.analysis.fk.point_grid`), two per grid cell whose four corners are points and
    one per cell with three; otherwise a Delaunay triangulation without the triangles with an
    edge longer than ``longest`` (mm). A grid needs no Delaunay search, whose cocircular points
    cost a second on a plate layer."""
    try:
        grid = point_grid(points)
    except InputError:
        grid = None
    if grid is None:
        tri = Triangulation(xs, ys)
        edges = np.hypot(
            np.diff(xs[tri.triangles], axis=1, append=xs[tri.triangles][:, :1]),
            np.diff(ys[tri.triangles], axis=1, append=ys[tri.triangles][:, :1]),
        )
        tri.set_mask(edges.max(axis=1) > longest)
        return tri
    node = np.full(grid.shape, -1, dtype=np.int64)
    node[grid.ix, grid.iy] = np.arange(len(points))
    # corners of each cell counter-clockwise: (i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)
    cells = np.stack([node[:-1, :-1], node[1:, :-1], node[1:, 1:], node[:-1, 1:]], axis=-1).reshape(-1, 4)
    present = cells >= 0
    full, three = cells[present.all(axis=1)], present.sum(axis=1) == 3
    triangles = np.concatenate(
        [full[:, [0, 1, 2]], full[:, [0, 2, 3]], cells[three][present[three]].reshape(-1, 3)]
    )
    return Triangulation(xs, ys, triangles)


def _save(fig, path: Path) -> Path:
    if fig.get_layout_engine() is None:
        fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
