"""Checkpoints of an explicit run: everything needed to continue it bit for bit.

A checkpoint holds u, v, a (n_points, 3), the time, the step, the intact mask of the bonds
(n_bonds,), what identifies the run (``meta``: the case hash, the time step and the peridyn
version, checked on restart) and the state of the run's stateful parts (``parts``: the
damage model's stretch-test skin, the contact neighbour list, the crack-length samples),
each a dict of arrays and numbers given by the part's ``checkpoint_state()`` and given back
to its ``restore_state(saved)``. It is written to a temporary file and renamed, so a run
killed while writing leaves the previous checkpoint intact.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import h5py
import numpy as np

from peridyn.discretization.state import State
from peridyn.errors import InputError

#: What ``meta`` holds, with its name in the refusal message (``case``, the case as JSON
#: text, names the case entries that differ when ``case_hash`` does).
META_KEYS = {"case_hash": "case", "dt": "time step (s)", "version": "peridyn version"}


def save_checkpoint(path, state: State, intact: np.ndarray, meta: dict, parts: dict | None = None) -> None:
    """Write ``state``, the bonds' ``intact`` mask, ``meta`` (``META_KEYS`` and ``case``) and the ``parts``
    (name -> object with ``checkpoint_state()``) to ``path`` atomically."""
    path = Path(path)
    tmp = path.with_suffix(path.suffix + ".tmp")
    with h5py.File(tmp, "w") as f:
        for name in ("u", "v", "a"):
            f.create_dataset(name, data=getattr(state, name))
        f.create_dataset("intact", data=intact)
        f.attrs["time"] = state.time
        f.attrs["step"] = state.step
        for key in (*META_KEYS, "case"):
            f.attrs[key] = meta[key]
        for name, part in (parts or {}).items():
            group = f.create_group(f"parts/{name}")
            for key, value in part.checkpoint_state().items():
                group.create_dataset(key, data=value)
    os.replace(tmp, path)


def load_checkpoint(path, n_points: int, n_bonds: int, meta: dict) -> tuple[State, np.ndarray, dict]:
    """Read a checkpoint made for this run: returns the state, the intact mask and the saved
    parts (name -> dict for ``restore_state``).

    Raises
    ------
    InputError
        No checkpoint, or one made for another body, case, time step or peridyn version
        (the message names what differs).
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"checkpoint file {str(path)!r} does not exist: nothing to restart from")
    try:
        with h5py.File(path, "r") as f:
            state = State(f["u"][...], f["v"][...], f["a"][...], float(f.attrs["time"]), int(f.attrs["step"]))
            intact = f["intact"][...]
            saved = {key: f.attrs.get(key) for key in (*META_KEYS, "case")}
            parts = {
                name: {key: ds[()] for key, ds in group.items()} for name, group in f.get("parts", {}).items()
            }
    except (OSError, KeyError) as exc:
        raise InputError(
            f"checkpoint {str(path)!r} is not readable ({exc}): start again with --overwrite"
        ) from None
    if state.u.shape != (n_points, 3) or intact.shape != (n_bonds,):
        raise InputError(
            f"checkpoint {str(path)!r} holds {state.u.shape[0]} points and {intact.shape[0]} "
            f"bonds, but the case has {n_points} points and {n_bonds} bonds: a different case?"
        )
    differ = [
        _case_differences(saved["case"], meta["case"])
        if key == "case_hash"
        else f"{label} {_text(saved[key])} -> {_text(meta[key])}"
        for key, label in META_KEYS.items()
        if _text(saved[key]) != _text(meta[key])
    ]
    if differ:
        raise InputError(
            f"checkpoint {str(path)!r} was made for another run ({'; '.join(differ)}): restart only "
            "with the case and settings that made it, or start again with --overwrite"
        )
    return state, intact, parts


def _case_differences(saved, current: str) -> str:
    """``case: key old -> new, ...`` for the entries of two cases (JSON text) that differ."""
    if saved is None:
        return "case (not recorded in the checkpoint)"
    old, new = _flatten(json.loads(_text(saved))), _flatten(json.loads(current))
    keys = sorted(k for k in old.keys() | new.keys() if old.get(k) != new.get(k))
    return "case: " + ", ".join(f"{k} {old.get(k)!r} -> {new.get(k)!r}" for k in keys)


def _flatten(value, prefix: str = "") -> dict:
    """Nested dicts and lists as {dotted key: leaf}."""
    if isinstance(value, dict):
        items = value.items()
    elif isinstance(value, list):
        items = ((f"[{i}]", v) for i, v in enumerate(value))
    else:
        return {prefix: value}
    flat = {}
    for key, v in items:
        name = f"{prefix}{key}" if key.startswith("[") or not prefix else f"{prefix}.{key}"
        flat.update(_flatten(v, name))
    return flat


def _text(value) -> str:
    """A meta value as text, for comparison and messages (a float with all its digits)."""
    if value is None:
        return "(none)"
    if isinstance(value, bytes):
        return value.decode()
    if isinstance(value, float | np.floating):
        return repr(float(value))
    return str(value)


class Checkpointer:
    """Observer that saves a checkpoint every ``every`` steps (and on demand: ``save``).

    Parameters
    ----------
    path : path
    every : int
        Steps between checkpoints (>= 1).
    intact : (n_bonds,) bool
        The bonds' intact mask (read at every save).
    meta : dict
        ``META_KEYS`` and ``case`` of the run.
    parts : dict of name -> object with ``checkpoint_state()``
    before_save : sequence of callables () -> None
        Called before every save, e.g. ``Recorder.flush``: the records held in memory up to the
        checkpoint's step are on disk before the checkpoint is.
    """

    def __init__(
        self, path, every: int, intact: np.ndarray, meta: dict, parts: dict | None = None, before_save=()
    ):
        if every < 1:
            raise InputError(f"checkpoint interval must be at least 1 step, got {every}")
        self.path = Path(path)
        self.every = int(every)
        self.intact = intact
        self.meta = meta
        self.parts = parts or {}
        self.before_save = list(before_save)

    def due(self, step: int) -> bool:
        """True when a checkpoint is saved at ``step``."""
        return step % self.every == 0

    def observe(self, state: State, solver) -> None:
        """Save when the step is a multiple of ``every``."""
        if self.due(state.step):
            self.save(state)

    def save(self, state: State) -> None:
        """Save a checkpoint of ``state`` now (after the ``before_save`` calls)."""
        for call in self.before_save:
            call()
        save_checkpoint(self.path, state, self.intact, self.meta, self.parts)
