"""Checksums of results files and checkpoints, and the lock of an output folder: a corrupted
file is refused, naming the file (its seal, peridyn.io.seal) or the dataset (a file without a
seal, read by the probe), never used (peridyn.io.integrity, peridyn.io.lock)."""

import json
import os
import socket
import subprocess
import sys
import zlib

import h5py
import numpy as np
import pytest

from peridyn.discretization.state import State
from peridyn.errors import InputError
from peridyn.io import integrity, seal
from peridyn.io.checkpoint import load_checkpoint, save_checkpoint
from peridyn.io.hdf5 import HDF5Writer
from peridyn.io.lock import LOCK_FILE, OutputLock, read_holder
from peridyn.io.results import Results

N = 10
META = {"case_hash": "abc", "case": "{}", "dt": 1e-7, "version": "1.0"}


def flip_byte(path, dataset: str, index: int = 0) -> None:
    """Flip every bit of one stored byte of ``dataset`` in the file (as a bad sector would)."""
    with h5py.File(path, "r") as f:
        ds = f[dataset]
        offset = ds.id.get_offset() if ds.chunks is None else ds.id.get_chunk_info(0).byte_offset
    with open(path, "r+b") as f:
        f.seek(offset + index)
        byte = f.read(1)[0]
        f.seek(offset + index)
        f.write(bytes([byte ^ 0xFF]))


def without_seal(path) -> None:
    """The file as written before seals were recorded, or left by a killed writer."""
    seal.unseal(path)


def write_run(path, steps=range(6)):
    rng = np.random.default_rng(3)
    with HDF5Writer(path, rng.random((N, 3)), np.full(N, 1e-9), {"case": "bar"}, flush_every=None) as h5:
        h5.create_series("u", (N, 3))
        h5.append_block("u", list(steps), [s * 1e-7 for s in steps], rng.random((len(steps), N, 3)))
        h5.write_array("final/u", rng.random((N, 3)))


def test_every_dataset_carries_the_crc32_of_its_bytes(tmp_path):
    path = tmp_path / "results.h5"
    write_run(path)
    with h5py.File(path) as f:
        assert integrity.is_marked(f)
        for name in ("geometry/points", "series/u/data", "series/u/step", "final/u"):
            ds = f[name]
            # zlib.crc32 of the C-order bytes read back: the definition of the attribute
            assert int(ds.attrs["crc32"]) == zlib.crc32(np.ascontiguousarray(ds[()]).tobytes()), name


@pytest.mark.parametrize("dataset", ["series/u/data", "series/u/time", "geometry/points", "final/u"])
def test_a_results_file_with_a_flipped_byte_is_refused_naming_the_file(tmp_path, dataset, monkeypatch):
    """A sealed file: refused by its seal, HDF5 never opening it."""
    path = tmp_path / "results.h5"
    write_run(path)
    flip_byte(path, dataset, 5)
    monkeypatch.setattr(h5py, "File", None)  # any open by HDF5 would raise a TypeError
    with pytest.raises(InputError, match=f"{path}: its bytes do not match its seal"):
        Results(path).series("u")


@pytest.mark.parametrize("dataset", ["series/u/data", "series/u/time", "geometry/points", "final/u"])
def test_a_results_file_without_a_seal_with_a_flipped_byte_is_refused_naming_the_dataset(tmp_path, dataset):
    """A file without a seal (written before seals were recorded) is read by the probe, which
    checks every dataset against its checksum."""
    path = tmp_path / "results.h5"
    write_run(path)
    without_seal(path)
    flip_byte(path, dataset, 5)
    with pytest.raises(InputError, match=f"dataset /{dataset} does not match its checksum"):
        Results(path).series("u")


def test_a_restart_refuses_a_corrupted_series(tmp_path):
    """Continuing a results file (a restart truncates it at the checkpoint) checks it first:
    sealed, by its seal; left by a killed run, by the probe naming the dataset."""
    path = tmp_path / "results.h5"
    write_run(path)
    flip_byte(path, "series/u/data", 17)
    rng = np.random.default_rng(3)
    with pytest.raises(InputError, match="its bytes do not match its seal"):
        HDF5Writer(path, rng.random((N, 3)), np.full(N, 1e-9), {}, mode="a")
    seal.unseal(path)  # as a run killed while writing leaves it
    with pytest.raises(InputError, match="dataset /series/u/data does not match its checksum"):
        with HDF5Writer(path, rng.random((N, 3)), np.full(N, 1e-9), {}, mode="a") as h5:
            h5.truncate(3)


def test_appending_and_truncating_keep_the_checksums(tmp_path):
    path = tmp_path / "results.h5"
    write_run(path)
    rng = np.random.default_rng(3)
    points, volumes = rng.random((N, 3)), np.full(N, 1e-9)
    with HDF5Writer(path, points, volumes, {}, mode="a") as h5:
        h5.truncate(2)
        h5.append("u", 7, 7e-7, np.ones((N, 3)))
    steps, _, data = Results(path).series("u")  # checked on open: no error
    assert steps.tolist() == [0, 1, 2, 7]
    np.testing.assert_array_equal(data[-1], 1.0)


