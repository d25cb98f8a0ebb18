"""Figures of a monitoring job: path indices against cycles and crack length, damage image
frames with the true crack, and the crack path over the life; ``draw_monitoring_figures`` draws
them all from the job's dataset (the job, and ``peridyn plot`` from ``monitoring.nc``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure


def _figure(size):
    fig = Figure(figsize=size)
    FigureCanvasAgg(fig)
    return fig


#: The index figures of a monitoring job: ``<variable>.png`` for each of these dataset variables.
INDEX_FIGURES = ("correlation_index", "residual_energy_index")
#: The dataset variables that the figures are drawn from (``draw_monitoring_figures``).
FIGURE_VARIABLES = (
    *INDEX_FIGURES,
    "cycles",
    "crack_length",
    "crossed",
    "transducer_x",
    "transducer_y",
    "crack_x",
    "crack_y",
    "image",
    "image_peak_x",
    "image_peak_y",
    "plate_size_x",
    "plate_size_y",
    "cracked_point_x",
    "cracked_point_y",
    "first_break_cycle",
)


def draw_monitoring_figures(ds, out) -> list[Path]:
    """The figures of a monitoring job from its dataset ``ds`` (the ``xarray.Dataset`` of
    ``monitoring.nc``, docs/monitoring.md "Output") into folder ``out``: ``correlation_index.png``,
    ``residual_energy_index.png``, ``images.png`` and ``crack_path.png``; returns their paths."""
    out = Path(out)
    cycles = ds["cycles"].values
    crack_length = ds["crack_length"].values
    labels = [str(p) for p in ds["path"].values]
    crossed = ds["crossed"].values.astype(bool)
    transducers = np.column_stack([ds["transducer_x"].values, ds["transducer_y"].values])
    cracks = [_polyline(x, y) for x, y in zip(ds["crack_x"].values, ds["crack_y"].values, strict=True)]
    plots = [
        plot_indices(
            cycles,
            crack_length,
            ds[name].values,
            labels,
            crossed,
            out / f"{name}.png",
            name.replace("_", " "),
        )
        for name in INDEX_FIGURES
    ]
    titles = [f"N = {n:.3g}, a = {1e3 * a:.1f} mm" for n, a in zip(cycles, crack_length, strict=True)]
    plots.append(
        plot_image_frames(
            ds["image_x"].values,
            ds["image_y"].values,
            ds["image"].values,
            transducers,
            cracks,
            np.column_stack([ds["image_peak_x"].values, ds["image_peak_y"].values]),
            titles,
            (float(ds["plate_size_x"]), float(ds["plate_size_y"])),
            out / "images.png",
        )
    )
    points = np.column_stack([ds["cracked_point_x"].values, ds["cracked_point_y"].values])
    plots.append(
        plot_crack_history(
            points,
            ds["first_break_cycle"].values,
            cracks,
            crack_length,
            cycles,
            transducers,
            out / "crack_path.png",
        )
    )
    return plots


def _polyline(x, y) -> np.ndarray | None:
    """The crack polylines ((m, 2), m, a NaN row between two branches: a drawn line breaks
    there) from their vertices' x and y padded with NaN at the end; None if it has none."""
    keep = np.flatnonzero(np.isfinite(x) & np.isfinite(y))
    if keep.size == 0:
        return None
    return np.column_stack([x, y])[: keep[-1] + 1]


def plot_indices(cycles, crack_length, index, labels, crossed, path, name="damage index") -> Path:
    """Each path's index ((n_int, n_paths)) against cycles and crack length (m, drawn in mm),
    crossed paths solid, the others dashed; writes PNG ``path``."""
    fig = _figure((10, 4))
    left, right = fig.subplots(1, 2)
    for p, label in enumerate(labels):
        style = "-o" if crossed[p] else "--x"
        left.plot(cycles, index[:, p], style, label=label + (" (crossed)" if crossed[p] else ""))
        right.plot(1e3 * np.asarray(crack_length), index[:, p], style)
    left.set_xlabel("cycles N")
    left.ticklabel_format(axis="x", style="sci", scilimits=(0, 0))
    right.set_xlabel("crack length a (mm)")
    for ax in (left, right):
        ax.set_ylabel(name)
        ax.grid(True, alpha=0.3)
    left.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return Path(path)


def plot_image_frames(x, y, images, transducers, cracks, peaks, titles, size, path) -> Path:
    """RAPID image frames ((n, ny, nx) on grid lines ``x``, ``y`` m) with the transducers, the
    true crack (its polylines, m, NaN rows between branches, or None) and each image's peak;
    writes PNG ``path``."""
    n = len(images)
    cols = min(n, 4)
    rows = -(-n // cols)
    fig = _figure((3.2 * cols, 3.0 * rows))
    axes = np.atleast_1d(fig.subplots(rows, cols)).ravel()
    xy = 1e3 * np.asarray(transducers)
    for ax, image, crack, peak, title in zip(axes, images, cracks, peaks, titles, strict=False):
        ax.imshow(image, origin="lower", extent=(0, 1e3 * size[0], 0, 1e3 * size[1]), cmap="magma")
        ax.plot(xy[:, 0], xy[:, 1], "s", color="cyan", ms=5)
        if crack is not None:
            ax.plot(1e3 * crack[:, 0], 1e3 * crack[:, 1], "-", color="lime", lw=2)
        if np.all(np.isfinite(peak)):
            ax.plot(1e3 * peak[0], 1e3 * peak[1], "+", color="white", ms=10, mew=2)
        ax.set_title(title, fontsize=8)
        ax.set_xticks([])
        ax.set_yticks([])
    for ax in axes[n:]:
        ax.set_visible(False)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    return Path(path)


def plot_crack_history(points, first_break, cracks, crack_length, cycles, transducers, path) -> Path:
    """The crack over the life: the fatigue model's cracked points coloured by the cycle of
    their first broken bond, the crack at each interrogation (its polylines, NaN rows between
    branches) and the transducers
    (all m, drawn in mm); writes PNG ``path``."""
    fig = _figure((6, 5))
    ax = fig.add_subplot()
    broken = np.isfinite(first_break)
    mark = ax.scatter(
        1e3 * points[broken, 0], 1e3 * points[broken, 1], c=first_break[broken], s=6, cmap="viridis"
    )
    fig.colorbar(mark, ax=ax, label="first bond broken at cycle")
    for crack, a, n in zip(cracks, crack_length, cycles, strict=True):
        if crack is not None:
            ax.plot(
                1e3 * crack[:, 0], 1e3 * crack[:, 1], "-", lw=1, label=f"N = {n:.3g}: a = {1e3 * a:.1f} mm"
            )
    xy = 1e3 * np.asarray(transducers)
    ax.plot(xy[:, 0], xy[:, 1], "ks", ms=6)
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return Path(path)
