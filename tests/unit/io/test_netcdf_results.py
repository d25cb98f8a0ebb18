"""Results files follow netCDF-4 conventions (schema 3, ``peridyn.io.netcdf``): netCDF readers
(xarray through h5netcdf) see named dimensions, time and component coordinates and units; files
of schema 2 still read, and a schema-2 file continued stays unlabelled; VTU snapshots carry their
time and the points' volumes."""

import json
import xml.etree.ElementTree as ET
from pathlib import Path

import h5py
import meshio
import numpy as np
import pytest
import xarray as xr

from peridyn.cli import main
from peridyn.errors import InputError
from peridyn.io.hdf5 import SCHEMA_ATTR, HDF5Writer
from peridyn.io.integrity import verify_file
from peridyn.io.netcdf import write_root_view
from peridyn.io.results import Results

BAR = str(Path(__file__).resolve().parents[3] / "cases" / "bar_pulse.yaml")

#: A few explicit steps of the bar pulse on a coarse grid, with a snapshot: about a second.
SHORT = [
    "--set", "discretization.spacing=2.5e-3", "--set", "solver.time=2e-6",
    "--set", "output.snapshot_times=[1e-6]", "--set", "output.plots=false", "--no-progress",
]  # fmt: skip


@pytest.fixture(scope="module")
def bar_run(tmp_path_factory):
    """The output folder of the shortened bar pulse (sensors x50, x100, x150; line ``axis``)."""
    out = tmp_path_factory.mktemp("bar")
    assert main(["run", BAR, "-o", str(out), "--overwrite", *SHORT]) == 0
    return out


def test_every_group_of_a_run_opens_labelled_in_xarray(bar_run):
    """The whole file opens as a netCDF tree (h5netcdf refuses a dataset without dimension
    scales); each series has time (s) and its own coordinates, and the values are the file's."""
    path = bar_run / "results.h5"
    tree = xr.open_datatree(path, engine="h5netcdf")
    sensors = tree["series/sensor_u"].to_dataset()
    assert sensors["data"].dims == ("time", "sensor", "component")
    assert sensors["component"].values.tolist() == ["x", "y", "z"]
    assert sensors["sensor"].values.tolist() == ["x50", "x100", "x150"]
    assert sensors["data"].attrs["units"] == "m" and sensors["time"].attrs["units"] == "s"
    steps, times, u = Results(path).series("sensor_u")
    np.testing.assert_array_equal(sensors["time"].values, times)
    np.testing.assert_array_equal(sensors["data"].values, u)
    assert tree["series/sensor_v"]["data"].attrs["units"] == "m/s"
    assert tree["series/field_u"]["data"].dims == ("time", "point", "component")
    geometry = tree["geometry"].to_dataset()
    assert geometry["points"].dims == ("point", "coordinate")
    assert geometry["points"].attrs["units"] == "m" and geometry["volumes"].attrs["units"] == "m3"
    final = tree["final"].to_dataset()
    assert final["u"].dims == ("point", "component") and final["v"].attrs["units"] == "m/s"
    # one group on its own, as plain xarray opens it
    line = xr.open_dataset(path, group="series/line_axis")
    assert line["data"].dims == ("time", "point", "component") and line["data"].attrs["units"] == "m"


def test_the_root_opens_labelled_without_a_group(bar_run):
    """``xarray.open_dataset(path)`` with no group reads the sensors' displacement at the root:
    named dimensions, time (s) and step as coordinates of the records, sensor and component
    labels, units; the values are the series' (virtual datasets of it), and the whole file still
    opens as one tree (the root's records are ``record``, not each series' ``time``)."""
    path = bar_run / "results.h5"
    root = xr.open_dataset(path)
    assert root["sensor_u"].dims == ("record", "sensor", "component")
    assert root["sensor_u"].attrs["units"] == "m" and root["time"].attrs["units"] == "s"
    assert root["component"].values.tolist() == ["x", "y", "z"]
    assert root["sensor"].values.tolist() == ["x50", "x100", "x150"]
    steps, times, u = Results(path).series("sensor_u")
    np.testing.assert_array_equal(root["time"].values, times)
    np.testing.assert_array_equal(root["step"].values, steps)
    np.testing.assert_array_equal(root["sensor_u"].values, u)
    by_time = root.swap_dims(record="time")["sensor_u"]
    assert by_time.sel(time=times[-1], sensor="x50", component="x") == u[-1, 0, 0]
    assert set(xr.open_datatree(path, engine="h5netcdf").children) >= {"series", "geometry", "final"}


