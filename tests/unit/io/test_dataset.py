"""The sweep dataset (peridyn.io.dataset, issue 21 item 2): what is written is read back equal,
with the column types and the NaN padding its docstring promises; a modal summary flattens to
frequencies by mode type and order (peridyn.jobs.sweep.flatten_summary)."""

from __future__ import annotations

import importlib.util

import numpy as np
import pytest

from peridyn.errors import InputError
from peridyn.io.dataset import SeriesColumn, build_dataset, load_sweep, write_dataset
from peridyn.jobs.sweep import flatten_summary, summary_unit

#: The dataset tests need the sweep extra (pip install 'peridyn[sweep]').
needs_sweep_extra = pytest.mark.skipif(
    not all(importlib.util.find_spec(m) for m in ("xarray", "h5netcdf")), reason="needs the sweep extra"
)


@needs_sweep_extra
def test_dataset_round_trip_with_types_and_padding(tmp_path):
    """A sweep dataset written to netCDF and read back keeps its coordinates, table columns (types
    included, a missing number as NaN), series padded with NaN to the longest, and attributes: stored
    values, compared exactly."""
    rng = np.random.default_rng(0)
    a, b = rng.normal(size=(5, 2, 3)), rng.normal(size=(3, 2, 3))
    ds = build_dataset(
        coords={
            "run_id": ["r0", "r1", "r2"],
            "material.E": [1e9, 2e9, 3e9],
            "kind": ["hole", "crack", "hole"],
        },
        table={
            "steps": [10, 20, 30],
            "max_damage": [0.5, None, 0.25],
            "status": ["complete", "failed: x", "pending"],
            "flag": [True, False, True],
        },
        series={
            "sensor_u": SeriesColumn(
                times=[np.arange(5) * 1e-7, None, np.arange(3) * 1e-7],
                values=[a, None, b],
                entry_names=["s1", "s2"],
            )
        },
        attrs={"sweep": "t"},
    )
    path = write_dataset(ds, tmp_path / "dataset.nc")
    assert not list(tmp_path.glob("*.tmp"))  # written under a temporary name, then renamed
    back = load_sweep(path)
    assert back["steps"].dtype == np.int64 and back["flag"].dtype == bool
    np.testing.assert_array_equal(back["max_damage"].values, [0.5, np.nan, 0.25])
    assert list(back["status"].values) == ["complete", "failed: x", "pending"]
    assert list(back["kind"].values) == ["hole", "crack", "hole"]
    assert back["sensor_u"].shape == (3, 5, 2, 3)
    np.testing.assert_array_equal(back["sensor_u"].values[0], a)
    np.testing.assert_array_equal(back["sensor_u"].values[2, :3], b)
    assert np.isnan(back["sensor_u"].values[2, 3:]).all() and np.isnan(back["sensor_u"].values[1]).all()
    np.testing.assert_array_equal(back["sensor_u_time"].values[2], [0, 1e-7, 2e-7, np.nan, np.nan])
    assert list(back["sensor_u_axis1"].values) == ["s1", "s2"]
    assert back.attrs["sweep"] == "t"


@needs_sweep_extra
def test_series_of_different_shapes_are_refused():
    column = SeriesColumn(times=[np.zeros(2), np.zeros(2)], values=[np.zeros((2, 3)), np.zeros((2, 4))])
    with pytest.raises(InputError, match="different shapes"):
        build_dataset({"run_id": ["a", "b"]}, {}, {"s": column}, {})


@needs_sweep_extra
def test_a_missing_dataset_is_named(tmp_path):
    with pytest.raises(InputError, match="does not exist"):
        load_sweep(tmp_path / "none.nc")


def test_modal_summary_flattens_to_frequencies_by_type_and_order():
    summary = {
        "kind": "modal",
        "seconds": 1.0,
        "points": 100,
        "modes": [
            {"index": 0, "type": "rigid", "order": 0, "frequency_hz": 0.001},
            {"index": 6, "type": "bending", "order": 1, "frequency_hz": 1579.8},
            {"index": 7, "type": "torsional", "order": 1, "frequency_hz": 1933.1},
            {"index": 8, "type": "bending", "order": 1, "frequency_hz": 2000.0},
        ],
        "kxky": {"110000": {"A0": 777.0, "S0": None}},
        "plots": ["a.png"],
    }
    assert flatten_summary(summary) == {
        "points": 100,
        "frequency_hz.bending.1": 1579.8,
        "frequency_hz.torsional.1": 1933.1,
        "frequency_hz.bending.1.8": 2000.0,
        "kxky.110000.A0": 777.0,
        "kxky.110000.S0": None,
    }


@needs_sweep_extra
def test_every_variable_has_a_long_name_and_every_number_a_unit(tmp_path):
    """The dataset says what each variable is: ``about`` for the columns, the results file's
    units for a series, seconds for the times (written and read back)."""
    column = SeriesColumn(
        times=[np.arange(2) * 1e-7], values=[np.zeros((2, 1, 3))], entry_names=["s1"],
        about={"units": "m", "long_name": "displacement at the sensors"},
    )  # fmt: skip
    ds = build_dataset(
        {"run_id": ["a"], "material.E": [2e11]},
        {"status": ["complete"], "strain_energy_j": [1.5], "steps": [10]},
        {"sensor_u": column},
        {},
        reference={"sensor_u": (np.arange(2) * 1e-7, np.zeros((2, 1, 3)))},
        about={
            "run_id": (None, "run"),
            "material.E": ("Pa", "parameter material.E"),
            "status": (None, "status"),
        },
    )
    back = load_sweep(write_dataset(ds, tmp_path / "dataset.nc"))
    for name, variable in back.variables.items():
        assert "long_name" in variable.attrs, name
        if variable.dtype.kind in "biuf":
            assert "units" in variable.attrs, name
    assert back["material.E"].attrs["units"] == "Pa" and back["sensor_u"].attrs["units"] == "m"
    assert back["sensor_u_time"].attrs["units"] == "s" and back["reference_sensor_u"].attrs["units"] == "m"
    assert back["steps"].attrs == {"units": "1", "long_name": "steps"}
    assert "units" not in back["status"].attrs


@pytest.mark.parametrize(
    ("key", "unit"),
    [("strain_energy_j", "J"), ("time_s", "s"), ("frequency_hz.bending.1", "Hz"), ("crack_length_m", "m"),
     ("fk_peaks_rad_m.S0", "rad/m"), ("max_damage", "1"), ("mac.1st_bending", "1")],
)  # fmt: skip
def test_summary_units_follow_the_key_suffixes(key, unit):
    assert summary_unit(key) == unit
