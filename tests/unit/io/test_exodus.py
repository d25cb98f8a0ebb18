"""Reading Exodus II files and turning elements into points (``peridyn.io.exodus``).

The meshes and gold results are Peridigm's own test data (``tests/data/peridigm``): the
facts checked come from the decks' descriptions (box sizes, element counts, node sets) and
from what Peridigm itself made of the same meshes (its gold output).
"""

from pathlib import Path

import numpy as np
import pytest
import scipy.io

from peridyn.errors import InputError
from peridyn.io.exodus import (
    ElementBlock,
    ExodusMesh,
    body_from_exodus,
    hex_centroid_volume,
    mesh_points,
    read_exodus,
    tet_centroid_volume,
)
from peridyn.io.exodus_write import ExodusWriter

DATA = Path(__file__).parents[2] / "data" / "peridigm"

#: Rounding of sums of a few hundred float64 volumes (relative).
SUM_RTOL = 1e-13
#: Rounding of the 24-tetrahedron sums of a hexahedron: volume (relative) and centroid (a few
#: ulps of the mesh's extent, times this).
HEX_RTOL = 1e-14
ULPS = 16 * np.finfo(float).eps

UNIT_HEX = np.array(
    [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], float
)


def test_hex_mesh_of_elastic_bond_based_3d():
    """The deck's mesh: a 1 x 6 x 1 m box of 0.25 m hexes (4 x 24 x 4), three blocks along y
    split at y = -1.5 and 1.5, one node set holding every node. The coordinates' extremes are the file's
    numbers and the block ids integers: compared exactly."""
    mesh = read_exodus(DATA / "ElasticBondBased3D.g")
    assert [(b.name, b.element_type, b.connectivity.shape) for b in mesh.blocks] == [
        ("block_1", "HEX8", (96, 8)),
        ("block_2", "HEX8", (192, 8)),
        ("block_3", "HEX8", (96, 8)),
    ]
    np.testing.assert_array_equal(mesh.coordinates.min(axis=0), [-0.5, -3.0, -0.5])
    np.testing.assert_array_equal(mesh.coordinates.max(axis=0), [0.5, 3.0, 0.5])
    assert len(mesh.times) == 0 and mesh.nodal_variables == {}
    ns = mesh.node_set("nodelist_1")  # unnamed in the file: Peridigm's name
    assert ns is mesh.node_set(1) and len(ns.nodes) == len(mesh.coordinates)

    pts = mesh_points(mesh)
    assert len(pts.points) == 4 * 24 * 4
    np.testing.assert_allclose(pts.volumes, 0.25**3, rtol=HEX_RTOL)
    np.testing.assert_allclose(pts.volumes.sum(), 1.0 * 6.0 * 1.0, rtol=SUM_RTOL)
    # centroids on the grid of cell centres
    np.testing.assert_allclose((pts.points + [0.5, 3.0, 0.5]) / 0.25 % 1.0, 0.5, atol=1e-12)
    y = pts.points[:, 1]
    assert np.all(y[pts.point_sets["block_1"]] < -1.5) and np.all(y[pts.point_sets["block_3"]] > 1.5)
    np.testing.assert_array_equal(pts.block_ids, np.repeat([1, 2, 3], [96, 192, 96]))
    assert len(pts.point_sets["nodelist_1"]) == 384


def test_points_are_those_peridigm_made():
    """Peridigm's gold output of the same deck holds the points it made from the hexes, in
    element order: coordinates to rounding, volumes (element variable ``Volume``) exactly
    to rounding, its blocks and its node set."""
    pts = mesh_points(read_exodus(DATA / "ElasticBondBased3D.g"))
    gold = read_exodus(DATA / "ElasticBondBased3D_gold.e")
    np.testing.assert_allclose(pts.points, gold.coordinates, rtol=0, atol=ULPS * 3.0)
    np.testing.assert_allclose(pts.volumes, gold.element_variables["Volume"][0], rtol=HEX_RTOL)
    assert [b.element_type for b in gold.blocks] == ["SPHERE"] * 3
    start = 0
    for b in gold.blocks:
        idx = np.arange(start, start + len(b.connectivity))
        np.testing.assert_array_equal(pts.point_sets[b.name], idx)
        start += len(idx)
    np.testing.assert_array_equal(np.sort(gold.node_set(1).nodes), pts.point_sets["nodelist_1"])


