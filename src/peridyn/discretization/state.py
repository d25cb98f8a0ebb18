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


@dataclass
class ProbeState:
    """A state's values at a recorder's probe points only (``peridyn.io.recorder.Probes``): what an
    MPI run gathers on rank 0 at a series record instead of the whole body. The ranks have
    already checked the whole state (``check_state``, ``peridyn.parallel.domain.Domain``).

    Attributes
    ----------
    u : (k, 3) float64
        Displacement (m) at the probes' ``u_points``, in their order.
    v : (s, 3) float64
        Velocity (m/s) at the probes' ``v_points``, in their order.
    time : float, s
    step : int
    """

    u: np.ndarray
    v: np.ndarray
    time: float = 0.0
    step: int = 0


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
    found = first_unsound(state, max_displacement)
    if found is not None:
        raise InstabilityError(state.step, state.time, found[1], found[2])


def first_unsound(
    state: State, max_displacement: float = np.inf, point_ids: np.ndarray | None = None
) -> tuple[int, int, str] | None:
    """What ``check_state`` reports: None when u and v are finite and no component of u exceeds
    ``max_displacement`` (m); else ``(field, point, detail)``: ``field`` 0 (u) or 1 (v), the
    first field out of bounds; ``point`` its first bad row or, with ``point_ids`` ((n,) int, the
    rows' global indices, e.g. a rank's owned points), the smallest global index of its bad
    rows; ``detail`` what is wrong."""
    if state_is_sound(state.u, state.v, float(max_displacement)):
        return None
    fields = (("displacement u", state.u, max_displacement), ("velocity v", state.v, np.inf))
    for field, (name, values, limit) in enumerate(fields):
        bad = ~(np.abs(values) <= limit).all(axis=1)
        if bad.any():
            rows = np.flatnonzero(bad)
            row = int(rows[0] if point_ids is None else rows[np.argmin(point_ids[rows])])
            what = "not finite" if not np.isfinite(values[row]).all() else f"above {limit:.3g} m (runaway)"
            point = row if point_ids is None else int(point_ids[row])
            return (
                field,
                point,
                f"{name} {what} (time step too large, or a load too violent for the discretisation?)",
            )
    return None
