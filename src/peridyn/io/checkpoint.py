"""Checkpoints of an explicit run: everything needed to continue it bit for bit.

A checkpoint holds u, v, a (n_points, 3), the time, the step, the intact mask of the bonds
(n_bonds,), what identifies the run (``meta``: the case hash, the time step and the peridyn
version, checked on restart) and the state of the run's stateful parts (``parts``: the
damage model's stretch-test skin, the contact neighbour list, the crack-length samples),
each a dict of arrays and numbers given by the part's ``checkpoint_state()`` and given back
to its ``restore_state(saved)``. It is written to a temporary file, sealed (``peridyn.io.seal``:
the CRC-32 of the whole file, checked before HDF5 opens it again) and renamed, so a run killed
while writing leaves the previous checkpoint intact.

Every dataset carries its CRC-32 and the attributes their own (``peridyn.io.integrity``); a
checkpoint that does not match them is refused, naming what differs. A checkpoint also names
the results file it belongs to (``results``: the run id of ``results.h5`` and how many records
each series held when it was saved), and a restart whose ``results.h5`` is missing, another
run's, or short of those records is refused: continuing it would leave a results file with
records missing.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import h5py
import numpy as np

from peridyn.discretization.state import State
from peridyn.errors import InputError
from peridyn.io import integrity, seal
from peridyn.io.results import Results

#: What ``meta`` holds, with its name in the refusal message (``case``, the case as JSON
#: text, names the case entries that differ when ``case_hash`` does).
META_KEYS = {"case_hash": "case", "dt": "time step (s)", "version": "peridyn version"}

#: The root attributes of a checkpoint, guarded by the checksum in ``ATTRS_CRC``.
SAVED_ATTRS = ("time", "step", *META_KEYS, "case", "results")
#: Root attribute: CRC-32 of ``SAVED_ATTRS``.
ATTRS_CRC = "attrs_crc32"


def save_checkpoint(
    path, state: State, intact: np.ndarray, meta: dict, parts: dict | None = None, results: dict | None = None
) -> None:
    """Write ``state``, the bonds' ``intact`` mask, ``meta`` (``META_KEYS`` and ``case``), the ``parts``
    (name -> object with ``checkpoint_state()``) and ``results`` (``{"run_id": ..., "records":
    {series: count}}`` of the run's results file, ``HDF5Writer.identity``; None: a run without
    one) to ``path`` atomically, every dataset with its checksum."""
    path = Path(path)
    tmp = path.with_suffix(path.suffix + ".tmp")
    with h5py.File(tmp, "w") as f:
        for name in ("u", "v", "a"):
            _write(f, name, getattr(state, name))
        _write(f, "intact", intact)
        f.attrs["time"] = state.time
        f.attrs["step"] = state.step
        for key in (*META_KEYS, "case"):
            f.attrs[key] = meta[key]
        f.attrs["results"] = json.dumps(results)
        for name, part in (parts or {}).items():
            group = f.create_group(f"parts/{name}")
            for key, value in part.checkpoint_state().items():
                _write(group, key, value)
        f.attrs[ATTRS_CRC] = np.uint32(integrity.attrs_crc(f.attrs, SAVED_ATTRS))
        integrity.mark_file(f)
    seal.seal(tmp)
    os.replace(tmp, path)


def _write(group: h5py.Group, name: str, value) -> None:
    """A dataset with its checksum."""
    value = np.asarray(value)
    integrity.stamp_whole(group.create_dataset(name, data=value), value)


def load_checkpoint(
    path, n_points: int, n_bonds: int, meta: dict, results_path=None
) -> tuple[State, np.ndarray, dict]:
    """Read a checkpoint made for this run: returns the state, the intact mask and the saved
    parts (name -> dict for ``restore_state``). With ``results_path``, the run's results file
    must be the one the checkpoint was saved with (``check_results``).

    Raises
    ------
    InputError
        No checkpoint, a corrupted one (naming the dataset or the attributes that do not match
        their checksum), one made for another body, case, time step or peridyn version (the
        message names what differs), or a results file that does not belong to it.
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"checkpoint file {str(path)!r} does not exist: nothing to restart from")
    try:
        seal.check(path)
    except InputError as exc:
        raise InputError(f"{exc} (start again with --overwrite)") from None
    try:
        with h5py.File(path, "r") as f:
            _verify(f, str(path))
            saved_results = f.attrs.get("results")
            results = json.loads(_text(saved_results)) if saved_results is not None else None
            state = State(f["u"][...], f["v"][...], f["a"][...], float(f.attrs["time"]), int(f.attrs["step"]))
            intact = f["intact"][...]
            saved = {key: f.attrs.get(key) for key in (*META_KEYS, "case")}
            parts = {
                name: {key: ds[()] for key, ds in group.items()} for name, group in f.get("parts", {}).items()
            }
    except InputError:
        raise
    except (OSError, KeyError, TypeError, ValueError, RuntimeError) as exc:  # damaged: HDF5 objects
        raise InputError(  # of another kind, attributes that do not parse
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
    if results_path is not None:
        check_results(results_path, state.step, results)
    return state, intact, parts


def _verify(f: h5py.File, path: str) -> None:
    """Check a checkpoint's datasets and attributes against their checksums."""
    if not integrity.is_marked(f):
        raise InputError(
            f"checkpoint {path!r} has no checksums (made by an older peridyn, or damaged): "
            "start again with --overwrite"
        )
    if int(f.attrs.get(ATTRS_CRC, -1)) != integrity.attrs_crc(f.attrs, SAVED_ATTRS):
        raise InputError(
            f"{path}: the checkpoint's attributes (time, step, case) do not match their checksum: "
            "the file is corrupted; it is not used (start again with --overwrite)"
        )
    try:
        integrity.verify_file(f, path)
    except InputError as exc:
        raise InputError(f"{exc} (start again with --overwrite)") from None


def check_results(results_path, step: int, saved: dict | None) -> None:
    """Refuse to continue a checkpoint at ``step`` whose results file (``saved``: its run id and
    record counts before ``step`` when the checkpoint was saved) is missing, another run's,
    corrupted, or holds another number of records before ``step``."""
    if saved is None:
        return
    path = Path(results_path)
    again = "start again with --overwrite"
    if not path.is_file():
        raise InputError(
            f"--restart: {str(path)!r} is missing: the records before the checkpoint's step {step} "
            f"would be lost; {again}"
        )
    results = Results(path)
    if results.run_id() != saved["run_id"]:
        raise InputError(
            f"--restart: {str(path)!r} was written by another run than the checkpoint (run id "
            f"{results.run_id()} there, {saved['run_id']} in the checkpoint); {again}"
        )
    for name, count in saved["records"].items():
        held = int(np.count_nonzero(results.steps(name) < step)) if name in results.series_names() else 0
        if held != count:
            raise InputError(
                f"--restart: {str(path)!r} holds {held} records of series {name!r} before step {step}, "
                f"the checkpoint was saved with {count}; {again}"
            )


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
    results : callable (step) -> dict, or None
        The identity of the run's results file at the checkpoint's step, after ``before_save``
        (``HDF5Writer.identity``),
        saved with the checkpoint and checked on restart.
    """

    def __init__(
        self,
        path,
        every: int,
        intact: np.ndarray,
        meta: dict,
        parts: dict | None = None,
        before_save=(),
        results=None,
    ):
        if every < 1:
            raise InputError(f"checkpoint interval must be at least 1 step, got {every}")
        self.path = Path(path)
        self.every = int(every)
        self.intact = intact
        self.meta = meta
        self.parts = parts or {}
        self.before_save = list(before_save)
        self.results = results

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
        results = self.results(state.step) if self.results is not None else None
        save_checkpoint(self.path, state, self.intact, self.meta, self.parts, results)
