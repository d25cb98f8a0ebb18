"""Exodus II meshes and results in: reading a file, and turning its elements into points.

Exodus II (Sandia, "EXODUS: A Finite Element Data Model") is a netCDF schema: dimensions
``num_nodes``, ``num_dim``, ``num_elem``, ``num_el_blk``; coordinates ``coordx/coordy/coordz``;
element blocks ``connect<j>`` (attribute ``elem_type``) with ids ``eb_prop1`` and names
``eb_names``; node sets ``node_ns<k>`` (ids ``ns_prop1``, names ``ns_names``); side sets
``elem_ss<k>``/``side_ss<k>``; times ``time_whole``; nodal, element and global variables
``vals_nod_var<i>``, ``vals_elem_var<i>eb<j>``, ``vals_glo_var`` named by ``name_nod_var``,
``name_elem_var``, ``name_glo_var``. Files are read with ``scipy.io.netcdf_file``, which reads
the netCDF-3 (classic and 64-bit offset) files that Cubit, Peridigm and the Exodus library
write by default: no extra dependency. netCDF-4 (HDF5-based) Exodus files are refused with a
clear error.

:func:`mesh_points` makes one point per element, as Peridigm's ``ExodusDiscretization`` does
(see ``docs/user-guide.md``, "Exodus in and out"):

- HEX (8 nodes; the mid-side nodes of HEX20/HEX27 are ignored): the hexahedron is split into
  24 tetrahedra, each from an edge of a face, the face's barycentre (mean of its 4 nodes) and
  the hexahedron's barycentre (mean of its 8 nodes). The point is the volume-weighted mean of
  the tetrahedra's centroids and its volume their sum. The volume is exact for a hexahedron
  with planar faces and, for warped faces, equals the volume of the trilinear (isoparametric)
  hexahedron; the centroid is exact for planar faces.
- TETRA (4 nodes; mid-edge nodes of TETRA10 ignored): the vertex mean and the exact volume.
- SPHERE: the node itself, with the volume from the block's second attribute (Sierra's and
  Peridigm's convention: attribute 1 is the radius, attribute 2 the volume).

Blocks without a name are called ``block_<id>``, node sets ``nodelist_<id>`` and side sets
``sideset_<id>`` (Peridigm's names). A node set becomes the points of every element that
contains at least one of its nodes (Peridigm's rule); a side set becomes the points of the
elements it lists.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field

import numpy as np
import scipy.io

from peridyn.discretization.body import Body
from peridyn.errors import InputError
from peridyn.io.mesh_text import volume_cells

#: HEX8 faces (Exodus node numbering, 0-based), in the order and with the nodes Peridigm's
#: ``hexCentroidAndVolume`` sums for each face's barycentre.
HEX_FACES = [(0, 1, 4, 5), (1, 2, 5, 6), (2, 3, 6, 7), (0, 3, 4, 7), (0, 1, 2, 3), (4, 5, 6, 7)]


@dataclass(frozen=True)
class ElementBlock:
    """One element block.

    Attributes
    ----------
    id : int
        The block id (``eb_prop1``).
    name : str
        Its name (``block_<id>`` when the file gives none).
    element_type : str
        ``elem_type`` in upper case, e.g. ``HEX8``, ``TETRA``, ``SPHERE``.
    connectivity : (n_elements, nodes_per_element) int64
        0-based node indices.
    attributes : (n_elements, n_attributes) float64
        Element attributes (``attrib<j>``; no columns when there are none).
    """

    id: int
    name: str
    element_type: str
    connectivity: np.ndarray
    attributes: np.ndarray


@dataclass(frozen=True)
class NodeSet:
    """A node set: ``id``, ``name`` (``nodelist_<id>`` when unnamed) and ``nodes`` (n,) 0-based."""

    id: int
    name: str
    nodes: np.ndarray


@dataclass(frozen=True)
class SideSet:
    """A side set: ``id``, ``name`` (``sideset_<id>`` when unnamed), ``elements`` (n,) 0-based
    global element indices (blocks in file order) and ``sides`` (n,) 1-based local side numbers."""

    id: int
    name: str
    elements: np.ndarray
    sides: np.ndarray


@dataclass(frozen=True)
class ExodusMesh:
    """The content of an Exodus II file.

    Attributes
    ----------
    title : str
    coordinates : (n_nodes, num_dim) float64, m
    blocks : list of ElementBlock, in file order (global element numbering follows it)
    node_sets, side_sets : list of NodeSet, list of SideSet
    times : (n_steps,) float64, s
        ``time_whole`` (empty for a mesh without results).
    nodal_variables : dict of name -> (n_steps, n_nodes) float64
    element_variables : dict of name -> (n_steps, n_elements) float64
        Blocks concatenated in file order; NaN in the blocks that do not define the variable.
    global_variables : dict of name -> (n_steps,) float64
    """

    title: str
    coordinates: np.ndarray
    blocks: list[ElementBlock]
    node_sets: list[NodeSet] = field(default_factory=list)
    side_sets: list[SideSet] = field(default_factory=list)
    times: np.ndarray = field(default_factory=lambda: np.zeros(0))
    nodal_variables: dict = field(default_factory=dict)
    element_variables: dict = field(default_factory=dict)
    global_variables: dict = field(default_factory=dict)

    @property
    def n_elements(self) -> int:
        """Number of elements over all blocks."""
        return sum(len(b.connectivity) for b in self.blocks)

    def node_set(self, key: str | int) -> NodeSet:
        """The node set of this name or id; InputError naming the sets when there is none."""
        return _find(self.node_sets, key, "node set")

    def side_set(self, key: str | int) -> SideSet:
        """The side set of this name or id; InputError naming the sets when there is none."""
        return _find(self.side_sets, key, "side set")


def _find(items, key, what):
    for item in items:
        if item.name == key or item.id == key:
            return item
    known = [f"{i.name} (id {i.id})" for i in items]
    raise InputError(f"no {what} {key!r} in the mesh; it has: {known or 'none'}")


def read_exodus(path: str | os.PathLike) -> ExodusMesh:
    """Read an Exodus II file (netCDF-3).

    Raises
    ------
    InputError
        The file is missing, is not netCDF-3 (e.g. netCDF-4/HDF5) or lacks the Exodus
        dimensions and variables it needs; the message names the file.
    """
    path = os.fspath(path)
    try:
        f = scipy.io.netcdf_file(path, "r", mmap=False)
    except FileNotFoundError:
        raise InputError(f"Exodus file {path!r} does not exist") from None
    except MemoryError:  # the sizes its header gives do not fit in memory
        raise InputError(
            f"{path}: the variables its header declares do not fit in memory (a damaged file?)"
        ) from None
    except (OSError, TypeError, ValueError, KeyError, IndexError) as exc:  # a damaged header too
        raise InputError(
            f"{path}: not a netCDF-3 Exodus II file ({type(exc).__name__}: {exc}); convert a netCDF-4 "
            "file with `nccopy -k classic`"
        ) from None
    try:
        return _read(f, path)
    except KeyError as exc:
        raise InputError(f"{path}: not an Exodus II file, it lacks {exc.args[0]!r}") from None
    except InputError:
        raise
    except (ValueError, IndexError) as exc:  # variables whose sizes disagree with the dimensions
        raise InputError(f"{path}: a damaged Exodus II file ({type(exc).__name__}: {exc})") from None
    finally:
        f.close()


def _read(f, path: str) -> ExodusMesh:
    v, dims = f.variables, f.dimensions
    num_dim = int(dims["num_dim"])
    coordinates = np.column_stack([np.array(v[f"coord{a}"].data, dtype=np.float64) for a in "xyz"[:num_dim]])
    n_blocks = int(dims.get("num_el_blk", 0))
    block_ids = _ids(v, "eb_prop1", n_blocks)
    block_names = _names(v, "eb_names", n_blocks)
    blocks = []
    for j in range(n_blocks):
        conn = v[f"connect{j + 1}"]
        kind = _text(conn._attributes.get("elem_type", b"")).upper()
        connectivity = np.array(conn.data, dtype=np.int64) - 1
        attrib = f"attrib{j + 1}"
        attributes = (
            np.array(v[attrib].data, dtype=np.float64) if attrib in v else np.zeros((len(connectivity), 0))
        )
        blocks.append(
            ElementBlock(
                block_ids[j], block_names[j] or f"block_{block_ids[j]}", kind, connectivity, attributes
            )
        )
    n_ns = int(dims.get("num_node_sets", 0))
    ns_ids, ns_names = _ids(v, "ns_prop1", n_ns), _names(v, "ns_names", n_ns)
    node_sets = [
        NodeSet(ns_ids[k], ns_names[k] or f"nodelist_{ns_ids[k]}", _indices(v, f"node_ns{k + 1}"))
        for k in range(n_ns)
    ]
    n_ss = int(dims.get("num_side_sets", 0))
    ss_ids, ss_names = _ids(v, "ss_prop1", n_ss), _names(v, "ss_names", n_ss)
    side_sets = [
        SideSet(
            ss_ids[k],
            ss_names[k] or f"sideset_{ss_ids[k]}",
            _indices(v, f"elem_ss{k + 1}"),
            _indices(v, f"side_ss{k + 1}") + 1,
        )
        for k in range(n_ss)
    ]
    times = np.array(v["time_whole"].data, dtype=np.float64) if "time_whole" in v else np.zeros(0)
    nodal = {
        name: np.array(v[f"vals_nod_var{i + 1}"].data, dtype=np.float64)
        for i, name in enumerate(_names(v, "name_nod_var", int(dims.get("num_nod_var", 0))))
    }
    glob = {}
    if "vals_glo_var" in v:
        values = np.array(v["vals_glo_var"].data, dtype=np.float64)
        for i, name in enumerate(_names(v, "name_glo_var", int(dims["num_glo_var"]))):
            glob[name] = values[:, i]
    mesh = ExodusMesh(
        _text(f._attributes.get("title", b"")),
        coordinates,
        blocks,
        node_sets,
        side_sets,
        times,
        nodal,
        _element_variables(v, dims, blocks, len(times)),
        glob,
    )
    _check_indices(mesh, path)
    return mesh


def _element_variables(v, dims, blocks, n_steps) -> dict:
    names = _names(v, "name_elem_var", int(dims.get("num_elem_var", 0)))
    out = {}
    for i, name in enumerate(names):
        parts = []
        for j, block in enumerate(blocks):
            key = f"vals_elem_var{i + 1}eb{j + 1}"
            if key in v:
                values = np.array(v[key].data, dtype=np.float64)
                parts.append(values.reshape(n_steps, len(block.connectivity)))
            else:
                parts.append(np.full((n_steps, len(block.connectivity)), np.nan))
        out[name] = np.concatenate(parts, axis=1) if parts else np.zeros((n_steps, 0))
    return out


def _check_indices(mesh: ExodusMesh, path: str) -> None:
    n_nodes, n_elem = len(mesh.coordinates), mesh.n_elements
    for b in mesh.blocks:
        if b.connectivity.size and (b.connectivity.min() < 0 or b.connectivity.max() >= n_nodes):
            raise InputError(f"{path}: block {b.name} refers to nodes outside 1..{n_nodes}")
    for s in mesh.node_sets:
        if s.nodes.size and (s.nodes.min() < 0 or s.nodes.max() >= n_nodes):
            raise InputError(f"{path}: node set {s.name} refers to nodes outside 1..{n_nodes}")
    for s in mesh.side_sets:
        if s.elements.size and (s.elements.min() < 0 or s.elements.max() >= n_elem):
            raise InputError(f"{path}: side set {s.name} refers to elements outside 1..{n_elem}")


def _ids(v, key: str, n: int) -> list[int]:
    """Ids of ``n`` entities (``eb_prop1`` ...), 1..n when the file has none."""
    return [int(i) for i in v[key].data] if key in v else list(range(1, n + 1))


def _names(v, key: str, n: int) -> list[str]:
    """Names from a (n, len_name) char variable; empty strings when the file has none."""
    if key not in v:
        return [""] * n
    return [_text(row) for row in np.asarray(v[key].data).reshape(n, -1)]


def _indices(v, key: str) -> np.ndarray:
    """A 1-based index variable as 0-based int64 (empty when the file has no such variable:
    netCDF-3 cannot hold a zero-length fixed dimension, so empty sets have no data)."""
    return np.array(v[key].data, dtype=np.int64) - 1 if key in v else np.zeros(0, dtype=np.int64)


def _text(value) -> str:
    """A netCDF char array or byte string as text, without trailing NULs and blanks."""
    raw = value.tobytes() if isinstance(value, np.ndarray) else bytes(value)
    return raw.split(b"\x00", 1)[0].decode("latin-1").strip()


@dataclass(frozen=True)
class MeshPoints:
    """Points made from the elements of an Exodus mesh (one per element, blocks in file order).

    Attributes
    ----------
    points : (n, 3) float64, m
    volumes : (n,) float64, m^3
    block_ids : (n,) int64
        Exodus block id of each point.
    point_sets : dict of name -> (k,) int64
        Sorted point indices of each block (by block name), node set and side set.
    """

    points: np.ndarray
    volumes: np.ndarray
    block_ids: np.ndarray
    point_sets: dict


def mesh_points(mesh: ExodusMesh) -> MeshPoints:
    """One point per element: centroid and volume of HEX and TETRA elements, the node and
    volume attribute of SPHERE elements; node and side sets as sets of points.

    Raises
    ------
    InputError
        The mesh is not 3-D, has no elements, a block has another element type or too few
        nodes per element, an element has a non-finite node coordinate or a non-positive
        volume (inverted node order), or two sets share a name.
    """
    if mesh.coordinates.shape[1] != 3:
        raise InputError(f"an Exodus mesh for points must be 3-D, this one has {mesh.coordinates.shape[1]}")
    if mesh.n_elements == 0:
        raise InputError("the Exodus mesh has no elements")
    centroids, volumes = zip(*(_block_points(mesh.coordinates, b) for b in mesh.blocks), strict=True)
    points, volumes = np.concatenate(centroids), np.concatenate(volumes)
    bad = np.flatnonzero(~np.isfinite(points).all(axis=1))
    if bad.size:
        raise InputError(
            f"element {bad[0] + 1} has a non-finite node coordinate (its point {points[bad[0]].tolist()})"
        )
    bad = np.flatnonzero(~(volumes > 0))
    if bad.size:
        raise InputError(
            f"element {bad[0] + 1} has volume {volumes[bad[0]]!r} m^3: it must be positive "
            "(check the node order of the element)"
        )
    block_ids = np.concatenate([np.full(len(b.connectivity), b.id, dtype=np.int64) for b in mesh.blocks])
    sets = {}
    start = 0
    for b in mesh.blocks:
        _add_set(sets, b.name, np.arange(start, start + len(b.connectivity)), "block")
        start += len(b.connectivity)
    for s in mesh.node_sets:
        _add_set(sets, s.name, elements_touching(mesh, s.nodes), "node set")
    for s in mesh.side_sets:
        _add_set(sets, s.name, np.unique(s.elements), "side set")
    return MeshPoints(points, volumes, block_ids, sets)


def _add_set(sets: dict, name: str, idx: np.ndarray, what: str) -> None:
    if name in sets:
        raise InputError(f"the Exodus mesh has two sets named {name!r} (a {what} and a block or set)")
    sets[name] = idx


def elements_touching(mesh: ExodusMesh, nodes: np.ndarray) -> np.ndarray:
    """(k,) sorted global indices of the elements that contain at least one of ``nodes``."""
    member = np.zeros(len(mesh.coordinates), dtype=bool)
    member[nodes] = True
    hit = np.concatenate([member[b.connectivity].any(axis=1) for b in mesh.blocks])
    return np.flatnonzero(hit)


def _block_points(coordinates: np.ndarray, block: ElementBlock) -> tuple[np.ndarray, np.ndarray]:
    """(n, 3) centroids and (n,) volumes of the elements of one block."""
    kind, conn = block.element_type, block.connectivity
    need = {"HEX": 8, "TET": 4, "SPHERE": 1}
    family = next((k for k in need if kind.startswith(k)), None)
    if family is None:
        raise InputError(
            f"block {block.name}: element type {kind!r} cannot be turned into points "
            "(HEX, TETRA and SPHERE can)"
        )
    if conn.shape[1] < need[family]:
        raise InputError(
            f"block {block.name}: a {kind} element needs {need[family]} nodes, has {conn.shape[1]}"
        )
    if family == "SPHERE":
        if block.attributes.shape[1] < 2:
            raise InputError(
                f"block {block.name}: SPHERE elements need the volume as their second attribute "
                f"(radius, volume), the block has {block.attributes.shape[1]} attributes"
            )
        return coordinates[conn[:, 0]], block.attributes[:, 1].copy()
    if family == "TET":
        return tet_centroid_volume(coordinates[conn[:, :4]])
    return hex_centroid_volume(coordinates[conn[:, :8]])


def tet_centroid_volume(nodes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Centroids (n, 3) and signed volumes (n,) of tetrahedra ``nodes`` (n, 4, 3), m and m^3
    (positive for Exodus node order: nodes 1-2-3 counter-clockwise seen from node 4)."""
    a = nodes[:, 0]
    volume = np.einsum("ij,ij->i", nodes[:, 1] - a, np.cross(nodes[:, 2] - a, nodes[:, 3] - a)) / 6.0
    return nodes.mean(axis=1), volume


