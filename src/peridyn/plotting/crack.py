"""Fracture figures: damage on the deformed configuration with crack paths, crack length
against time."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from peridyn.analysis.crack import CrackPath  # noqa: E402
from peridyn.plotting.fields import _save  # noqa: E402


def plot_damage_map(points: np.ndarray, u: np.ndarray, phi: np.ndarray, paths: list[CrackPath],
                    path: Path, scale: float = 50.0, title: str = "damage") -> Path:
    """Damage index on the deformed configuration x + scale * u (the seed draws x50), with the
    crack polylines (drawn on the reference configuration) over it.

    Parameters
    ----------
    points, u : (n, 2|3) float64, m
    phi : (n,) float64
    paths : crack paths of ``peridyn.analysis.crack.crack_paths``
    """
    xy = (points[:, :2] + scale * u[:, :2]) * 1e3
    fig, ax = plt.subplots(figsize=(7, 5))
    order = np.argsort(phi)  # damaged points on top
    sc = ax.scatter(xy[order, 0], xy[order, 1], c=phi[order], s=4, cmap="inferno_r",
                    vmin=0.0, vmax=1.0, linewidths=0)
    for k, p in enumerate(paths):
        ax.plot(p.points[:, 0] * 1e3, p.points[:, 1] * 1e3, "-", color="tab:cyan", lw=1.5,
                label="crack paths (reference configuration)" if k == 0 else None)
    if paths:
        ax.legend(loc="upper right", fontsize=8)
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_title(f"{title}, displacements x{scale:g}")
    fig.colorbar(sc, ax=ax, label="damage index")
    return _save(fig, path)


def plot_crack_length(times_s, lengths_m, path: Path) -> Path:
    """Total crack length (mm) against time (us)."""
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(np.asarray(times_s) * 1e6, np.asarray(lengths_m) * 1e3, "-o", ms=2)
    ax.set_xlabel("time (us)")
    ax.set_ylabel("crack length (mm)")
    ax.grid(alpha=0.3)
    return _save(fig, path)