def test_a_root_axis_another_group_labels_otherwise_is_prefixed(tmp_path):
    """Without sensors the root shows the first series by name; its ``point`` axis (a line's
    3 points) would clash with the geometry's 5 points, which every group inherits from the
    root: it is ``line_a_point`` at the root, and the file opens as one tree."""
    path = tmp_path / "r.h5"
    with HDF5Writer(path, np.zeros((5, 3)), np.ones(5), {}) as out:
        out.create_series(
            "line_a", (3, 3), dims=("point", "component"), coords={"point": [0, 2, 4]}, units="m"
        )
        out.create_series("plane_b", (2, 3), dims=("point", "component"), units="m")
        out.append("line_a", 0, 0.0, np.ones((3, 3)))
        out.append("line_a", 4, 1e-6, 2 * np.ones((3, 3)))
    root = xr.open_dataset(path)
    assert root["line_a"].dims == ("record", "line_a_point", "component")
    assert root["line_a_point"].values.tolist() == [0, 2, 4]
    np.testing.assert_array_equal(root["time"].values, [0.0, 1e-6])
    xr.open_datatree(path, engine="h5netcdf")


def test_a_continued_file_shows_every_record_at_the_root(tmp_path):
    """A run continued from a checkpoint (``mode="a"``) drops the root's view when it opens the
    file and writes it again on closing, for all the records then; the file's checksums hold."""
    path = tmp_path / "r.h5"
    with HDF5Writer(path, np.zeros((2, 3)), np.ones(2), {}) as out:
        out.create_series("sensor_u", (1, 3), dims=("sensor", "component"), coords={"sensor": ["s"]})
        out.append("sensor_u", 0, 0.0, np.zeros((1, 3)))
        out.append("sensor_u", 1, 1e-7, np.ones((1, 3)))
    with HDF5Writer(path, np.zeros((2, 3)), np.ones(2), {}, mode="a") as out:
        out.truncate(0)
        out.append("sensor_u", 1, 1e-7, 3 * np.ones((1, 3)))
        out.append("sensor_u", 2, 2e-7, 4 * np.ones((1, 3)))
    root = xr.open_dataset(path)
    np.testing.assert_array_equal(root["step"].values, [0, 1, 2])
    np.testing.assert_array_equal(root["sensor_u"].values[:, 0, 0], [0.0, 3.0, 4.0])
    with h5py.File(path) as f:
        verify_file(f, str(path))


def test_to_xarray_names_the_variable_and_keeps_steps_and_units(bar_run):
    results = Results(bar_run / "results.h5")
    ds = results.to_xarray("sensor_u")
    steps, times, u = results.series("sensor_u")
    assert ds["sensor_u"].dims == ("time", "sensor", "component")
    np.testing.assert_array_equal(ds["step"].values, steps)
    np.testing.assert_array_equal(ds["sensor_u"].sel(sensor="x50", component="x").values, u[:, 0, 0])
    assert ds["sensor_u"].attrs == {"units": "m", "long_name": "displacement at the sensors"}
    assert ds["time"].attrs["units"] == "s"