def test_a_results_file_from_before_checksums_is_read(tmp_path):
    path = tmp_path / "results.h5"
    write_run(path)
    with h5py.File(path, "a") as f:  # as written before checksums (and seals) were recorded
        del f.attrs[integrity.FILE_ATTR]
        f.visititems(lambda _, obj: obj.attrs.pop("crc32", None) if isinstance(obj, h5py.Dataset) else None)
    without_seal(path)
    assert Results(path).series("u")[0].tolist() == list(range(6))


def _checkpoint(path, results=None):
    rng = np.random.default_rng(5)
    state = State(rng.random((N, 3)), rng.random((N, 3)), rng.random((N, 3)), 3e-6, 30)
    save_checkpoint(path, state, np.ones(40, dtype=bool), META, results=results)
    return state


@pytest.mark.parametrize("dataset", ["u", "v", "intact"])
def test_a_checkpoint_with_a_flipped_byte_is_refused_naming_the_file(tmp_path, dataset):
    path = tmp_path / "checkpoint.h5"
    state = _checkpoint(path)
    assert seal.read_seal(path) is not None  # written whole: always sealed
    np.testing.assert_array_equal(load_checkpoint(path, N, 40, META)[0].u, state.u)  # intact: read back
    flip_byte(path, dataset, 3)
    with pytest.raises(InputError, match=f"{path}: its bytes do not match its seal"):
        load_checkpoint(path, N, 40, META)
    without_seal(path)  # an older peridyn's checkpoint: the probe names the dataset
    with pytest.raises(InputError, match=f"dataset /{dataset} does not match its checksum"):
        load_checkpoint(path, N, 40, META)


def test_a_checkpoint_with_an_altered_step_is_refused(tmp_path):
    path = tmp_path / "checkpoint.h5"
    _checkpoint(path)
    with h5py.File(path, "a") as f:
        f.attrs["step"] = 31
    assert seal.read_seal(path) is None  # HDF5 cut the file back to its data: the seal is gone
    with pytest.raises(InputError, match=r"attributes \(time, step, case\) do not match their checksum"):
        load_checkpoint(path, N, 40, META)


def test_a_restart_checks_the_results_file_belongs_to_the_checkpoint(tmp_path):
    results = tmp_path / "results.h5"
    # steps 0..50: 3 records before the checkpoint's step 30 (one at step 30 itself may be written
    # before the checkpoint or after it, as the final state's record is: not counted)
    write_run(results, range(0, 60, 10))
    ckpt = tmp_path / "checkpoint.h5"
    run_id = Results(results).run_id()
    _checkpoint(ckpt, {"run_id": run_id, "records": {"u": 3}})
    load_checkpoint(ckpt, N, 40, META, results)  # the right file: accepted
    _checkpoint(ckpt, {"run_id": run_id, "records": {"u": 5}})
    with pytest.raises(
        InputError, match="holds 3 records of series 'u' before step 30, the checkpoint was saved with 5"
    ):
        load_checkpoint(ckpt, N, 40, META, results)
    _checkpoint(ckpt, {"run_id": "0" * 32, "records": {"u": 3}})
    with pytest.raises(InputError, match="written by another run than the checkpoint"):
        load_checkpoint(ckpt, N, 40, META, results)
    results.unlink()
    with pytest.raises(
        InputError, match="results.h5' is missing: the records before the checkpoint's step 30"
    ):
        load_checkpoint(ckpt, N, 40, META, results)


def test_a_second_lock_is_refused_naming_the_holder(tmp_path):
    with OutputLock(tmp_path) as lock:
        assert read_holder(tmp_path / LOCK_FILE) == lock.holder
        with pytest.raises(InputError, match=f"in use by another run \\(process {os.getpid()} on "):
            OutputLock(tmp_path)
    assert not (tmp_path / LOCK_FILE).exists()  # released
    OutputLock(tmp_path).release()  # and free again


def test_a_stale_lock_of_a_dead_process_is_taken_over(tmp_path):
    dead = subprocess.run(
        [sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True
    )
    pid = int(dead.stdout)  # that process has ended
    stale = {"pid": pid, "host": socket.gethostname(), "started": "2026-01-01T00:00:00+00:00"}
    (tmp_path / LOCK_FILE).write_text(json.dumps(stale))
    with OutputLock(tmp_path) as lock:
        assert read_holder(tmp_path / LOCK_FILE)["pid"] == os.getpid() == lock.holder["pid"]


def test_a_lock_held_from_another_host_is_never_taken_over(tmp_path):
    other = {"pid": 1, "host": "not-" + socket.gethostname(), "started": "2026-01-01T00:00:00+00:00"}
    (tmp_path / LOCK_FILE).write_text(json.dumps(other))
    with pytest.raises(InputError, match=f"if that job is gone, remove '.*{LOCK_FILE}'"):
        OutputLock(tmp_path)