def test_node_set_becomes_the_elements_touching_it():
    """WaveInBar: the loaded end's node set holds the 4 node planes x = -21..-15 mm; the mesh's
    nodes at x = -15 mm are not shared with the next layer of elements (828 nodes = 22 planes
    of 6 x 6 + one duplicated plane), so the elements touching the set are the 3 layers left
    of x = -15 mm: 75 of the 21 x 5 x 5 elements of 2 mm. Checked against a plain loop over
    the elements. Point indices: compared exactly."""
    mesh = read_exodus(DATA / "WaveInBar.g")
    assert len(mesh.coordinates) == 22 * 36 + 36 and mesh.n_elements == 21 * 5 * 5
    nodes = mesh.node_set("nodelist_1").nodes
    np.testing.assert_allclose(
        np.unique(mesh.coordinates[nodes, 0].round(9)), [-0.021, -0.019, -0.017, -0.015]
    )
    pts = mesh_points(mesh)
    np.testing.assert_allclose(pts.volumes.sum(), 0.042 * 0.01 * 0.01, rtol=SUM_RTOL)
    members = set(nodes.tolist())
    conn = mesh.blocks[0].connectivity
    expected = [e for e in range(len(conn)) if any(int(k) in members for k in conn[e])]
    np.testing.assert_array_equal(pts.point_sets["nodelist_1"], expected)
    assert len(expected) == 75 and np.all(pts.points[expected, 0] < -0.015)


def test_node_set_rule_is_peridigms():
    """WaveInBar's deck gives the node set an initial velocity of -100 m/s in x: the points
    moving at t = 0 in Peridigm's gold output are the points of our node set. Point indices: compared
    exactly."""
    gold = read_exodus(DATA / "WaveInBar_gold.e")
    pts = mesh_points(read_exodus(DATA / "WaveInBar.g"))
    np.testing.assert_allclose(pts.points, gold.coordinates, rtol=0, atol=ULPS * 0.021)
    moving = np.flatnonzero(gold.nodal_variables["VelocityX"][0] == -100.0)
    np.testing.assert_array_equal(moving, pts.point_sets["nodelist_1"])


def test_peridigm_results_file():
    """Compression_2x1x1: two points 2 m apart (x origin -2, length 4), output at 0..50 us every
    10 us, Peridigm's names for vector components, and the deck's node sets by name."""
    out = read_exodus(DATA / "Compression_2x1x1_gold.e")
    np.testing.assert_allclose(out.coordinates, [[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]], atol=1e-15)
    np.testing.assert_allclose(out.times, np.arange(6) * 1e-5, rtol=1e-12)
    assert {"DisplacementX", "VelocityZ", "Force_DensityY"} <= set(out.nodal_variables)
    assert out.nodal_variables["DisplacementX"].shape == (6, 2)
    assert out.element_variables["Dilatation"].shape == (6, 2)
    assert out.node_set("MIN_X_NODE_SET").nodes.tolist() == [0]
    assert out.node_set("MAX_X_NODE_SET").nodes.tolist() == [1]
    with pytest.raises(InputError, match="MIN_X_NODE_SET"):
        out.node_set("min_x")


def test_results_file_without_steps(tmp_path):
    """A results file closed before its first step: variables declared, none recorded. The coordinates
    are the copied file's numbers: compared exactly."""
    gold = read_exodus(DATA / "Compression_2x1x1_gold.e")
    with scipy.io.netcdf_file(DATA / "Compression_2x1x1_gold.e", "r", mmap=False) as src:
        with scipy.io.netcdf_file(tmp_path / "empty.e", "w", version=2) as dst:
            dst.createDimension("time_step", None)  # scipy wants the unlimited one first
            for name, size in src.dimensions.items():
                if size is not None:
                    dst.createDimension(name, size)
            for name, var in src.variables.items():
                data = var.data[:0] if var.isrec else var.data
                out = dst.createVariable(name, var.typecode(), var.dimensions)
                out[: len(data)] = data
                for key, value in var._attributes.items():
                    setattr(out, key, value)
    empty = read_exodus(tmp_path / "empty.e")
    assert len(empty.times) == 0
    assert empty.element_variables.keys() == gold.element_variables.keys()
    assert empty.element_variables["Dilatation"].shape == (0, 2)
    np.testing.assert_array_equal(empty.coordinates, gold.coordinates)


