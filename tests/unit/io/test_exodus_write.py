"""Writing Exodus II results (``peridyn.io.exodus_write``): round trips through our reader and
through ``scipy.io.netcdf_file`` alone, the layout Peridigm writes, restart truncation."""

import numpy as np
import pytest
import scipy.io

from peridyn.errors import InputError
from peridyn.io.exodus import read_exodus
from peridyn.io.exodus_write import ExodusWriter

N = 7
BLOCKS = [(1, "left", [0, 2, 4, 6]), (5, "right", [1, 3, 5])]
ORDER = np.array([0, 2, 4, 6, 1, 3, 5])  # elements: blocks in order


def _writer(path, dim=3):
    points = np.random.default_rng(0).random((N, dim))
    return ExodusWriter(
        path,
        points,
        blocks=BLOCKS,
        node_sets={"end": [0, 1], "none": []},
        nodal={"Displacement": dim, "Temperature": 1},
        element={"Damage": 1},
        global_={"Force": dim, "Energy": 1},
    ), points


def _steps(n_steps, dim=3, seed=1):
    rng = np.random.default_rng(seed)
    return [
        {
            "nodal": {"Displacement": rng.random((N, dim)), "Temperature": rng.random(N)},
            "element": {"Damage": rng.random(N)},
            "global_": {"Force": rng.random(dim), "Energy": rng.random()},
        }
        for _ in range(n_steps)
    ]


@pytest.mark.parametrize("dim", [2, 3])
def test_round_trip(tmp_path, dim):
    """Every array written comes back bit for bit, appended step by step."""
    writer, points = _writer(tmp_path / "r.e", dim)
    steps = _steps(4, dim)
    for k, s in enumerate(steps):
        writer.append(0.25 * k, **s)
    mesh = read_exodus(tmp_path / "r.e")
    np.testing.assert_array_equal(mesh.coordinates, points)
    np.testing.assert_array_equal(mesh.times, [0.0, 0.25, 0.5, 0.75])
    assert [(b.id, b.name, b.element_type) for b in mesh.blocks] == [
        (1, "left", "SPHERE"),
        (5, "right", "SPHERE"),
    ]
    np.testing.assert_array_equal(np.concatenate([b.connectivity[:, 0] for b in mesh.blocks]), ORDER)
    assert [(s.name, s.nodes.tolist()) for s in mesh.node_sets] == [("end", [0, 1])]  # empty sets left out
    u = np.stack([s["nodal"]["Displacement"] for s in steps])
    for c, axis in enumerate("XYZ"[:dim]):
        np.testing.assert_array_equal(mesh.nodal_variables[f"Displacement{axis}"], u[:, :, c])
        np.testing.assert_array_equal(
            mesh.global_variables[f"Force{axis}"], [s["global_"]["Force"][c] for s in steps]
        )
    np.testing.assert_array_equal(
        mesh.nodal_variables["Temperature"], [s["nodal"]["Temperature"] for s in steps]
    )
    np.testing.assert_array_equal(
        mesh.element_variables["Damage"], [s["element"]["Damage"][ORDER] for s in steps]
    )
    np.testing.assert_array_equal(mesh.global_variables["Energy"], [s["global_"]["Energy"] for s in steps])


def test_layout_is_exodus(tmp_path):
    """Read with scipy alone: the Exodus dimensions, variables and attributes Peridigm's files
    have (compare ``tests/data/peridigm/*_gold.e``)."""
    writer, _ = _writer(tmp_path / "r.e")
    for k, s in enumerate(_steps(2)):
        writer.append(float(k), **s)
    with scipy.io.netcdf_file(tmp_path / "r.e", "r", mmap=False) as f:
        assert f.version_byte == 2 and f.dimensions["time_step"] is None
        assert (f.dimensions["num_nodes"], f.dimensions["num_elem"], f.dimensions["num_el_blk"]) == (N, N, 2)
        assert f.floating_point_word_size == 8 and f.file_size == 1
        v = f.variables
        assert v["connect2"].elem_type == b"SPHERE" and v["connect2"].shape == (3, 1)
        assert v["eb_prop1"].data.tolist() == [1, 5] and v["eb_prop1"].name == b"ID"
        assert v["vals_nod_var1"].shape == (2, N) and v["vals_elem_var1eb2"].shape == (2, 3)
        assert v["vals_glo_var"].shape == (2, 4) and v["elem_var_tab"].data.tolist() == [[1], [1]]
        assert v["time_whole"].data.tolist() == [0.0, 1.0]


def test_resume_drops_later_steps(tmp_path):
    """A restart at t = 0.5 keeps the steps up to 0.5 and appends after them. Stored values read back:
    compared exactly."""
    writer, _ = _writer(tmp_path / "r.e")
    steps = _steps(4)
    for k, s in enumerate(steps):
        writer.append(0.25 * k, **s)
    again, _ = _writer(tmp_path / "r.e")
    again.resume(0.5)
    again.append(0.6, **steps[0])
    mesh = read_exodus(tmp_path / "r.e")
    np.testing.assert_array_equal(mesh.times, [0.0, 0.25, 0.5, 0.6])
    u = [s["nodal"]["Displacement"][:, 1] for s in (*steps[:3], steps[0])]
    np.testing.assert_array_equal(mesh.nodal_variables["DisplacementY"], u)
    other = ExodusWriter(tmp_path / "r.e", np.zeros((N, 3)), nodal={"Velocity": 3})
    with pytest.raises(InputError, match="differ"):
        other.resume(0.5)


def test_bad_input_is_refused(tmp_path):
    writer, _ = _writer(tmp_path / "r.e")
    step = _steps(1)[0]
    with pytest.raises(InputError, match="declared"):
        writer.append(0.0, nodal={"Displacement": np.zeros((N, 3))}, element=step["element"])
    with pytest.raises(InputError, match="shape"):
        writer.append(0.0, **{**step, "element": {"Damage": np.zeros(N + 1)}})
    with pytest.raises(InputError, match="exactly once"):
        ExodusWriter(tmp_path / "b.e", np.zeros((3, 3)), blocks=[(1, "a", [0, 1]), (2, "b", [1, 2])])
    with pytest.raises(InputError, match="components"):
        ExodusWriter(tmp_path / "b.e", np.zeros((3, 3)), nodal={"Stress": 6})
    assert not (tmp_path / "b.e").exists()
