"""Bodies and point generators."""

import numpy as np
import pytest

from peridyn.discretization import geometry
from peridyn.discretization.body import Body, in_cylinder
from peridyn.errors import InputError
from peridyn.io import mesh_text


def test_box_cells_and_volume():
    body = geometry.box((0.010, 0.006, 0.004), (1e-3, 1e-3, 0.5e-3))
    assert body.n_points == 10 * 6 * 8
    assert body.volumes.sum() == pytest.approx(0.010 * 0.006 * 0.004, rel=1e-12)
    assert body.points[:, 2].min() == pytest.approx(0.25e-3)


@pytest.mark.parametrize(
    "placement, z_expected",
    [
        ("cell", [1 / 3, 1.0, 5 / 3]),  # cell-centred slabs of t / 3
        ("surface", [0.0, 1.0, 2.0]),  # seed 000: 3 layers 1 mm apart on the faces
    ],
)
def test_plate_layers(placement, z_expected):
    body = geometry.plate(0.012, 0.006, 0.002, spacing=1.2e-3, layers=3, layer_placement=placement)
    assert body.n_points == 10 * 5 * 3
    np.testing.assert_allclose(np.unique(body.points[:, 2]) * 1e3, z_expected, rtol=1e-12)
    top = geometry.layer(body, -1)
    assert top.sum() == 50
    assert np.all(body.points[top, 2] == body.points[:, 2].max())


def test_rectangle_is_2d_with_thickness():
    body = geometry.rectangle(0.004, 0.010125, 0.125e-3, thickness=1e-3, plane="strain")
    assert body.dim == 2 and body.plane == "strain"
    assert np.all(body.points[:, 2] == 0.0)
    assert body.volumes.sum() == pytest.approx(0.004 * 81 * 0.125e-3 * 1e-3, rel=1e-12)


def test_hole_removal_reindexes_node_sets():
    """Removing the points in a hole keeps each node set's points (their coordinates are copied:
    compared exactly), and none is left in the hole."""
    body = geometry.plate(0.03, 0.02, 0.002, spacing=1e-3, layers=2)
    body = body.with_node_set("edge", geometry.face(body, "x+"))
    edge_points = body.points[body.node_set("edge")]
    holed = body.remove(in_cylinder((0.015, 0.01, 0.0), 0.003))
    assert holed.n_points < body.n_points
    np.testing.assert_array_equal(holed.points[holed.node_set("edge")], edge_points)
    r = np.hypot(holed.points[:, 0] - 0.015, holed.points[:, 1] - 0.01)
    assert r.min() > 0.003


def test_text_mesh_round_trip(tmp_path):
    """A body written as a text mesh and read back: the same points (printed with 17 significant digits,
    which read back to the same bits), its volumes to rounding and one block."""
    body = geometry.box((0.003, 0.002, 0.002), 1e-3)
    mesh_text.to_text_mesh(body, tmp_path / "m.txt")
    back = mesh_text.from_text_mesh(tmp_path / "m.txt")
    np.testing.assert_array_equal(back.points, body.points)
    np.testing.assert_allclose(back.volumes, body.volumes, rtol=1e-15)
    assert list(back.node_sets) == ["block_1"]


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(points=np.array([[0, 0, np.nan]]), volumes=[1.0]), "non-finite"),
        (dict(points=np.zeros((1, 3)), volumes=[-1.0]), "positive"),
        (dict(points=np.zeros((2, 2)), volumes=[1.0, 1.0]), "shape"),
    ],
)
def test_bad_bodies_are_refused(kwargs, message):
    with pytest.raises(InputError, match=message):
        Body(cells=1.0, dim=3, spacing=1.0, **kwargs)


def test_negative_spacing_is_refused():
    with pytest.raises(InputError, match="spacing"):
        geometry.box((0.01, 0.01, 0.01), -1e-3)


def test_empty_node_set_is_refused():
    body = geometry.box((0.004, 0.004, 0.004), 1e-3)
    with pytest.raises(InputError, match="empty"):
        body.with_node_set("nothing", lambda x: x[:, 0] > 1.0)


def test_unknown_node_set_suggests_a_name():
    body = geometry.box((0.004, 0.004, 0.004), 1e-3).with_node_set("left", lambda x: x[:, 0] < 1e-3)
    with pytest.raises(InputError, match="did you mean 'left'"):
        body.node_set("lfet")


def test_a_side_the_spacing_does_not_divide_is_rounded_with_a_warning():
    """A grid of whole cells cannot hold 50 mm at 1.5 mm spacing (33.3 cells): the body gets
    33 cells (49.5 mm) and the user is told which side changed and by how much."""
    with pytest.warns(UserWarning, match=r"0.05 m -> 0.0495 m \(33 cells\)"):
        body = geometry.box((0.06, 0.05, 0.006), 0.0015)
    assert body.points[:, 1].max() + 0.00075 == pytest.approx(0.0495)
    with pytest.warns(UserWarning, match="sides rounded"):
        geometry.rectangle(0.1, 0.0101, 1e-3, 1e-3)


def test_a_side_the_spacing_divides_gives_no_warning():
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        geometry.box((0.1, 0.05, 0.008), 0.001)
        geometry.box((0.1, 0.05, 0.008), 0.00066667)  # 150 x 75 x 12 cells, 5e-6 relative
