"""Maps between points and degrees of freedom (dof = 3 i + a, point-major)."""

from __future__ import annotations

import numpy as np

from peridyn.physics.materials.base import Model


def free_dofs(model: Model, fixed: np.ndarray | None = None) -> np.ndarray:
    """Indices of the free dofs: all but the z dofs of a 2D body and the ``fixed`` ones."""
    n = model.body.n_points
    free = np.ones((n, 3), dtype=bool)
    if model.body.dim == 2:
        free[:, 2] = False
    if fixed is not None:
        free &= ~fixed
    return np.flatnonzero(free.ravel())
