"""Tests of the incremental HDF5 results writer (read back with ``peridyn.io.results``)."""

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
from peridyn.io.results import Results

N = 10


@pytest.fixture
def geometry():
    rng = np.random.default_rng(1)
    return rng.random((N, 2)), np.full(N, 1e-6)


def record(step):
    return np.arange(N * 2, dtype=np.float64).reshape(N, 2) * 0.5 + step


def write_run(path, geometry, steps, mode="w", **kwargs):
    with HDF5Writer(path, *geometry, {"case": "bar"}, mode=mode, **kwargs) as out:
        out.create_series("u", (N, 2))
        for step in steps:
            out.append("u", step, step * 1e-7, record(step))


def test_geometry_and_series_round_trip(tmp_path, geometry):
    """Series (steps, times, records) and geometry written to results.h5 read back as written, dtypes
    included: stored values, compared exactly."""
    path = tmp_path / "run.h5"
    write_run(path, geometry, range(5))
    steps, times, data = Results(path).series("u")
    np.testing.assert_array_equal(steps, np.arange(5))
    np.testing.assert_array_equal(times, np.arange(5) * 1e-7)
    np.testing.assert_array_equal(data, np.stack([record(s) for s in range(5)]))
    assert (steps.dtype, times.dtype, data.dtype) == (np.int64, np.float64, np.float64)
    np.testing.assert_array_equal(Results(path).array("/geometry/points"), geometry[0])
    np.testing.assert_array_equal(Results(path).array("geometry/volumes"), geometry[1])


def test_series_layout_is_resizable_and_chunked_along_time(tmp_path, geometry):
    path = tmp_path / "run.h5"
    with HDF5Writer(path, *geometry, {}) as out:
        out.create_series("u", (N, 2), attrs={"units": "m"})
        out.create_series("big", (300_000,), dtype="float32")
    with h5py.File(path) as f:
        data = f["series/u/data"]
        assert data.shape == (0, N, 2) and data.maxshape == (None, N, 2)
        assert data.chunks[1:] == (N, 2)
        assert 0.5 * 2**20 < data.chunks[0] * N * 2 * 8 <= 2**20
        assert f["series/big/data"].chunks == (1, 300_000)
        assert f["series/u/time"].dtype == np.float64
        assert f["series/u/step"].dtype == np.int64
        assert f["series/u"].attrs["units"] == "m"


def test_scalar_series(tmp_path, geometry):
    path = tmp_path / "run.h5"
    with HDF5Writer(path, *geometry, {}) as out:
        out.create_series("energy", ())
        out.append("energy", 3, 0.5, 2.25)
    steps, times, data = Results(path).series("energy")
    assert steps.tolist() == [3] and times.tolist() == [0.5] and data.tolist() == [2.25]


def test_float32_storage(tmp_path, geometry):
    """A float32 series stores its records cast to float32 (one correctly rounded conversion, as
    ``astype``): compared exactly."""
    path = tmp_path / "run.h5"
    values = np.linspace(0, 1, N * 2).reshape(N, 2)
    with HDF5Writer(path, *geometry, {}) as out:
        out.create_series("plane", (N, 2), dtype="float32")
        out.append("plane", 0, 0.0, values)
    _, _, data = Results(path).series("plane")
    assert data.dtype == np.float32
    np.testing.assert_array_equal(data[0], values.astype(np.float32))


def test_provenance_round_trip(tmp_path, geometry):
    """Provenance (numbers, booleans, None, nested mappings, lists and an array) reads back as written,
    types included: stored values, compared exactly."""
    path = tmp_path / "run.h5"
    provenance = {
        "version": "0.1.0",
        "seed": 42,
        "dt": 1.5e-8,
        "converged": True,
        "config": {"material": {"E": 70e9, "nu": 0.33}, "probes": [1, 2]},
        "tags": ["a", "b"],
        "restart_of": None,
        "horizon_factors": np.array([3.0, 4.0]),
    }
    with HDF5Writer(path, *geometry, provenance):
        pass
    read = Results(path).provenance()
    np.testing.assert_array_equal(read.pop("horizon_factors"), [3.0, 4.0])
    provenance.pop("horizon_factors")
    assert read == provenance
    assert type(read["seed"]) is int and type(read["converged"]) is bool