def _tet_volume(p0, p1, p2, p3) -> np.ndarray:
    """(n,) signed volumes of the tetrahedra p0 p1 p2 p3 (each (n, 3), m), m^3: the scalar
    triple product a . (b x c) / 6 of the edges from p0, term by term as Peridigm's
    ``scalarTripleProduct``."""
    a, b, c = p1 - p0, p2 - p0, p3 - p0
    triple = a[:, 0] * (b[:, 1] * c[:, 2] - b[:, 2] * c[:, 1])
    triple = triple + a[:, 1] * (b[:, 2] * c[:, 0] - b[:, 0] * c[:, 2])
    triple = triple + a[:, 2] * (b[:, 0] * c[:, 1] - b[:, 1] * c[:, 0])
    return triple / 6.0


#: The 24 tetrahedra of a hexahedron as Peridigm's ``hexCentroidAndVolume`` orders them: (first
#: node, second node, face) with the face's barycentre and the hexahedron's as the last two.
HEX_TETRAHEDRA = [
    (1, 0, 0), (5, 1, 0), (4, 5, 0), (0, 4, 0), (2, 1, 1), (6, 2, 1), (5, 6, 1), (1, 5, 1),
    (3, 2, 2), (7, 3, 2), (6, 7, 2), (2, 6, 2), (0, 3, 3), (3, 7, 3), (7, 4, 3), (4, 0, 3),
    (0, 1, 4), (1, 2, 4), (2, 3, 4), (3, 0, 4), (5, 4, 5), (4, 7, 5), (7, 6, 5), (6, 5, 5),
]  # fmt: skip


