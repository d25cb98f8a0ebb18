"""Tests of the results reader: round trip with the writer, the record-count guard, the schema."""

import h5py
import numpy as np
import pytest

from peridyn.errors import InputError
from peridyn.io.hdf5 import SCHEMA_ATTR, SCHEMA_VERSION, HDF5Writer
from peridyn.io.results import Results

N = 6


@pytest.fixture
def path(tmp_path):
    """A results file with a series of 4 records, series attributes, an array and a summary."""
    path = tmp_path / "results.h5"
    points = np.column_stack([np.arange(N) * 1e-3, np.zeros(N)])
    with HDF5Writer(path, points, np.full(N, 1e-9), {"case": "bar"}) as out:
        out.create_series("u", (N, 2), attrs={"names": ["left", "right"], "points": [0, 5]})
        for step in range(4):
            out.append("u", step, step * 1e-8, np.full((N, 2), float(step)))
        out.write_array("final/damage", np.linspace(0.0, 1.0, N))
        out.write_summary({"points": N, "bonds": np.int64(10), "strain_energy_j": np.float64(0.5)})
    return path


def test_round_trip_of_everything_the_writer_stores(path):
    """What the writer was given comes back: series, attributes, arrays, provenance, summary
    (numpy scalars stored as numbers), and the schema version of this peridyn. Stored values read back:
    compared exactly."""
    results = Results(path)
    assert results.schema_version == SCHEMA_VERSION
    steps, times, data = results.series("u")
    assert steps.tolist() == [0, 1, 2, 3]
    np.testing.assert_array_equal(times, np.arange(4) * 1e-8)
    np.testing.assert_array_equal(data[:, 0, 0], [0.0, 1.0, 2.0, 3.0])
    assert results.series_names() == ["u"] and results.n_records("u") == 4
    assert results.series_attrs("u") == {"names": ["left", "right"], "points": [0, 5]}
    np.testing.assert_array_equal(results.array("final/damage"), np.linspace(0.0, 1.0, N))
    assert results.has("final/damage") and not results.has("final/u") and not results.has("series")
    assert results.provenance() == {"case": "bar"}  # the schema attribute is not provenance
    assert results.summary() == {"points": N, "bonds": 10, "strain_energy_j": 0.5}


def test_a_half_written_record_is_not_read(path):
    """The record-count guard: a crash after writing a record's data and time but before its
    step leaves those two one longer; every read stops at the last complete record."""
    with h5py.File(path, "a") as f:
        for key in ("data", "time"):
            f["series/u"][key].resize(5, axis=0)
    results = Results(path)
    assert results.n_records("u") == 4
    steps, times, data = results.series("u")
    assert len(steps) == len(times) == len(data) == 4
    assert sum(len(t) for t, _ in results.iter_series("u", 3)) == 4


def test_a_file_of_a_newer_schema_is_refused_with_the_versions(path):
    """A results file written by a newer peridyn may hold keys of other meanings: the reader
    and the append-mode writer refuse it and say which versions."""
    with h5py.File(path, "a") as f:
        f.attrs[SCHEMA_ATTR] = SCHEMA_VERSION + 1
    message = (
        f"written with results schema {SCHEMA_VERSION + 1}, newer than the schema {SCHEMA_VERSION} "
        "this peridyn reads: upgrade peridyn"
    )
    with pytest.raises(InputError, match=message):
        Results(path)
    with pytest.raises(InputError, match=message):
        HDF5Writer(path, np.zeros((N, 2)), np.ones(N), {}, mode="a")


def test_a_file_without_a_schema_reads_as_schema_1(path):
    """Files written before the version was recorded have no attribute: schema 1."""
    with h5py.File(path, "a") as f:
        del f.attrs[SCHEMA_ATTR]
    assert Results(path).schema_version == 1


def test_the_schema_name_is_reserved_and_bad_files_are_named(tmp_path, path):
    with pytest.raises(InputError, match="'schema_version' is reserved"):
        HDF5Writer(tmp_path / "other.h5", np.zeros((N, 2)), np.ones(N), {SCHEMA_ATTR: 7})
    text = tmp_path / "notes.h5"
    text.write_text("not HDF5")
    with pytest.raises(InputError, match="notes.h5: not a readable HDF5 file"):
        Results(text)
    with h5py.File(path, "a") as f:
        del f["summary"]
    with pytest.raises(InputError, match="no summary"):
        Results(path).summary()
