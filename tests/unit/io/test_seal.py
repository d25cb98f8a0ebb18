"""The seal of peridyn's HDF5 files (peridyn.io.seal) and the probe of a file without one
(peridyn.io.hdf5_probe): a damaged file is refused before HDF5 can loop forever on it, and a run
killed while writing leaves a file that is read and continued as before."""

import os
import signal
import subprocess
import sys
import time
import zlib
from pathlib import Path

import h5py
import numpy as np
import pytest
import xarray as xr

import peridyn
from peridyn.discretization.state import State
from peridyn.errors import InputError
from peridyn.io import seal
from peridyn.io.checkpoint import load_checkpoint, save_checkpoint
from peridyn.io.hdf5 import HDF5Writer
from peridyn.io.results import Results

N = 10
#: Seconds a probe may take in these tests (PERIDYN_PROBE_SECONDS), and a bound on what a
#: child Python needs beyond it (start, imports) on a loaded machine.
PROBE_S, START_S = 3.0, 30.0


def write_run(path, steps=range(6)):
    rng = np.random.default_rng(3)
    with HDF5Writer(path, rng.random((N, 3)), np.full(N, 1e-9), {"case": "bar"}, flush_every=None) as h5:
        h5.create_series("u", (N, 3))
        h5.append_block("u", list(steps), [s * 1e-7 for s in steps], rng.random((len(steps), N, 3)))


def without_seal(path) -> None:
    """The file as written before seals were recorded (or left by a killed writer)."""
    seal.unseal(path)
    assert seal.read_seal(path) is None


def damage_global_heap(path) -> None:
    """Zero the header of the first object of the file's global heap (where variable-length
    strings live): HDF5 2.0 then loops forever reading the heap, uninterruptibly (the damage a
    fuzzed results file showed: 64 bytes zeroed there)."""
    data = bytearray(path.read_bytes())
    at = data.find(b"GCOL")
    assert at > 0, "the file has a global heap (its variable-length string attributes)"
    data[at + 16 : at + 32] = bytes(16)  # the collection's 16-byte header, then the object's
    path.write_bytes(bytes(data))


def read_elsewhere(path) -> tuple[str, float]:
    """``Results(path).series("u")`` in a child Python (a hang in HDF5 cannot be interrupted in
    this one): its one-line error ("" when it read the file) or "hang" after the probe's limit
    and ``START_S``, and the seconds it took."""
    code = (
        f"import sys; sys.path.insert(0, {str(Path(peridyn.__file__).parents[1])!r})\n"
        "from peridyn.errors import InputError\nfrom peridyn.io.results import Results\n"
        "try:\n    Results(sys.argv[1]).series('u')\nexcept InputError as exc:\n    print(exc)\n"
    )
    env = dict(os.environ, PERIDYN_PROBE_SECONDS=str(PROBE_S))
    start = time.monotonic()
    try:
        done = subprocess.run(
            [sys.executable, "-c", code, str(path)],
            capture_output=True,
            text=True,
            timeout=PROBE_S + START_S,
            env=env,
        )
    except subprocess.TimeoutExpired:
        return "hang", time.monotonic() - start
    assert done.returncode == 0, done.stderr
    return done.stdout.strip(), time.monotonic() - start


def test_a_closed_file_is_sealed_with_the_crc32_of_its_bytes(tmp_path):
    path = tmp_path / "results.h5"
    write_run(path)
    data = path.read_bytes()
    body, line = data[: -seal.LENGTH], data[-seal.LENGTH :]
    # the definition of the seal: zlib.crc32 and length of every byte before it, as text
    assert line == f"peridyn seal 1 crc32 {zlib.crc32(body):08x} bytes {len(body):020d}\n".encode()
    assert seal.read_seal(path) == (zlib.crc32(body), len(body))
    assert body.startswith(b"\x89HDF\r\n\x1a\n")  # HDF5's signature first: tools know the file
    assert xr.open_dataset(path)["u"].shape == (6, N, 3)  # its root view, HDF5 reading past the seal