def test_vtu_snapshot_carries_its_time_and_the_volumes(bar_run):
    """ParaView reads the field data ``TimeValue`` as the data set's time: it equals the time
    the .pvd lists; the point data ``volume`` is the geometry's (m^3)."""
    pvd = ET.parse(bar_run / "snapshots.pvd").getroot()
    entry = next(pvd.iter("DataSet"))
    mesh = meshio.read(bar_run / entry.attrib["file"])
    assert mesh.field_data["TimeValue"].tolist() == [float(entry.attrib["timestep"])]
    volumes = Results(bar_run / "results.h5").array("geometry/volumes")
    np.testing.assert_array_equal(mesh.point_data["volume"], volumes)


def _schema_2_file(path):
    """A results file as peridyn wrote it before schema 3: no dimension scales, no units."""
    with h5py.File(path, "w") as f:
        f.attrs[SCHEMA_ATTR] = 2
        f["geometry/points"] = np.zeros((2, 3))
        f["geometry/volumes"] = np.ones(2)
        group = f.create_group("series/sensor_u")
        group.create_dataset("data", data=np.arange(12.0).reshape(2, 2, 3), maxshape=(None, 2, 3))
        group.create_dataset("time", data=[0.0, 1e-7], maxshape=(None,))
        group.create_dataset("step", data=np.array([0, 1]), maxshape=(None,))
        group.attrs["names"] = json.dumps(["a", "b"])


def test_a_schema_2_file_reads_and_stays_schema_2_when_continued(tmp_path):
    path = tmp_path / "old.h5"
    _schema_2_file(path)
    results = Results(path)
    assert results.schema_version == 2
    ds = results.to_xarray("sensor_u")
    assert ds["sensor_u"].dims == ("time", "axis_1", "component")
    assert ds["component"].values.tolist() == ["x", "y", "z"] and ds["sensor_u"].attrs == {}
    np.testing.assert_array_equal(ds["sensor_u"].values, np.arange(12.0).reshape(2, 2, 3))
    # a restart appends to it: no labels are mixed into the old layout
    with HDF5Writer(path, np.zeros((2, 3)), np.ones(2), {}, mode="a") as out:
        out.append("sensor_u", 2, 2e-7, np.zeros((2, 3)))
        out.write_array("final/u", np.zeros((2, 3)), dims=("point", "component"))
    with h5py.File(path, "r") as f:
        assert f.attrs[SCHEMA_ATTR] == 2 and "point" not in f["final"]
    assert Results(path).n_records("sensor_u") == 3


def test_write_array_refuses_dimension_names_that_do_not_fit(tmp_path):
    with HDF5Writer(tmp_path / "r.h5", np.zeros((2, 3)), np.ones(2), {}) as out:
        out.write_array("final/u", np.zeros((2, 3)), dims=("point", "component"))
        with pytest.raises(InputError, match="dimension 'point' has length 2 in /final, not 5"):
            out.write_array("final/w", np.zeros((5, 3)), dims=("point", "component"))
        with pytest.raises(InputError, match="1 dimension names"):
            out.write_array("final/q", np.zeros((2, 3)), dims=("point",))


def test_no_root_view_of_a_series_torn_by_a_failed_write(tmp_path):
    """A write that failed part-way (a full or failing disk) can leave a series' data one record
    longer than its time and step; closing the file then wrote a root view whose ``record``
    lengths disagreed, and the labelling error hid the disk's (the disk-fault fuzz campaign,
    seed 4). Such a series gets no view; the file closes without a new error."""
    path = tmp_path / "r.h5"
    with HDF5Writer(path, np.zeros((2, 3)), np.ones(2), {}) as out:
        out.create_series("sensor_u", (1, 3), dims=("sensor", "component"), coords={"sensor": ["s"]})
        for step in range(3):
            out.append("sensor_u", step, step * 1e-7, np.zeros((1, 3)))
    with h5py.File(path, "a") as f:
        f["series/sensor_u/time"].resize((2,))  # the last record's time never written
        write_root_view(f, "sensor_u")
        assert [k for k, v in f["/"].items() if isinstance(v, h5py.Dataset)] == []
