"""Tests of the .vtu writer and the .pvd collection."""

import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest

from peridyn.errors import InputError
from peridyn.io.vtk import PVDCollection, write_vtu


def test_vtu_round_trip_3d(tmp_path):
    rng = np.random.default_rng(2)
    points = rng.random((8, 3))
    fields = {
        "displacement": rng.random((8, 3)),
        "damage": rng.random(8),
        "block": np.arange(8, dtype=np.int64),
        "stress": rng.random((8, 6)).astype(np.float32),
    }
    path = tmp_path / "out.vtu"
    write_vtu(path, points, fields)
    mesh = meshio.read(path)
    np.testing.assert_array_equal(mesh.points, points)
    assert [(block.type, len(block)) for block in mesh.cells] == [("vertex", 8)]
    np.testing.assert_array_equal(mesh.cells[0].data.ravel(), np.arange(8))
    assert set(mesh.point_data) == set(fields)
    for name, values in fields.items():
        np.testing.assert_array_equal(mesh.point_data[name], values)
        assert mesh.point_data[name].dtype == values.dtype


def test_vtu_pads_2d_points_and_vectors(tmp_path):
    points = np.array([[0.0, 0.0], [1e-3, 0.0], [0.0, 1e-3]])
    velocity = np.array([[1.0, 2.0], [3.0, 4.0], [5.0, 6.0]])
    path = tmp_path / "out.vtu"
    write_vtu(path, points, {"velocity": velocity, "broken": np.array([True, False, True])})
    mesh = meshio.read(path)
    np.testing.assert_array_equal(mesh.points, np.column_stack([points, np.zeros(3)]))
    np.testing.assert_array_equal(mesh.point_data["velocity"][:, :2], velocity)
    np.testing.assert_array_equal(mesh.point_data["velocity"][:, 2], 0.0)
    np.testing.assert_array_equal(mesh.point_data["broken"], [1, 0, 1])


def test_vtu_rejects_field_of_wrong_length(tmp_path):
    with pytest.raises(InputError, match=r"field 'damage' has shape \(2,\), expected \(3,\)"):
        write_vtu(tmp_path / "out.vtu", np.zeros((3, 3)), {"damage": np.zeros(2)})


def test_vtu_rejects_bad_points(tmp_path):
    with pytest.raises(InputError, match="points must have shape"):
        write_vtu(tmp_path / "out.vtu", np.zeros((3, 4)), {})


def datasets(path):
    root = ET.parse(path).getroot()
    assert root.tag == "VTKFile" and root.attrib["type"] == "Collection"
    return [(float(d.attrib["timestep"]), d.attrib["file"]) for d in root.iter("DataSet")]


def test_pvd_is_valid_after_each_add_and_lists_files_in_order(tmp_path):
    path = tmp_path / "run.pvd"
    pvd = PVDCollection(path)
    expected = []
    for i, time in enumerate([0.0, 1e-7, 2.5e-7]):
        name = f"vtu/step_{i:06d}.vtu"
        pvd.add(time, name)
        expected.append((time, name))
        assert datasets(path) == expected
    assert pvd.entries == expected
    assert not list(tmp_path.glob("*.tmp"))


def test_pvd_append_mode_and_truncate(tmp_path):
    path = tmp_path / "run.pvd"
    pvd = PVDCollection(path)
    for i in range(4):
        pvd.add(i * 1e-6, f"step_{i}.vtu")
    restarted = PVDCollection(path, mode="a")
    restarted.truncate(1.5e-6)
    restarted.add(2e-6, "step_2_restarted.vtu")
    assert datasets(path) == [
        (0.0, "step_0.vtu"),
        (1e-6, "step_1.vtu"),
        (2e-6, "step_2_restarted.vtu"),
    ]


def test_pvd_rejects_time_going_back(tmp_path):
    pvd = PVDCollection(tmp_path / "run.pvd")
    pvd.add(1.0, "a.vtu")
    with pytest.raises(InputError, match="does not exceed the last listed time"):
        pvd.add(1.0, "b.vtu")


def test_pvd_append_mode_rejects_a_broken_file(tmp_path):
    path = tmp_path / "run.pvd"
    path.write_text("<VTKFile><Collection><DataSet file='a.vtu'/>")
    with pytest.raises(InputError, match="run.pvd: not a valid .pvd collection"):
        PVDCollection(path, mode="a")
