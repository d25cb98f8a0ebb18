"""Tests of the Peridigm-style text mesh reader and writer."""

import numpy as np
import pytest

from peridyn.errors import InputError
from peridyn.io.mesh_text import read_text_mesh, write_text_mesh


def write(tmp_path, text, name="mesh.txt"):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_round_trip_is_exact(tmp_path):
    """Points, block ids and volumes written as text and read back are the same numbers, dtypes and
    shapes: the floats are printed with 17 significant digits, which read back to the same bits."""
    rng = np.random.default_rng(0)
    points = rng.normal(size=(50, 3)) * 1e-3
    block_ids = rng.integers(1, 4, size=50)
    volumes = rng.uniform(1e-12, 1e-9, size=50)
    path = tmp_path / "mesh.txt"
    write_text_mesh(path, points, block_ids, volumes)
    p, b, v = read_text_mesh(path)
    np.testing.assert_array_equal(p, points)
    np.testing.assert_array_equal(b, block_ids)
    np.testing.assert_array_equal(v, volumes)
    assert (p.dtype, b.dtype, v.dtype) == (np.float64, np.int64, np.float64)
    assert (p.shape, b.shape, v.shape) == ((50, 3), (50,), (50,))


def test_write_pads_2d_points_with_zero_z(tmp_path):
    """2D points are written with z = 0 and read back exactly (numbers printed to round-trip)."""
    path = tmp_path / "mesh.txt"
    write_text_mesh(path, [[1.0, 2.0], [3.0, 4.0]], [1, 2], [0.5, 0.25])
    p, b, v = read_text_mesh(path)
    np.testing.assert_array_equal(p, [[1.0, 2.0, 0.0], [3.0, 4.0, 0.0]])
    np.testing.assert_array_equal(b, [1, 2])


def test_comments_blank_lines_and_whitespace(tmp_path):
    """Comments, blank lines, tabs and non-ASCII text are skipped; each number parses to the float of
    the same decimal literal (correctly rounded): compared exactly."""
    text = (
        "# x y z block_id volume, spacing 1 µm — ünïcode comment\n"
        "\n"
        "0 0 0 1 1e-9   # first point\n"
        "   \n"
        "1e-3\t0  0 2 2e-9\n"
        "# trailing comment\n"
    )
    p, b, v = read_text_mesh(write(tmp_path, text))
    np.testing.assert_array_equal(p, [[0, 0, 0], [1e-3, 0, 0]])
    np.testing.assert_array_equal(b, [1, 2])
    np.testing.assert_array_equal(v, [1e-9, 2e-9])


def test_single_point(tmp_path):
    p, b, v = read_text_mesh(write(tmp_path, "1 2 3 7 0.5\n"))
    assert p.shape == (1, 3) and b.tolist() == [7] and v.tolist() == [0.5]


def test_missing_file_is_named(tmp_path):
    with pytest.raises(InputError, match="nowhere.txt.*does not exist"):
        read_text_mesh(tmp_path / "nowhere.txt")


@pytest.mark.parametrize("text", ["", "# only a comment\n\n"])
def test_empty_file(tmp_path, text):
    with pytest.raises(InputError, match="mesh.txt: no points"):
        read_text_mesh(write(tmp_path, text))


def test_wrong_column_count_names_line_and_counts(tmp_path):
    text = "# header\n0 0 0 1 1\n0 0 1 1\n0 0 2 1 1\n"
    with pytest.raises(InputError, match=r"mesh.txt, line 3: found 4 columns, expected 5"):
        read_text_mesh(write(tmp_path, text))


def test_wrong_column_count_on_every_line(tmp_path):
    text = "\n# header\n0 0 0 1 1 9\n0 0 1 1 1 9\n"
    with pytest.raises(InputError, match=r"line 3: found 6 columns, expected 5"):
        read_text_mesh(write(tmp_path, text))


def test_non_numeric_value_names_line_and_column(tmp_path):
    text = "0 0 0 1 1\n0 abc 0 1 1\n"
    with pytest.raises(InputError, match=r"line 2: y = 'abc' is not a number"):
        read_text_mesh(write(tmp_path, text))


@pytest.mark.parametrize("volume", ["0", "-1e-9", "nan", "inf"])
def test_bad_volume_names_line(tmp_path, volume):
    text = f"0 0 0 1 1\n# comment\n1 0 0 1 {volume}\n"
    with pytest.raises(InputError, match=r"line 3: volume must be positive and finite"):
        read_text_mesh(write(tmp_path, text))


def test_nan_coordinate_names_line(tmp_path):
    text = "0 0 0 1 1\n0 nan 0 1 1\n"
    with pytest.raises(InputError, match=r"line 2: coordinates must be finite"):
        read_text_mesh(write(tmp_path, text))


def test_fractional_block_id_names_line(tmp_path):
    text = "0 0 0 1 1\n0 0 0 1.5 1\n"
    with pytest.raises(InputError, match=r"line 2: block_id must be an integer"):
        read_text_mesh(write(tmp_path, text))


def test_write_rejects_bad_volumes(tmp_path):
    with pytest.raises(InputError, match="volumes must be positive"):
        write_text_mesh(tmp_path / "m.txt", np.zeros((2, 3)), [1, 1], [1.0, 0.0])


def test_write_rejects_mismatched_lengths(tmp_path):
    with pytest.raises(InputError, match=r"shape \(2,\)"):
        write_text_mesh(tmp_path / "m.txt", np.zeros((2, 3)), [1, 1, 1], [1.0, 1.0])


def test_input_error_is_a_value_error(tmp_path):
    with pytest.raises(ValueError):
        read_text_mesh(tmp_path / "nowhere.txt")
