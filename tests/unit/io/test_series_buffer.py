"""Tests of block appends (``HDF5Writer.append_block``) and of the bounded record buffer in
front of the writer (``peridyn.io.series_buffer``), which the recorder uses: the facts come
from their docstrings (same file as record-by-record appends, nothing written between
flushes, at most ``max_bytes`` or ``max_records`` held per series)."""

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import h5py
import numpy as np
import pytest

import peridyn
from peridyn.errors import InputError
from peridyn.io.hdf5 import HDF5Writer
from peridyn.io.recorder import rows_of
from peridyn.io.results import Results
from peridyn.io.series_buffer import SeriesBuffer

N = 6


@pytest.fixture
def geometry():
    rng = np.random.default_rng(3)
    return rng.random((N, 3)), np.full(N, 1e-9)


def records(k, seed=0):
    """k float64 records (N, 3) with values that float32 rounds (to test the cast)."""
    return np.random.default_rng(seed).normal(scale=1e-6, size=(k, N, 3))


def _series(path, name):
    with h5py.File(path, "r") as f:
        group = f["series"][name]
        return group["step"][:], group["time"][:], group["data"][:]


@pytest.mark.parametrize("dtype", ["float64", "float32"])
def test_block_append_writes_what_single_appends_write(tmp_path, geometry, dtype):
    """``append_block`` of several records writes the file that one ``append`` per record writes: the
    same stored values and dtypes (float32: the same cast), compared exactly."""
    values = records(5)
    steps, times = [0, 2, 3, 7, 9], [0.0, 2e-7, 3e-7, 7e-7, 9e-7]
    for name, blocks in (("single", [[i] for i in range(5)]), ("block", [[0, 1], [2, 3, 4]])):
        with HDF5Writer(tmp_path / f"{name}.h5", *geometry, {}) as out:
            out.create_series("u", (N, 3), dtype)
            for rows in blocks:
                if name == "single":
                    out.append("u", steps[rows[0]], times[rows[0]], values[rows[0]])
                else:
                    out.append_block("u", [steps[i] for i in rows], [times[i] for i in rows], values[rows])
    single, block = _series(tmp_path / "single.h5", "u"), _series(tmp_path / "block.h5", "u")
    for a, b in zip(single, block, strict=True):
        assert a.dtype == b.dtype
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(block[2], values.astype(dtype))


def test_block_append_checks_every_record_and_writes_nothing_on_error(tmp_path, geometry):
    with HDF5Writer(tmp_path / "run.h5", *geometry, {}) as out:
        out.create_series("u", (N, 3))
        out.append("u", 4, 4e-7, records(1)[0])
        with pytest.raises(InputError, match="step 6 does not exceed the last recorded step 6"):
            out.append_block("u", [5, 6, 6], [5e-7, 6e-7, 6e-7], records(3))
        with pytest.raises(InputError, match="step 3 does not exceed the last recorded step 4"):
            out.append_block("u", [3], [3e-7], records(1))
        with pytest.raises(InputError, match="time must be a finite number"):
            out.append_block("u", [5, 6], [5e-7, np.nan], records(2))
        with pytest.raises(InputError, match=r"record has shape \(6, 2\), expected \(6, 3\)"):
            out.append_block("u", [5], [5e-7], np.zeros((1, N, 2)))
        with pytest.raises(InputError, match="needs as many times and records"):
            out.append_block("u", [5, 6], [5e-7], records(2))
    assert Results(tmp_path / "run.h5").series("u")[0].tolist() == [4]


def test_buffered_records_equal_direct_appends(tmp_path, geometry):
    """Records held by a ``SeriesBuffer`` and written in blocks give the file of direct appends: the
    same stored values, compared exactly."""
    values = records(11, seed=1)
    for name in ("direct", "buffered"):
        with HDF5Writer(tmp_path / f"{name}.h5", *geometry, {}, flush_every=None) as out:
            out.create_series("u", (N, 3), "float32")
            out.create_series("s", (2,))
            target = out if name == "direct" else SeriesBuffer(out, max_bytes=values[0].nbytes * 4)
            for step, value in enumerate(values):
                target.append("u", step, step * 1e-7, value)
                target.append("s", step, step * 1e-7, value[0, :2])
            if name == "buffered":
                target.flush()
    for series in ("u", "s"):
        direct, buffered = _series(tmp_path / "direct.h5", series), _series(tmp_path / "buffered.h5", series)
        for a, b in zip(direct, buffered, strict=True):
            np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("dtype", ["float64", "float32"])
