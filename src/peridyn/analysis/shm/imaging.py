"""Damage images from path indices: RAPID (reconstruction algorithm for probabilistic inspection
of damage; Zhao et al. 2007, Smart Mater. Struct. 16, 1208-1217).

Each path (actuator ``a``, sensor ``s``) spreads its damage index over an ellipse with foci at
the two transducers: at a point ``x`` the weight is ``max(0, (beta - R) / (beta - 1))`` with
``R = (|x - a| + |x - s|) / |a - s|`` (1 on the path, ``beta`` on the ellipse's rim). The image
is the sum over the paths; damage lies where paths of large index overlap, and the image's peak
is the estimate of its position.
"""

from __future__ import annotations

import numpy as np

from peridyn.errors import InputError

__all__ = ["image_peak", "rapid_image"]


def rapid_image(transducers, paths, indices, x, y, beta: float = 1.05) -> np.ndarray:
    """RAPID image on the grid ``x`` by ``y``.

    Parameters
    ----------
    transducers : (n, 2) array_like, m
        Transducer centres.
    paths : (n_paths, 2) int array_like
        Actuator and sensor index of each path.
    indices : (n_paths,) array_like
        Damage index of each path (>= 0 counts; negative values count as 0).
    x, y : (nx,), (ny,) array_like, m
        Grid lines of the image.
    beta : float > 1
        Size of the ellipses (ratio of the rim's path length to the direct path's).

    Returns
    -------
    (ny, nx) float64, the indices' unit
    """
    xy = np.asarray(transducers, dtype=float)
    paths = np.asarray(paths, dtype=int)
    di = np.clip(np.asarray(indices, dtype=float), 0.0, None)
    if xy.ndim != 2 or xy.shape[1] != 2:
        raise InputError(f"transducers must be (n, 2) positions, got shape {xy.shape}")
    if paths.ndim != 2 or paths.shape[1] != 2 or di.shape != (paths.shape[0],):
        raise InputError(f"paths (n_paths, 2) and indices (n_paths,) needed, got {paths.shape}, {di.shape}")
    if paths.size and (paths.min() < 0 or paths.max() >= len(xy)):
        raise InputError(f"a path names a transducer outside 0..{len(xy) - 1}")
    if not beta > 1:
        raise InputError(f"RAPID beta must be > 1, got {beta!r}")
    gx, gy = np.meshgrid(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
    image = np.zeros(gx.shape)
    for (i, j), value in zip(paths, di, strict=True):
        a, s = xy[i], xy[j]
        direct = np.hypot(*(s - a))
        if direct <= 0:
            raise InputError(f"path {i}-{j} joins two transducers at one position")
        ratio = (np.hypot(gx - a[0], gy - a[1]) + np.hypot(gx - s[0], gy - s[1])) / direct
        image += value * np.clip((beta - ratio) / (beta - 1.0), 0.0, None)
    return image


def image_peak(x, y, image, transducers=(), exclusion: float = 0.0) -> np.ndarray:
    """(2,) position (m) of the largest pixel of ``image`` ((ny, nx) on grid lines ``x``, ``y``)
    farther than ``exclusion`` (m) from every one of ``transducers`` ((n, 2), m). Every path
    from a transducer has weight 1 there, so a RAPID image peaks on a transducer whose paths
    changed together, wherever the damage is."""
    image = np.asarray(image, dtype=float)
    if image.shape != (len(y), len(x)):
        raise InputError(f"image must be (len(y), len(x)) = {(len(y), len(x))}, got {image.shape}")
    gx, gy = np.meshgrid(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
    allowed = np.ones(image.shape, dtype=bool)
    for tx, ty in np.asarray(transducers, dtype=float).reshape(-1, 2):
        allowed &= np.hypot(gx - tx, gy - ty) > exclusion
    if not allowed.any():
        raise InputError(f"no image pixel lies farther than {exclusion} m from every transducer")
    row, col = np.unravel_index(np.argmax(np.where(allowed, image, -np.inf)), image.shape)
    return np.array([float(x[col]), float(y[row])])
