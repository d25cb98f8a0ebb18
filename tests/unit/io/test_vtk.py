"""Tests of the .vtu writer and the .pvd collection."""

import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest

from peridyn.errors import InputError
from peridyn.io.vtk import PVDCollection, read_pvtu_pieces, write_pvtu, write_vtu


@pytest.mark.parametrize("compression", ["none", "zlib"])
def test_vtu_round_trip_3d(tmp_path, compression):
    """Points, vertex cells and point fields (float64, int64, float32) written to a VTU file,
    uncompressed or zlib, read back by meshio as written, dtypes included: stored values, compared
    exactly."""
    rng = np.random.default_rng(2)
    points = rng.random((8, 3))
    fields = {
        "displacement": rng.random((8, 3)),
        "damage": rng.random(8),
        "block": np.arange(8, dtype=np.int64),
        "stress": rng.random((8, 6)).astype(np.float32),
    }
    path = tmp_path / "out.vtu"
    write_vtu(path, points, fields, compression)
    assert (b'compressor="vtkZLibDataCompressor"' in path.read_bytes()) == (compression == "zlib")
    mesh = meshio.read(path)
    np.testing.assert_array_equal(mesh.points, points)
    assert [(block.type, len(block)) for block in mesh.cells] == [("vertex", 8)]
    np.testing.assert_array_equal(mesh.cells[0].data.ravel(), np.arange(8))
    assert set(mesh.point_data) == set(fields)
    for name, values in fields.items():
        np.testing.assert_array_equal(mesh.point_data[name], values)
        assert mesh.point_data[name].dtype == values.dtype


def test_vtu_encoded_in_pieces_is_the_file_encoded_whole(tmp_path, monkeypatch):
    """An uncompressed VTU file's arrays are base64-encoded a few MiB at a time; with pieces of
    15 bytes (7 points: every array's bytes end mid-piece, the cells' arrays made in chunks of one
    point) the file is byte for byte the one written in one piece (base64 of whole 3-byte groups
    joins), and meshio reads back what was written."""
    rng = np.random.default_rng(5)
    points, fields = rng.random((7, 3)), {"u": rng.random((7, 3)), "damage": rng.random(7).astype(np.float32)}
    write_vtu(tmp_path / "whole.vtu", points, fields, time=1.5e-6)
    monkeypatch.setattr("peridyn.io.vtk.ENCODE_CHUNK", 15)
    write_vtu(tmp_path / "pieces.vtu", points, fields, time=1.5e-6)
    assert (tmp_path / "pieces.vtu").read_bytes() == (tmp_path / "whole.vtu").read_bytes()
    mesh = meshio.read(tmp_path / "pieces.vtu")
    np.testing.assert_array_equal(mesh.points, points)
    np.testing.assert_array_equal(mesh.cells[0].data.ravel(), np.arange(7))
    for name, values in fields.items():
        np.testing.assert_array_equal(mesh.point_data[name], values)


def test_vtu_pads_2d_points_and_vectors(tmp_path):
    """2D points and vectors are padded with a zero z and booleans stored as 0 and 1: stored values,
    compared exactly."""
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


def test_vtu_rejects_an_unknown_compression(tmp_path):
    with pytest.raises(InputError, match="compression must be one of"):
        write_vtu(tmp_path / "out.vtu", np.zeros((3, 3)), {}, "gzip")


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


def test_pvtu_declares_the_pieces_fields_as_write_vtu_writes_them(tmp_path):
    """A .pvtu (VTK's parallel unstructured grid, the format ParaView reads as one data set)
    lists its pieces relative to its folder and declares each point field with the VTK type and
    component count of the pieces' own arrays (as meshio reads them back): 2D vectors padded to 3,
    booleans as UInt8."""
    rng = np.random.default_rng(3)
    data = {
        "displacement": rng.standard_normal((4, 2)),
        "valid": np.array([True, False, True, True]),
        "damage": rng.random(4).astype(np.float32),
    }
    (tmp_path / "step").mkdir()
    pieces = ["step/piece_0000.vtu", "step/piece_0001.vtu"]
    for piece in pieces:
        write_vtu(tmp_path / piece, rng.random((4, 2)), data)
    write_pvtu(tmp_path / "step.pvtu", pieces, data)
    assert read_pvtu_pieces(tmp_path / "step.pvtu") == [tmp_path / p for p in pieces]
    declared = {
        a.attrib["Name"]: (a.attrib["type"], int(a.attrib["NumberOfComponents"]))
        for a in ET.parse(tmp_path / "step.pvtu").getroot().find("PUnstructuredGrid/PPointData")
    }
    written = meshio.read(tmp_path / pieces[0]).point_data
    vtk_type = {"float64": "Float64", "float32": "Float32", "uint8": "UInt8"}
    assert declared == {
        name: (vtk_type[value.dtype.name], 1 if value.ndim == 1 else value.shape[1])
        for name, value in written.items()
    }
    assert declared["displacement"] == ("Float64", 3) and declared["valid"] == ("UInt8", 1)