def hex_centroid_volume(nodes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Centroids (n, 3) and signed volumes (n,) of hexahedra ``nodes`` (n, 8, 3) in Exodus
    order, m and m^3, from 24 tetrahedra (face edge, face barycentre, hexahedron barycentre),
    operation by operation as Peridigm's ``hexCentroidAndVolume`` (its GeometryUtils): the
    points of a deck's mesh are Peridigm's to the last bit (a bond filter's plane through mesh
    points' bonds then decides them as Peridigm does)."""
    n = [nodes[:, k] for k in range(8)]
    faces = [0.25 * (((n[a] + n[b]) + n[c]) + n[d]) for a, b, c, d in HEX_FACES]
    centre = 0.5 * (faces[4] + faces[5])
    volume = np.zeros(len(nodes))
    moment = np.zeros((len(nodes), 3))
    for first, second, face in HEX_TETRAHEDRA:
        p = (n[first], n[second], faces[face], centre)
        v = _tet_volume(*p)
        volume = volume + v
        moment = moment + ((((p[0] + p[1]) + p[2]) + p[3]) * 0.25) * v[:, None]
    return moment / volume[:, None], volume


def body_from_exodus(
    path: str | os.PathLike, dim: int = 3, thickness: float | None = None, plane: str | None = None
) -> Body:
    """A body from an Exodus mesh: a point per element (:func:`mesh_points`) with the element's
    volume (m^3), node sets of each block (by name), node set and side set. 3D: cells taken as
    cubes of the volume. 2D (``dim`` 2, a body of ``thickness`` m in ``plane`` "stress" or
    "strain"): one layer of elements, every point at the same z (else an InputError), placed
    at z = 0; cells squares of area volume / thickness, as Peridigm's 2D decks read a one-layer
    hex mesh."""
    mesh = read_exodus(path)
    try:
        pts = mesh_points(mesh)
    except InputError as exc:  # a block the points cannot be made of: which file's
        raise InputError(f"{os.fspath(path)}: {exc}") from None
    points = pts.points
    if dim == 2:
        z = points[:, 2]
        if np.ptp(z) > 1e-12 * max(1.0, float(np.max(np.abs(points)))):
            raise InputError(
                f"{path}: a 2D body needs one layer of elements (its points at z from {z.min():g} "
                f"to {z.max():g} m)"
            )
        points = points * [1.0, 1.0, 0.0]  # the layer in the plane z = 0 of a 2D body
    cells, side = volume_cells(pts.volumes, dim, thickness, "Exodus mesh")
    return Body(
        points=points,
        volumes=pts.volumes,
        cells=cells,
        dim=dim,
        spacing=float(np.median(side)),
        node_sets=pts.point_sets,
        thickness=thickness if dim == 2 else None,
        plane=plane if dim == 2 else None,
    )
