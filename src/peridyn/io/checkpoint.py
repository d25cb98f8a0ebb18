"""Checkpoints of an explicit run: everything needed to continue it bit for bit.

A checkpoint holds u, v, a (n_points, 3), the time, the step and the intact
mask of the bonds (n_bonds,). It is written to a temporary file and renamed,
so a run killed while writing leaves the previous checkpoint intact.
"""

from __future__ import annotations

import os
from pathlib import Path

import h5py
import numpy as np

from peridyn.discretization.state import State
from peridyn.errors import InputError


def save_checkpoint(path, state: State, intact: np.ndarray) -> None:
    """Write ``state`` and the bonds' ``intact`` mask to ``path`` atomically."""
    path = Path(path)
    tmp = path.with_suffix(path.suffix + ".tmp")
    with h5py.File(tmp, "w") as f:
        for name in ("u", "v", "a"):
            f.create_dataset(name, data=getattr(state, name))
        f.create_dataset("intact", data=intact)
        f.attrs["time"] = state.time
        f.attrs["step"] = state.step
    os.replace(tmp, path)


def load_checkpoint(path, n_points: int, n_bonds: int) -> tuple[State, np.ndarray]:
    """Read a checkpoint; checks that it belongs to a body of the same size."""
    path = Path(path)
    if not path.is_file():
        raise InputError(f"checkpoint file {str(path)!r} does not exist: nothing to restart from")
    with h5py.File(path, "r") as f:
        state = State(f["u"][...], f["v"][...], f["a"][...], float(f.attrs["time"]), int(f.attrs["step"]))
        intact = f["intact"][...]
    if state.u.shape != (n_points, 3) or intact.shape != (n_bonds,):
        raise InputError(
            f"checkpoint {str(path)!r} holds {state.u.shape[0]} points and {intact.shape[0]} "
            f"bonds, but the case has {n_points} points and {n_bonds} bonds: a different case?"
        )
    return state, intact


class Checkpointer:
    """Observer that saves a checkpoint every ``every`` steps."""

    def __init__(self, path, every: int, intact: np.ndarray):
        if every < 1:
            raise InputError(f"checkpoint interval must be at least 1 step, got {every}")
        self.path = Path(path)
        self.every = int(every)
        self.intact = intact

    def observe(self, state: State, solver) -> None:
        """Save when the step is a multiple of ``every``."""
        if state.step % self.every == 0:
            save_checkpoint(self.path, state, self.intact)