def test_hex_volume_is_the_trilinear_volume():
    """A warped hexahedron (non-planar faces): the 24-tetrahedron volume equals the integral
    of det J of the trilinear map, exact with 2 x 2 x 2 Gauss points (det J is quadratic per
    axis)."""
    rng = np.random.default_rng(3)
    nodes = UNIT_HEX * [2.0, 3.0, 1.5] + rng.uniform(-0.2, 0.2, (8, 3))
    signs = 2 * UNIT_HEX - 1
    volume = 0.0
    for xi in np.array(np.meshgrid(*[[-1, 1]] * 3)).reshape(3, -1).T / np.sqrt(3):
        factors = 1 + signs * xi  # (8, 3)
        grad = np.stack(
            [signs[:, d] * np.prod(np.delete(factors, d, axis=1), axis=1) / 8 for d in range(3)], 1
        )
        volume += np.linalg.det(nodes.T @ grad)
    _, v = hex_centroid_volume(nodes[None])
    np.testing.assert_allclose(v[0], volume, rtol=1e-14)


def test_hex_with_planar_faces_exact():
    """A frustum-like hexahedron (planar trapezoid faces): volume and centroid of the
    polyhedron from its 5 tetrahedra (a standard split of a hexahedron with planar faces)."""
    nodes = UNIT_HEX.copy()
    nodes[4:, :2] = 0.25 + 0.5 * nodes[4:, :2]  # top face shrunk about the axis: a frustum
    c, v = hex_centroid_volume(nodes[None])
    tets = [[0, 1, 3, 4], [1, 2, 3, 6], [1, 4, 5, 6], [3, 6, 7, 4], [1, 3, 4, 6]]
    cs, vs = tet_centroid_volume(nodes[np.array(tets)])
    np.testing.assert_allclose(v[0], vs.sum(), rtol=1e-14)
    np.testing.assert_allclose(
        v[0], (1 + 0.25 + 0.5) / 3, rtol=1e-14
    )  # frustum: h (A1 + A2 + sqrt(A1 A2)) / 3
    np.testing.assert_allclose(c[0], (vs[:, None] * cs).sum(0) / vs.sum(), rtol=1e-14)


def _mesh(kind, conn, coordinates, attributes=None, node_sets=()):
    conn = np.asarray(conn)
    attrs = np.zeros((len(conn), 0)) if attributes is None else np.asarray(attributes, float)
    return ExodusMesh(
        "t", np.asarray(coordinates, float), [ElementBlock(1, "b", kind, conn, attrs)], list(node_sets)
    )


def test_tet_and_sphere_elements():
    """A TETRA4: volume 1/6 of the unit corner, centroid the vertex mean; a SPHERE element
    keeps its node and takes the volume from its second attribute. A sphere's point and volume are the
    file's numbers: compared exactly."""
    tet = mesh_points(_mesh("TETRA", [[0, 1, 2, 3]], [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]))
    np.testing.assert_allclose(tet.volumes, [1 / 6], rtol=1e-15)
    np.testing.assert_allclose(tet.points, [[0.25, 0.25, 0.25]], rtol=1e-15)
    sphere = mesh_points(_mesh("SPHERE", [[1], [0]], [[0, 0, 0], [1, 2, 3]], [[0.5, 2e-9], [0.5, 3e-9]]))
    np.testing.assert_array_equal(sphere.points, [[1, 2, 3], [0, 0, 0]])
    np.testing.assert_array_equal(sphere.volumes, [2e-9, 3e-9])