def test_provenance_rejects_unstorable_value(tmp_path, geometry):
    with pytest.raises(InputError, match="'when'.*has type object"):
        HDF5Writer(tmp_path / "run.h5", *geometry, {"when": object()})


def test_chunked_reading_equals_whole_reading(tmp_path, geometry):
    """A series read in chunks of 5 records is the series read whole: the same stored values, compared
    exactly."""
    path = tmp_path / "run.h5"
    write_run(path, geometry, range(0, 23, 1))
    _, times, data = Results(path).series("u")
    chunks = list(Results(path).iter_series("u", 5))
    assert [len(t) for t, _ in chunks] == [5, 5, 5, 5, 3]
    np.testing.assert_array_equal(np.concatenate([t for t, _ in chunks]), times)
    np.testing.assert_array_equal(np.concatenate([d for _, d in chunks]), data)


def test_data_written_before_an_exception_is_readable(tmp_path, geometry):
    """Records appended before an exception inside the writer's ``with`` block are readable after it, as
    written: stored values, compared exactly."""
    path = tmp_path / "run.h5"
    with pytest.raises(RuntimeError, match="solver blew up"):
        with HDF5Writer(path, *geometry, {}) as out:
            out.create_series("u", (N, 2))
            out.append("u", 0, 0.0, record(0))
            out.append("u", 1, 1e-7, record(1))
            raise RuntimeError("solver blew up")
    steps, _, data = Results(path).series("u")
    assert steps.tolist() == [0, 1]
    np.testing.assert_array_equal(data[1], record(1))


def test_data_survives_a_process_killed_without_closing(tmp_path):
    """Records appended by a process that exits without closing the file are readable, as written
    (stored values, compared exactly), and so is the provenance."""
    path = tmp_path / "run.h5"
    script = textwrap.dedent(
        f"""
        import os
        import numpy as np
        from peridyn.io.hdf5 import HDF5Writer
        out = HDF5Writer({str(path)!r}, np.zeros((4, 3)), np.ones(4), {{"case": "crash"}})
        out.create_series("u", (4, 3))
        for step in range(3):
            out.append("u", step, step * 1e-7, np.full((4, 3), step, dtype=float))
        os._exit(1)
        """
    )
    env = dict(os.environ, PYTHONPATH=str(Path(peridyn.__file__).parents[1]))
    done = subprocess.run([sys.executable, "-c", script], timeout=60, env=env)
    assert done.returncode == 1
    steps, _, data = Results(path).series("u")
    assert steps.tolist() == [0, 1, 2]
    np.testing.assert_array_equal(data[2], np.full((4, 3), 2.0))
    assert Results(path).provenance() == {"case": "crash"}


def test_append_mode_continues_series(tmp_path, geometry):
    """A writer in mode "a" continues the series after its last record; the records read back as written
    (stored values, compared exactly)."""
    path = tmp_path / "run.h5"
    write_run(path, geometry, range(3))
    write_run(path, geometry, range(3, 5), mode="a")
    steps, _, data = Results(path).series("u")
    assert steps.tolist() == [0, 1, 2, 3, 4]
    np.testing.assert_array_equal(data[4], record(4))


def test_truncate_drops_records_after_checkpoint_step(tmp_path, geometry):
    """``truncate`` drops the records after the checkpoint step in every series, the records appended
    after it follow, and the provenance is merged; stored values, compared exactly."""
    path = tmp_path / "run.h5"
    with HDF5Writer(path, *geometry, {"case": "bar"}) as out:
        out.create_series("u", (N, 2))
        out.create_series("e", ())
        for step in range(0, 50, 10):
            out.append("u", step, step * 1e-7, record(step))
            out.append("e", step, step * 1e-7, float(step))
    with HDF5Writer(path, *geometry, {"restarted_at": 25}, mode="a") as out:
        out.truncate(25)
        out.append("u", 30, 30e-7, record(30) + 1)
    steps, times, data = Results(path).series("u")
    assert steps.tolist() == [0, 10, 20, 30]
    np.testing.assert_array_equal(times, [0, 10e-7, 20e-7, 30e-7])
    np.testing.assert_array_equal(data[3], record(30) + 1)
    assert Results(path).series("e")[0].tolist() == [0, 10, 20]
    assert Results(path).provenance() == {"case": "bar", "restarted_at": 25}


