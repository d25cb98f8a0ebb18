"""Fuzzing the files peridyn writes and reads back: a real run's checkpoint and results file with
bits flipped, bytes set at random, runs zeroed, repeated or removed, or cut short
(tests/fuzz/file_mutations.py; half the changes land in the bytes of a dataset's values).

The promise (docs/user-guide.md, "Checkpoint and restart"): a corrupted file is refused, naming
the file (by its seal, before HDF5 opens it; or, where the change cut the seal off, by the probe
that reads it in a child process with a time limit), or -- where the change fell on the seal
alone -- read with every value as written; it is never used with other values, and never hangs.
Reading changes no byte, of the copy read nor of the earlier run. Counts: ``pytest -s``.
"""

from __future__ import annotations

import random
import warnings
from pathlib import Path

import h5py
import numpy as np
import pytest
from file_mutations import hdf5_live_ranges, mutate_bytes
from fuzz_contract import HANG_S, check_unchanged, fingerprint, outcome_in_a_fork, report
from fuzz_mutations import ROOT, base_case, dump

from peridyn.cli import main
from peridyn.io.checkpoint import META_KEYS, load_checkpoint
from peridyn.io.results import Results


@pytest.fixture(autouse=True)
def probe_within_the_hang_limit(monkeypatch):
    """A probe of a file without a seal (``peridyn.io.hdf5_probe``) that HDF5 cannot finish is
    killed well within ``HANG_S``: its refusal, not a hang of the example."""
    monkeypatch.setenv("PERIDYN_PROBE_SECONDS", str(HANG_S / 4))


@pytest.fixture(scope="module")
def earlier_run(tmp_path_factory) -> Path:
    """A finished run of the 160-point bar with its checkpoint (every 2 steps)."""
    root = tmp_path_factory.mktemp("stored")
    case = root / "tiny.yaml"
    case.write_bytes(dump(base_case(ROOT / "cases" / "bar_pulse.yaml", tiny=True)))
    out = root / "finished"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert main(["run", str(case), "-o", str(out), "--checkpoint-every", "2", "--no-progress"]) == 0
    return out


def _datasets(path: Path) -> dict[str, np.ndarray]:
    """Every dataset of an HDF5 file by name."""
    found = {}
    with h5py.File(path, "r") as f:
        f.visititems(
            lambda name, obj: found.update({name: obj[()]}) if isinstance(obj, h5py.Dataset) else None
        )
    return found


def _same(a, b) -> bool:
    a, b = np.asarray(a), np.asarray(b)
    if a.shape != b.shape or a.dtype != b.dtype:
        return False
    return a.tolist() == b.tolist() if a.dtype.kind == "O" else a.tobytes() == b.tobytes()


def _same_all(a, b) -> bool:
    """``_same`` of two arrays, or of each of two tuples of arrays (a series)."""
    if isinstance(a, tuple):
        return isinstance(b, tuple) and len(a) == len(b) and all(map(_same, a, b))
    return _same(a, b)


def fuzz_checkpoints(n: int, earlier: Path, folder: Path) -> None:
    """``n`` damaged copies of the run's checkpoint, loaded as ``run --restart`` loads it."""
    original = earlier / "checkpoint.h5"
    data = original.read_bytes()
    live = hdf5_live_ranges(original)
    with h5py.File(original, "r") as f:
        meta = {key: f.attrs[key] for key in (*META_KEYS, "case")}
        time, step = float(f.attrs["time"]), int(f.attrs["step"])
    values = _datasets(original)
    n_points, n_bonds = values["u"].shape[0], values["intact"].shape[0]

    def differences(path: Path) -> list[str]:
        s, intact, _ = load_checkpoint(path, n_points, n_bonds, meta, earlier / "results.h5")
        used = [k for k in ("u", "v", "a") if not _same(getattr(s, k), values[k])]
        used += ["intact"] * (not _same(intact, values["intact"]))
        return used + ["time/step"] * ((s.time, s.step) != (time, step))

    before = fingerprint(earlier)
    for seed in range(n):
        rng = random.Random(seed)
        damaged, what = mutate_bytes(data, rng, live)
        path = folder / f"checkpoint-{seed}.h5"  # a new file each: no cached verification
        path.write_bytes(damaged)
        mine = fingerprint(folder)
        outcome_in_a_fork(
            "checkpoints", lambda path=path: differences(path), f"seed {seed}: {what}", names=str(path)
        )
        check_unchanged("checkpoints", mine, folder, f"seed {seed} (the copy read)")
        path.unlink()
    check_unchanged("checkpoints", before, earlier, "the campaign")
    print("\n" + report("checkpoints"))


def test_damaged_checkpoints_are_refused_naming_the_file(earlier_run, tmp_path):
    fuzz_checkpoints(60, earlier_run, tmp_path)


@pytest.mark.slow
def test_damaged_checkpoints_are_refused_naming_the_file_many(earlier_run, tmp_path):
    fuzz_checkpoints(800, earlier_run, tmp_path)


def _read_all(path: Path, names: list[str]) -> dict:
    """What a reader of the results takes: the status, every series and every dataset."""
    results = Results(path)
    read = {"status": results.status()}
    for series in results.series_names():
        read[f"series/{series}"] = results.series(series)
    for name in names:
        read[name] = results.array(name)
    return read


def fuzz_results(n: int, earlier: Path, folder: Path) -> None:
    """``n`` damaged copies of the run's results file, read whole through ``Results``."""
    original = earlier / "results.h5"
    data = original.read_bytes()
    live = hdf5_live_ranges(original)
    names = sorted(_datasets(original))
    expected = _read_all(original, names)

    def differences(path: Path) -> list[str]:
        read = _read_all(path, names)
        return [
            key
            for key, value in expected.items()
            if not (value == read[key] if key == "status" else _same_all(value, read[key]))
        ]

    before = fingerprint(earlier)
    for seed in range(n):
        rng = random.Random(seed)
        damaged, what = mutate_bytes(data, rng, live)
        path = folder / f"results-{seed}.h5"
        path.write_bytes(damaged)
        mine = fingerprint(folder)
        outcome_in_a_fork(
            "results files", lambda path=path: differences(path), f"seed {seed}: {what}", names=str(path)
        )
        check_unchanged("results files", mine, folder, f"seed {seed} (the copy read)")
        path.unlink()
    check_unchanged("results files", before, earlier, "the campaign")
    print("\n" + report("results files"))


def test_damaged_results_files_are_refused_naming_the_file(earlier_run, tmp_path):
    fuzz_results(40, earlier_run, tmp_path)


@pytest.mark.slow
def test_damaged_results_files_are_refused_naming_the_file_many(earlier_run, tmp_path):
    fuzz_results(600, earlier_run, tmp_path)