def _chars(names, width=33):
    """Names as a NUL-padded (n, width) netCDF char table."""
    table = np.zeros((len(names), width), "S1")
    for k, name in enumerate(names):
        table[k, : len(name)] = np.frombuffer(name.encode(), "S1")
    return table


def _write_mesh(path):
    """Two unit cubes along x sharing a face (block 10 "steel", HEX8) and a corner tetrahedron
    (block 20, unnamed, TETRA4); node set 7 (unnamed): the x = 0 face; side set 3 "right":
    side 2 (the x+ face) of element 2. Written the way Cubit writes it (ids, names, 1-based)."""
    cube = np.array(UNIT_HEX)
    nodes = np.concatenate(
        [cube, cube[[1, 2, 5, 6]] + [1, 0, 0], [[5, 0, 0], [6, 0, 0], [5, 1, 0], [5, 0, 1]]]
    )
    conn_hex = np.array([[0, 1, 2, 3, 4, 5, 6, 7], [1, 8, 9, 2, 5, 10, 11, 6]]) + 1
    with scipy.io.netcdf_file(path, "w", version=2) as f:
        f.title = "two cubes and a tet"
        for name, size in [("len_name", 33), ("num_dim", 3), ("num_nodes", len(nodes)), ("num_elem", 3)]:
            f.createDimension(name, size)
        for name, size in [("num_el_blk", 2), ("num_node_sets", 1), ("num_side_sets", 1)]:
            f.createDimension(name, size)
        for name, size in [("num_el_in_blk1", 2), ("num_nod_per_el1", 8), ("num_el_in_blk2", 1)]:
            f.createDimension(name, size)
        for name, size in [("num_nod_per_el2", 4), ("num_nod_ns1", 4), ("num_side_ss1", 1)]:
            f.createDimension(name, size)
        for axis, c in enumerate("xyz"):
            f.createVariable(f"coord{c}", "d", ("num_nodes",))[:] = nodes[:, axis]
        f.createVariable("eb_prop1", "i", ("num_el_blk",))[:] = [10, 20]
        f.createVariable("eb_names", "c", ("num_el_blk", "len_name"))[:] = _chars(["steel", ""])
        f.createVariable("connect1", "i", ("num_el_in_blk1", "num_nod_per_el1"))[:] = conn_hex
        f.variables["connect1"].elem_type = "HEX8"
        f.createVariable("connect2", "i", ("num_el_in_blk2", "num_nod_per_el2"))[:] = [[13, 14, 15, 16]]
        f.variables["connect2"].elem_type = "TETRA4"
        f.createVariable("ns_prop1", "i", ("num_node_sets",))[:] = [7]
        f.createVariable("node_ns1", "i", ("num_nod_ns1",))[:] = [1, 4, 5, 8]
        f.createVariable("ss_prop1", "i", ("num_side_sets",))[:] = [3]
        f.createVariable("ss_names", "c", ("num_side_sets", "len_name"))[:] = _chars(["right"])
        f.createVariable("elem_ss1", "i", ("num_side_ss1",))[:] = [2]
        f.createVariable("side_ss1", "i", ("num_side_ss1",))[:] = [2]


def test_blocks_sets_and_side_sets_from_a_file(tmp_path):
    """A mesh file of named and unnamed blocks, node sets and side sets: names, ids, element types and
    sides as written, volumes and centroids to rounding, and the block ids (integers) exactly."""
    _write_mesh(tmp_path / "m.g")
    mesh = read_exodus(tmp_path / "m.g")
    assert mesh.title == "two cubes and a tet"
    assert [(b.id, b.name, b.element_type) for b in mesh.blocks] == [
        (10, "steel", "HEX8"),
        (20, "block_20", "TETRA4"),
    ]
    side = mesh.side_set("right")
    assert side is mesh.side_set(3) and side.elements.tolist() == [1] and side.sides.tolist() == [2]
    pts = mesh_points(mesh)
    np.testing.assert_allclose(pts.volumes, [1.0, 1.0, 1 / 6], rtol=HEX_RTOL)
    np.testing.assert_allclose(
        pts.points, [[0.5, 0.5, 0.5], [1.5, 0.5, 0.5], [5.25, 0.25, 0.25]], rtol=HEX_RTOL
    )
    np.testing.assert_array_equal(pts.block_ids, [10, 10, 20])
    sets = {k: v.tolist() for k, v in pts.point_sets.items()}
    assert sets == {"steel": [0, 1], "block_20": [2], "nodelist_7": [0], "right": [1]}


