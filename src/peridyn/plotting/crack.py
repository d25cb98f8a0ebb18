"""Fracture figures: damage on the deformed configuration with crack paths, crack length
against time."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from scipy.spatial import cKDTree  # noqa: E402

from peridyn.analysis.crack import CrackPath  # noqa: E402
from peridyn.plotting.fields import _save  # noqa: E402


def plot_damage_map(
    points: np.ndarray,
    u: np.ndarray,
    phi: np.ndarray,
    paths: list[CrackPath],
    path: Path,
    scale: float | None = None,
    title: str = "damage",
) -> Path:
    """Damage index on the deformed configuration x + scale * u with the crack polylines
    (``displaced_polylines``) over it.

    Parameters
    ----------
    points, u : (n, 2|3) float64, m
    phi : (n,) float64
    paths : crack paths of ``peridyn.analysis.crack.crack_paths``
    scale : float or None
        Displacement magnification; None: 50 (as Martowicz draws) or less, so that the largest
        drawn displacement is at most a tenth of the body's size.
    """
    xy0, uv = points[:, :2], u[:, :2]
    if scale is None:
        scale = default_scale(xy0, uv)
    xy = (xy0 + scale * uv) * 1e3
    fig, ax = plt.subplots(figsize=(7, 5))
    order = np.argsort(phi)  # damaged points on top
    sc = ax.scatter(
        xy[order, 0], xy[order, 1], c=phi[order], s=4, cmap="inferno_r", vmin=0.0, vmax=1.0, linewidths=0
    )
    for k, line in enumerate(displaced_polylines(xy0, uv, paths, scale)):
        ax.plot(
            line[:, 0] * 1e3,
            line[:, 1] * 1e3,
            "-",
            color="tab:cyan",
            lw=1.5,
            label="crack paths" if k == 0 else None,
        )
    if paths:
        ax.legend(loc="upper right", fontsize=8)
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_title(f"{title}, displacements x{scale:.3g}")
    fig.colorbar(sc, ax=ax, label="damage index")
    return _save(fig, path)


def displaced_polylines(
    xy: np.ndarray, uv: np.ndarray, paths: list[CrackPath], scale: float
) -> list[np.ndarray]:
    """Each path's polyline ((m, 2), m) moved by ``scale`` times the mean in-plane
    displacement of the points of its vertex's 8 nearest (x, y) positions: both faces of the
    crack, so it stays on the opened crack's mid-line. In 3D every point of those positions'
    columns through the thickness counts (the 8 nearest points alone would be one column and
    one face).

    xy, uv : (n, 2) float64, m
        Reference positions and displacements.
    """
    nearest = cKDTree(xy)
    per_column = len(xy) // max(len(np.unique(xy, axis=0)), 1)
    count = min(8 * per_column, len(xy))
    lines = []
    for p in paths:
        near = nearest.query(p.points, k=count)[1].reshape(len(p.points), -1)
        lines.append(p.points + scale * uv[near].mean(axis=1))
    return lines


def default_scale(xy: np.ndarray, uv: np.ndarray, largest: float = 50.0) -> float:
    """Displacement magnification: ``largest``, or less so that the largest drawn displacement
    is a tenth of the body's bounding-box diagonal."""
    size = float(np.linalg.norm(xy.max(axis=0) - xy.min(axis=0)))
    umax = float(np.max(np.linalg.norm(uv, axis=1))) if len(uv) else 0.0
    return largest if umax == 0 else min(largest, 0.1 * size / umax)


def plot_crack_length(times_s, lengths_m, path: Path) -> Path:
    """Total crack length (mm) against time (us)."""
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(np.asarray(times_s) * 1e6, np.asarray(lengths_m) * 1e3, "-o", ms=2)
    ax.set_xlabel("time (us)")
    ax.set_ylabel("crack length (mm)")
    ax.grid(alpha=0.3)
    return _save(fig, path)