@pytest.mark.parametrize("where", [b"TREE", b"HEAP", b"SNOD", b"GCOL", "superblock", "last byte", "seal"])
def test_a_sealed_file_with_a_flipped_byte_anywhere_is_refused_before_hdf5_opens_it(
    tmp_path, where, monkeypatch
):
    """HDF5's own structures (its superblock, B-tree, local and global heaps, a symbol table
    node) too: no dataset checksum could see those."""
    path = tmp_path / "results.h5"
    write_run(path)
    data = bytearray(path.read_bytes())
    if where == "seal":  # its CRC-32's first hex digit another
        at = len(data) - seal.LENGTH + len("peridyn seal 1 crc32 ")
        data[at] = ord("0") if data[at] != ord("0") else ord("1")
    else:
        at = {"superblock": 20, "last byte": len(data) - seal.LENGTH - 1}.get(where) or data.find(where) + 20
        assert at > 19
        data[at] ^= 0x01
    path.write_bytes(bytes(data))
    assert seal.read_seal(path) is not None
    monkeypatch.setattr(h5py, "File", None)  # any open by HDF5 would raise a TypeError
    with pytest.raises(InputError, match=f"^{path}: its bytes do not match its seal"):
        Results(path)


@pytest.mark.parametrize("change", ["added", "removed"])
def test_a_sealed_file_with_bytes_added_or_removed_is_refused_before_hdf5_opens_it(
    tmp_path, change, monkeypatch
):
    path = tmp_path / "results.h5"
    write_run(path)
    data = path.read_bytes()
    whole = len(data) - seal.LENGTH
    data = data[:1000] + b"\xff" * 8 + data[1000:] if change == "added" else data[:1000] + data[1008:]
    path.write_bytes(data)
    monkeypatch.setattr(h5py, "File", None)  # any open by HDF5 would raise a TypeError
    monkeypatch.setattr(subprocess, "run", None)  # and so would a probe
    held = whole + (8 if change == "added" else -8)
    with pytest.raises(
        InputError, match=f"^{path}: holds {held} bytes before its seal, which covers {whole}: "
    ):
        Results(path)


def test_a_cut_file_is_refused_naming_it(tmp_path, monkeypatch):
    """Cut short, a file has lost its seal; shorter than its HDF5 superblock's end-of-file
    address, it is refused as HDF5 would refuse it, without a probe."""
    path = tmp_path / "results.h5"
    write_run(path)
    whole = path.stat().st_size - seal.LENGTH
    path.write_bytes(path.read_bytes()[:-1000])
    monkeypatch.setattr(subprocess, "run", None)  # a probe would raise a TypeError
    with pytest.raises(
        InputError,
        match=f"^{path}: holds {whole + seal.LENGTH - 1000} bytes, its HDF5 superblock says {whole}: ",
    ):
        Results(path)


def test_a_sealed_file_that_hangs_hdf5_is_refused_at_once(tmp_path):
    """The damage that made HDF5 loop forever is refused by the seal, without a probe."""
    path = tmp_path / "results.h5"
    write_run(path)
    damage_global_heap(path)
    message, seconds = read_elsewhere(path)
    assert message.startswith(f"{path}: its bytes do not match its seal"), message
    assert seconds < START_S


def test_a_file_without_a_seal_that_hangs_hdf5_is_refused_within_the_time_limit(tmp_path):
    """The probe does not answer in its time limit: killed, and the file refused as damaged."""
    path = tmp_path / "results.h5"
    write_run(path)
    without_seal(path)
    damage_global_heap(path)
    message, seconds = read_elsewhere(path)
    limit = PROBE_S + path.stat().st_size / 50e6  # hdf5_probe.BYTES_PER_S
    assert (
        message
        == f"{path}: HDF5 did not finish reading it in {limit:.0f} s: the file is damaged; it is not used"
    )
    assert PROBE_S <= seconds < PROBE_S + START_S