def test_records_given_by_rows_are_those_rows(tmp_path, geometry, dtype):
    """``append(..., values, rows)`` holds ``values[rows]`` (an index array is taken straight
    into the buffer, a slice is viewed), cast to the series' dtype: the file of direct appends
    of ``values[rows]``. Stored values: compared exactly."""
    fields = records(10, seed=2).reshape(5, 2 * N, 3)  # five records of 2 N points
    picks = {"spread": np.array([7, 0, 11, 3, 3, 5]), "layer": slice(1, 2 * N, 2)}
    for name in ("direct", "buffered"):
        with HDF5Writer(tmp_path / f"{name}.h5", *geometry, {}, flush_every=None) as out:
            for series in picks:
                out.create_series(series, (N, 3), dtype)
            target = out if name == "direct" else SeriesBuffer(out, max_records=2)
            for step, field in enumerate(fields):
                for series, rows in picks.items():
                    if name == "direct":
                        out.append(series, step, step * 1e-7, field[rows])
                    else:
                        target.append(series, step, step * 1e-7, field, rows)
            if name == "buffered":
                target.flush()
    for series in picks:
        direct, buffered = _series(tmp_path / "direct.h5", series), _series(tmp_path / "buffered.h5", series)
        for a, b in zip(direct, buffered, strict=True):
            assert a.dtype == b.dtype
            np.testing.assert_array_equal(a, b)


def test_buffer_holds_at_most_max_bytes_or_max_records_per_series(tmp_path, geometry):
    record_bytes = records(1)[0].nbytes
    with HDF5Writer(tmp_path / "run.h5", *geometry, {}, flush_every=None) as out:
        out.create_series("u", (N, 3))
        by_bytes = SeriesBuffer(out, max_bytes=3 * record_bytes + 1)
        for step in range(7):
            by_bytes.append("u", step, step * 1e-7, records(1, step)[0])
            assert by_bytes.held == (step + 1) % 3  # written at every third record
        by_bytes.flush()
        assert by_bytes.held == 0
        out.create_series("s", ())
        by_count = SeriesBuffer(out, max_records=4)
        for step in range(6):
            by_count.append("s", step, step * 1e-7, float(step))
        assert by_count.held == 2
    with pytest.raises(InputError, match="must be positive"):
        SeriesBuffer(out, max_bytes=0)


def test_a_killed_process_keeps_the_flushed_blocks_only(tmp_path):
    """Records held in memory die with the process; the blocks written before stay readable. Stored
    values: compared exactly."""
    path = tmp_path / "run.h5"
    script = textwrap.dedent(
        f"""
        import os
        import numpy as np
        from peridyn.io.hdf5 import HDF5Writer
        from peridyn.io.series_buffer import SeriesBuffer
        out = HDF5Writer({str(path)!r}, np.zeros((4, 3)), np.ones(4), {{}}, flush_every=None)
        out.create_series("u", (4, 3))
        buffer = SeriesBuffer(out, max_records=3)
        for step in range(8):
            buffer.append("u", step, step * 1e-7, np.full((4, 3), step, dtype=float))
        os._exit(1)
        """
    )
    env = dict(os.environ, PYTHONPATH=str(Path(peridyn.__file__).parents[1]))
    done = subprocess.run([sys.executable, "-c", script], timeout=60, env=env)
    assert done.returncode == 1
    steps, _, data = Results(path).series("u")
    assert steps.tolist() == list(range(6))  # two blocks of three; steps 6 and 7 were held
    np.testing.assert_array_equal(data[5], np.full((4, 3), 5.0))


@pytest.mark.parametrize(
    "index, is_slice",
    [
        ([2, 5, 8, 11], True),
        ([4, 5, 6], True),
        ([7], False),
        ([], False),
        ([1, 3, 4], False),
        ([5, 3, 1], False),
    ],
)
def test_rows_of_gives_the_rows_of_the_index(index, is_slice):
    """The recorder's plane rows: a slice for a layer's arithmetic progression, the same rows."""
    u = np.arange(36.0).reshape(12, 3)
    rows = rows_of(np.array(index, dtype=np.int64))
    assert isinstance(rows, slice) is is_slice
    np.testing.assert_array_equal(u[rows], u[np.array(index, dtype=np.int64)])