def test_append_rejects_repeated_step(tmp_path, geometry):
    path = tmp_path / "run.h5"
    write_run(path, geometry, range(3))
    with HDF5Writer(path, *geometry, {}, mode="a") as out:
        with pytest.raises(InputError, match="step 2 does not exceed the last recorded step 2"):
            out.append("u", 2, 0.0, record(2))


def test_append_mode_recreating_a_series_reuses_it(tmp_path, geometry):
    path = tmp_path / "run.h5"
    write_run(path, geometry, range(2))
    with HDF5Writer(path, *geometry, {}, mode="a") as out:
        out.create_series("u", (N, 2))
        with pytest.raises(InputError, match="already exists with record shape"):
            out.create_series("u", (N, 3))
    assert Results(path).series("u")[0].tolist() == [0, 1]


def test_append_mode_rejects_other_geometry(tmp_path, geometry):
    path = tmp_path / "run.h5"
    write_run(path, geometry, range(1))
    with pytest.raises(InputError, match="differ from the geometry"):
        HDF5Writer(path, geometry[0] * 2, geometry[1], {}, mode="a")


def test_append_rejects_wrong_record_shape_and_unknown_series(tmp_path, geometry):
    with HDF5Writer(tmp_path / "run.h5", *geometry, {}) as out:
        out.create_series("displacement", (N, 2))
        with pytest.raises(InputError, match=r"record has shape \(10, 3\), expected \(10, 2\)"):
            out.append("displacement", 0, 0.0, np.zeros((N, 3)))
        with pytest.raises(InputError, match="did you mean 'displacement'"):
            out.append("displacment", 0, 0.0, np.zeros((N, 2)))


def test_flush_every_batches_flushes(tmp_path, geometry):
    path = tmp_path / "run.h5"
    write_run(path, geometry, range(7), flush_every=3)
    assert Results(path).series("u")[0].tolist() == list(range(7))


def test_write_array_replaces_and_keeps_attrs(tmp_path, geometry):
    """``write_array`` replaces an array and stores its attributes, and refuses paths outside its
    groups; the array reads back as written (stored values, compared exactly)."""
    path = tmp_path / "run.h5"
    with HDF5Writer(path, *geometry, {}) as out:
        out.write_array("final/damage", np.zeros(N))
        out.write_array("/final/damage", np.linspace(0, 1, N), attrs={"units": "1"})
        with pytest.raises(InputError, match="outside /geometry, /series"):
            out.write_array("geometry/points", np.zeros((N, 2)))
    np.testing.assert_array_equal(Results(path).array("final/damage"), np.linspace(0, 1, N))
    with h5py.File(path) as f:
        assert f["final/damage"].attrs["units"] == "1"


def test_readers_name_missing_file_and_series(tmp_path, geometry):
    with pytest.raises(InputError, match="nothing.h5.*does not exist"):
        Results(tmp_path / "nothing.h5").series("u")
    path = tmp_path / "run.h5"
    write_run(path, geometry, range(1))
    with pytest.raises(InputError, match=r"no series 'uu'; it has \['u'\]"):
        Results(path).series("uu")
    with pytest.raises(InputError, match="no dataset 'final/damage'"):
        Results(path).array("final/damage")
    with pytest.raises(InputError, match="chunk_records must be a positive integer"):
        next(Results(path).iter_series("u", 0))


def test_append_mode_drops_a_half_written_record(tmp_path, geometry):
    """A record whose data and time were written but not its step (a crash in between) is not read, and
    appending replaces it; the records read back as written (stored values, compared exactly)."""
    path = tmp_path / "run.h5"
    write_run(path, geometry, range(3))
    with h5py.File(path, "a") as f:  # a crash after writing data and time, before step
        for key in ("data", "time"):
            f["series/u"][key].resize(4, axis=0)
    assert Results(path).series("u")[0].tolist() == [0, 1, 2]
    write_run(path, geometry, [3], mode="a")
    steps, _, data = Results(path).series("u")
    assert steps.tolist() == [0, 1, 2, 3]
    np.testing.assert_array_equal(data[3], record(3))


def test_writer_names_a_file_it_cannot_create(tmp_path, geometry):
    with pytest.raises(InputError, match="cannot open results file .*missing_dir"):
        HDF5Writer(tmp_path / "missing_dir" / "run.h5", *geometry, {})