def test_bad_meshes_are_refused(tmp_path):
    with pytest.raises(InputError, match="QUAD4"):
        mesh_points(_mesh("QUAD4", [[0, 1, 2, 3]], [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]))
    with pytest.raises(InputError, match="second attribute"):
        mesh_points(_mesh("SPHERE", [[0]], [[0, 0, 0]], [[0.5]]))
    inverted = UNIT_HEX[[4, 5, 6, 7, 0, 1, 2, 3]]
    with pytest.raises(InputError, match="node order"):
        mesh_points(_mesh("HEX8", [list(range(8))], inverted))
    with pytest.raises(InputError, match="does not exist"):
        read_exodus(tmp_path / "none.e")
    (tmp_path / "text.e").write_text("not netcdf")
    with pytest.raises(InputError, match="netCDF-3"):
        read_exodus(tmp_path / "text.e")
    with scipy.io.netcdf_file(tmp_path / "plain.nc", "w") as f:
        f.createDimension("x", 1)
    with pytest.raises(InputError, match="num_dim"):
        read_exodus(tmp_path / "plain.nc")


def test_sphere_volumes_written_read_back_and_one_layer_2d(tmp_path):
    """``ExodusWriter(volumes=...)`` writes Peridigm's sphere attributes (radius, volume) that
    ``body_from_exodus`` reads back as the points' volumes; a 2D body (Peridigm's 2D decks on a
    one-layer mesh) takes cells of area volume / thickness and refuses points at two z. The volumes read
    back are the stored ones: compared exactly."""
    points = np.array([[0.0, 0.0, 0.1], [0.5, 0.0, 0.1], [0.0, 0.5, 0.1]])
    volumes = np.array([0.02, 0.03, 0.05])
    ExodusWriter(tmp_path / "flat.e", points, volumes=volumes).append(0.0)
    body = body_from_exodus(tmp_path / "flat.e", dim=2, thickness=0.2, plane="strain")
    np.testing.assert_array_equal(body.volumes, volumes)
    assert (body.dim, body.thickness, body.plane) == (2, 0.2, "strain")
    np.testing.assert_allclose(body.cells[:, 0] ** 2 * 0.2, volumes, rtol=1e-15)
    radius = read_exodus(tmp_path / "flat.e").blocks[0].attributes[:, 0]
    np.testing.assert_allclose(4 / 3 * np.pi * radius**3, volumes, rtol=1e-15)
    points[2, 2] = 0.3
    ExodusWriter(tmp_path / "two.e", points, volumes=volumes).append(0.0)
    assert body_from_exodus(tmp_path / "two.e").dim == 3
    with pytest.raises(InputError, match="one layer"):
        body_from_exodus(tmp_path / "two.e", dim=2, thickness=0.2)


def test_hex_points_are_peridigms_to_the_bit():
    """Peridigm writes each element's point (its ``hexCentroidAndVolume``) as the coordinates
    of its output: on the 640 hexahedra of its PrecrackedPlateTwoCracks test, whose bond filters
    meet bonds exactly at their edges, every coordinate of the gold file is the point peridyn
    makes of the mesh, bit for bit (the former tetrahedra order left 674 of them a few 1e-15 m
    off)."""
    folder = Path(__file__).parents[2] / "data" / "peridigm_corpus" / "PrecrackedPlateTwoCracks"
    gold = read_exodus(folder / "PrecrackedPlate_gold.e").coordinates
    points = mesh_points(read_exodus(folder / "Plate.g")).points
    assert points.shape == gold.shape == (640, 3)
    assert np.array_equal(points, gold)
