"""Cycle mapping: how many load cycles each fatigue step stands for.

The thesis (Freimanis 2019, section 7.1) uses a linear mapping of steps to cycles with a parameter tau:
each step advances N by 1 / tau cycles (tau = 1e-5 for 3 steps then 1e-4 for 57 steps gives its
870 000 cycles). ``adaptive`` shortens a step to the cycles the next bond needs to break, so that
no bond dies more than one step late (the per-step cap of 1 / tau still holds).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from peridyn.errors import InputError


@dataclass(frozen=True)
class CycleMapping:
    """Steps and cycles of a fatigue run.

    Attributes
    ----------
    schedule : tuple of (steps, tau)
        Consecutive blocks of ``steps`` steps of 1 / tau cycles each.
    adaptive : bool
        Cut a step short at the cycle where the next bond breaks.
    """

    schedule: tuple[tuple[int, float], ...]
    adaptive: bool = False

    def __post_init__(self):
        if not self.schedule:
            raise InputError("fatigue mapping needs at least one (steps, tau) block")
        for steps, tau in self.schedule:
            if int(steps) < 1 or not (np.isfinite(tau) and tau > 0):
                raise InputError(
                    f"fatigue mapping block needs steps >= 1 and tau > 0, got steps={steps!r}, tau={tau!r}"
                )

    @property
    def n_steps(self) -> int:
        """Number of steps of the whole schedule."""
        return sum(int(s) for s, _ in self.schedule)

    def cycles_per_step(self) -> np.ndarray:
        """(n_steps,) cycles per step, 1 / tau of each step's block."""
        return np.concatenate([np.full(int(s), 1.0 / tau) for s, tau in self.schedule])