def test_a_file_left_by_a_killed_writer_is_read_and_continued(tmp_path):
    """SIGKILL while writing leaves a file without a seal: it is read through the probe, and a
    restart continues it (truncation and appends) and seals it again."""
    path = tmp_path / "results.h5"
    code = (
        f"import os, signal, sys; sys.path.insert(0, {str(Path(peridyn.__file__).parents[1])!r})\n"
        "import numpy as np\nfrom peridyn.io.hdf5 import HDF5Writer\n"
        f"h5 = HDF5Writer(sys.argv[1], np.zeros(({N}, 3)), np.ones({N}), {{}})\n"
        f"h5.create_series('u', ({N}, 3))\n"
        f"for step in range(4):\n    h5.append('u', step, step * 1e-7, np.full(({N}, 3), step))\n"
        "os.kill(os.getpid(), signal.SIGKILL)\n"
    )
    killed = subprocess.run([sys.executable, "-c", code, str(path)], capture_output=True, text=True)
    assert killed.returncode == -signal.SIGKILL, killed.stderr
    assert seal.read_seal(path) is None
    assert Results(path).steps("u").tolist() == [0, 1, 2, 3]  # through the probe
    with HDF5Writer(path, np.zeros((N, 3)), np.ones(N), {}, mode="a") as h5:
        h5.truncate(1)
        h5.append("u", 2, 2e-7, np.full((N, 3), 7.0))
    assert seal.read_seal(path) is not None
    steps, _, u = Results(path).series("u")
    assert steps.tolist() == [0, 1, 2] and u[2].tolist() == np.full((N, 3), 7.0).tolist()


def test_a_sealed_file_continued_is_unsealed_while_written(tmp_path):
    path = tmp_path / "results.h5"
    write_run(path)
    rng = np.random.default_rng(3)
    with HDF5Writer(path, rng.random((N, 3)), np.full(N, 1e-9), {}, mode="a") as h5:
        assert seal.read_seal(path) is None  # a kill now leaves no seal that could be stale
        h5.append("u", 9, 9e-7, np.ones((N, 3)))
    assert seal.read_seal(path) is not None
    assert Results(path).steps("u").tolist() == [0, 1, 2, 3, 4, 5, 9]


def test_a_file_written_before_seals_is_read_and_sealed_when_continued(tmp_path):
    path = tmp_path / "results.h5"
    write_run(path)
    without_seal(path)
    assert Results(path).steps("u").tolist() == [0, 1, 2, 3, 4, 5]  # through the probe
    rng = np.random.default_rng(3)
    with HDF5Writer(path, rng.random((N, 3)), np.full(N, 1e-9), {}, mode="a") as h5:
        h5.append("u", 9, 9e-7, np.ones((N, 3)))
    assert seal.read_seal(path) is not None


def test_a_checkpoint_left_without_a_seal_and_damaged_is_refused(tmp_path):
    path = tmp_path / "checkpoint.h5"
    meta = {"case_hash": "abc", "case": "{}", "dt": 1e-7, "version": "1.0"}
    zeros = np.zeros((N, 3))
    save_checkpoint(path, State(zeros, zeros, zeros, 0.0, 0), np.ones(4, dtype=bool), meta)
    without_seal(path)
    damage = bytearray(path.read_bytes())
    damage[:8] = b"\xff" * 8  # HDF5's signature gone: no superblock
    path.write_bytes(bytes(damage))
    with pytest.raises(
        InputError,
        match=f"^{path}: not a readable HDF5 file \\(no HDF5 signature\\): damaged or not HDF5; it is not",
    ):
        load_checkpoint(path, N, 4, meta)


def test_each_version_of_a_file_is_checked_once(tmp_path, monkeypatch):
    path = tmp_path / "results.h5"
    write_run(path)
    seal._checked.clear()  # as in a new process
    reads = []
    crc = seal.crc_of
    monkeypatch.setattr(seal, "crc_of", lambda p, size: reads.append(p) or crc(p, size))
    Results(path).series("u")
    Results(path).steps("u")
    assert len(reads) == 1
    os.utime(path, ns=(0, 0))  # another version (its modification time)
    Results(path)
    assert len(reads) == 2


def test_a_bad_probe_time_limit_is_refused(tmp_path, monkeypatch):
    monkeypatch.setenv("PERIDYN_PROBE_SECONDS", "soon")
    path = tmp_path / "results.h5"
    write_run(path)
    without_seal(path)
    with pytest.raises(InputError, match="PERIDYN_PROBE_SECONDS must be a number of seconds, got 'soon'"):
        Results(path)


def test_a_pipe_is_refused_without_waiting_for_a_writer(tmp_path):
    path = tmp_path / "results.h5"
    os.mkfifo(path)  # opening it to read would wait for a writer forever
    with pytest.raises(InputError, match=f"^{path}: not a regular file"):
        Results(path)
