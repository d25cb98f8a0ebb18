"""Mode-shape figures: out-of-plane (or in-plane) colour maps of the top face of a plate."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.tri import Triangulation


def plot_mode_shapes(body, result, types, path) -> Path:
    """One panel per elastic mode: u_z on the top face (|u| for in-plane modes), with the
    frequency and type in the title.

    Parameters
    ----------
    body : Body
    result : ModalResult
    types : list of ModeType
    path : PNG to write
    """
    elastic = np.flatnonzero(~result.rigid)
    cols = 3
    rows = max(1, int(np.ceil(len(elastic) / cols)))
    fig = Figure(figsize=(4.2 * cols, 2.6 * rows))
    FigureCanvasAgg(fig)
    x = body.points
    top = x[:, 2] >= x[:, 2].max() - 0.5 * np.min(body.cells[:, 2]) if body.dim == 3 else slice(None)
    tri = Triangulation(x[top, 0] * 1e3, x[top, 1] * 1e3)
    for panel, i in enumerate(elastic):
        ax = fig.add_subplot(rows, cols, panel + 1)
        shape = result.shapes[i]
        in_plane = types[i].type in ("in-plane bending", "other")
        values = np.linalg.norm(shape[top, :2], axis=1) if in_plane else shape[top, 2]
        lim = float(np.max(np.abs(values))) or 1.0
        ax.tripcolor(
            tri,
            values,
            cmap="viridis" if in_plane else "RdBu_r",
            vmin=0 if in_plane else -lim,
            vmax=lim,
            shading="gouraud",
        )
        ax.set_aspect("equal")
        ax.set_title(f"{result.frequencies[i]:.1f} Hz: {types[i]}", fontsize=9)
        ax.set_xticks([])
        ax.set_yticks([])
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return Path(path)
