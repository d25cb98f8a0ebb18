"""The mutable state of the points in a dynamic run: displacement, velocity, acceleration."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from peridyn.errors import InstabilityError
from peridyn.kernels.verlet import state_is_sound

#: A displacement larger than this many times the body's size is a runaway solution.
RUNAWAY_FACTOR = 100.0


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


def runaway_limit(points: np.ndarray) -> float:
    """Largest believable displacement component, m: ``RUNAWAY_FACTOR`` times the largest
    extent of the body's reference points (n_points, dim)."""
    return runaway_limit_of_extent(np.ptp(points, axis=0))


def runaway_limit_of_extent(extent: np.ndarray) -> float:
    """``runaway_limit`` from the extent (max - min, m) of the points along each axis."""
    return RUNAWAY_FACTOR * float(np.max(extent))


def check_state(state: State, max_displacement: float = np.inf) -> None:
    """Raise InstabilityError naming the step, time, first bad point and field when u or v is
    not finite, or when a displacement component exceeds ``max_displacement`` (m).

    One pass over both fields when all is well (``kernels.verlet.state_is_sound``)."""
    if state_is_sound(state.u, state.v, float(max_displacement)):
        return
    fields = (("displacement u", state.u, max_displacement), ("velocity v", state.v, np.inf))
    for name, values, limit in fields:
        bad = ~(np.abs(values) <= limit).all(axis=1)
        if bad.any():
            point = int(np.flatnonzero(bad)[0])
            what = "not finite" if not np.isfinite(values[point]).all() else f"above {limit:.3g} m (runaway)"
            raise InstabilityError(
                state.step,
                state.time,
                point,
                f"{name} {what} (time step too large, or a load too violent for the discretisation?)",
            )
