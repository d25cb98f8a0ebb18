"""The mutable state of the points in a dynamic run: displacement, velocity, acceleration."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class State:
    """Displacement, velocity and acceleration at one instant.

    Attributes
    ----------
    u, v, a : (n_points, 3) float64 (m, m/s, m/s^2)
    time : float, s
    step : int
    """

    u: np.ndarray
    v: np.ndarray
    a: np.ndarray
    time: float = 0.0
    step: int = 0

    @classmethod
    def zeros(cls, n_points: int) -> State:
        """A body at rest in its reference configuration."""
        return cls(np.zeros((n_points, 3)), np.zeros((n_points, 3)), np.zeros((n_points, 3)))
