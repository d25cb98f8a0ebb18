"""Observers of a running solver that a job attaches: each has ``observe(state, solver)``,
called after every step."""

from __future__ import annotations

import numpy as np

from peridyn.analysis.crack import DEFAULT_THRESHOLD, total_crack_length
from peridyn.errors import InputError


class CrackLengthObserver:
    """Total crack length against time, sampled every ``every`` steps of a run.

    Parameters
    ----------
    body : Body
        The whole body.
    damage : callable () -> (n_points,) float64
        The damage index of the current state (e.g. ``lambda: damage_field(model)``).
    every : int
    threshold : float
    """

    def __init__(self, body, damage, every: int, threshold: float = DEFAULT_THRESHOLD):
        if every < 1:
            raise InputError(f"crack observer interval must be >= 1 step, got {every!r}")
        self.body, self.damage, self.every, self.threshold = body, damage, int(every), threshold
        self.times: list[float] = []
        self.lengths: list[float] = []

    def due(self, step: int) -> bool:
        """True when a sample is taken at ``step``."""
        return step % self.every == 0

    def observe(self, state, solver=None) -> None:
        if self.due(state.step):
            self.sample(state.time)

    def sample(self, time: float) -> None:
        """Record the crack length of the current damage at ``time`` (s)."""
        body = self.body
        self.times.append(float(time))
        self.lengths.append(total_crack_length(body.points, self.damage(), body.spacing, self.threshold))

    def checkpoint_state(self) -> dict:
        """The samples so far, for a checkpoint: times (k,) s and lengths (k,) m."""
        return {"times": np.array(self.times, dtype=float), "lengths": np.array(self.lengths, dtype=float)}

    def restore_state(self, saved: dict) -> None:
        """Take back the samples of ``checkpoint_state``."""
        self.times = [float(t) for t in saved["times"]]
        self.lengths = [float(x) for x in saved["lengths"]]

    def history(self) -> dict:
        """``{"time_s": [...], "length_m": [...]}``."""
        return {"time_s": list(self.times), "length_m": list(self.lengths)}


def crack_observer(case, setup, n_steps, damage):
    """Crack length against time, sampled at the snapshots (or 100 times a run) of a case
    with damage (``damage``: the whole body's damage index, a callable); None without damage."""
    if setup.damage is None:
        return None
    every = case.output.snapshot_every or max(1, n_steps // 100)
    return CrackLengthObserver(setup.whole_body, damage, every)
