"""VTK output for ParaView: point clouds as .vtu files (one, or per-rank pieces joined by a .pvtu
file) and .pvd time collections."""

from __future__ import annotations

import base64
import math
import os
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from peridyn.errors import InputError


def write_vtu(
    path: str | os.PathLike, points, point_data: dict, compression: str = "none", time: float | None = None
) -> None:
    """Write points and their fields as an unstructured grid of VTK_VERTEX cells.

    Parameters
    ----------
    path : str or path-like
        The .vtu file to write (overwritten).
    points : array_like, shape (n_points, dim)
        Coordinates in m, ``dim`` 2 or 3; 2-D points get ``z = 0``.
    point_data : dict of str to array_like
        Fields of shape ``(n_points,)`` (scalars) or ``(n_points, k)``.
        Two-component vectors are padded with a zero third component so that
        ParaView shows them as vectors; booleans are written as uint8.
    compression : {"none", "zlib"}
        The data arrays' compression (``VTU_COMPRESSIONS``). zlib makes a snapshot of
        displacements and velocities about 0.7 times the size and takes 8 times as long to
        write (125 000 points: 0.33 s against 0.04 s, benchmarks/RESULTS.md, "Output and I/O").
    time : float, optional
        The simulated time of the snapshot in s, stored as the field data ``TimeValue``
        (which ParaView reads as the data set's time, also outside a .pvd collection).

    Raises
    ------
    InputError
        An unknown compression, points of a bad shape, or a field whose first dimension is
        not ``n_points`` or that is not numeric.
    """
    if compression not in VTU_COMPRESSIONS:
        raise InputError(
            f"write_vtu: compression must be one of {sorted(VTU_COMPRESSIONS)}, got {compression!r}"
        )
    points = _pad_columns(np.asarray(points, dtype=np.float64))
    if points.ndim != 2 or points.shape[1] != 3:
        raise InputError(f"write_vtu: points must have shape (n_points, 2 or 3), got {points.shape}")
    n = points.shape[0]
    fields = {name: _vtk_field(name, values, n) for name, values in point_data.items()}
    if compression == "none":
        _write_streamed_vtu(Path(path), points, fields, time)
        return
    cells = [("vertex", np.arange(n, dtype=np.int64).reshape(-1, 1))]
    import meshio  # here: meshio and the rich console it loads cost 20 MB a process that writes no VTU

    mesh = meshio.Mesh(points, cells, point_data=fields)
    meshio.vtu.write(os.fspath(path), mesh, compression=VTU_COMPRESSIONS[compression])
    if time is not None:  # meshio writes no field data: the time goes in after it
        grid, path = b"<UnstructuredGrid>", Path(path)
        path.write_bytes(path.read_bytes().replace(grid, grid + _time_value(time), 1))


#: Bytes of an array encoded at a time (a multiple of 3, so that the base64 pieces join).
ENCODE_CHUNK = 3 << 20

#: VTK's cell type of a vertex.
VTK_VERTEX = 1


def _write_streamed_vtu(path: Path, points: np.ndarray, fields: dict, time: float | None) -> None:
    """An uncompressed .vtu file (base64 binary data arrays, as meshio writes them) whose arrays
    are encoded a few MiB at a time from their own memory, the vertex cells' arrays made in
    chunks: where meshio encodes each array whole, holding about 300 bytes a point while it
    writes (benchmarks/RESULTS.md), this holds a few MiB."""
    n = len(points)
    chunk = ENCODE_CHUNK // 8

    def counting(start):  # connectivity (0 ... n-1) or offsets (1 ... n) of the vertex cells
        return (np.arange(i + start, min(i + chunk, n) + start, dtype="<i8") for i in range(0, n, chunk))

    with open(path, "wb") as file:
        file.write(
            b'<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" version="1.0" '
            b'byte_order="LittleEndian" header_type="UInt64">\n<UnstructuredGrid>'
            + (b"" if time is None else _time_value(time))
            + f'\n<Piece NumberOfPoints="{n}" NumberOfCells="{n}">\n<Points>\n'.encode()
        )
        points = points.astype("<f8", copy=False)
        _write_array(file, "", [points], points.nbytes, "Float64", 3)
        file.write(b"</Points>\n<Cells>\n")
        _write_array(file, "connectivity", counting(0), 8 * n, "Int64", None)
        _write_array(file, "offsets", counting(1), 8 * n, "Int64", None)
        types = (np.full(min(chunk, n - i), VTK_VERTEX, "u1") for i in range(0, n, chunk))
        _write_array(file, "types", types, n, "UInt8", None)
        file.write(b"</Cells>\n<PointData>\n")
        for name, values in fields.items():
            dtype = values.dtype.newbyteorder("<")
            components = None if values.ndim == 1 else values.shape[1]
            values = values.astype(dtype, copy=False)
            _write_array(file, name, [values], values.nbytes, VTK_TYPES[dtype.name], components)
        file.write(b"</PointData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n")


def _write_array(file, name: str, parts, size: int, vtk_type: str, components: int | None) -> None:
    """One inline binary DataArray: base64 of its byte count ``size`` (UInt64) and the bytes of
    ``parts`` (contiguous arrays, in order), encoded ``ENCODE_CHUNK`` bytes at a time."""
    label = f' Name="{name}"' if name else ""
    label += "" if components is None else f' NumberOfComponents="{components}"'
    file.write(f'<DataArray type="{vtk_type}"{label} format="binary">\n'.encode())
    carry = np.uint64(size).astype("<u8").tobytes()
    for part in parts:
        data = memoryview(np.ascontiguousarray(part)).cast("B")
        for start in range(0, len(data), ENCODE_CHUNK):
            block = carry + data[start : start + ENCODE_CHUNK]
            whole = len(block) - len(block) % 3
            file.write(base64.b64encode(block[:whole]))
            carry = block[whole:]
    file.write(base64.b64encode(carry) + b"\n</DataArray>\n")


#: ``write_vtu``'s compressions: the case's ``output.vtu_compression`` -> meshio's argument.
VTU_COMPRESSIONS = {"none": None, "zlib": "zlib"}

#: VTK's names of the numpy types that ``write_vtu`` writes.
VTK_TYPES = {"float64": "Float64", "float32": "Float32", "uint8": "UInt8", "int64": "Int64", "int32": "Int32"}


def write_pvtu(path: str | os.PathLike, pieces: list, point_data: dict) -> None:
    """Write a ParaView parallel unstructured grid (.pvtu): the .vtu ``pieces`` (paths relative to
    the folder of ``path``, each written by ``write_vtu``) as one data set.

    Parameters
    ----------
    path : str or path-like
        The .pvtu file (written atomically).
    pieces : list of str
    point_data : dict of str to array_like
        The fields of one of the pieces (as given to ``write_vtu``): their names, types and
        numbers of components are declared.
    """
    root = ET.Element("VTKFile", type="PUnstructuredGrid", version="0.1", byte_order="LittleEndian")
    grid = ET.SubElement(root, "PUnstructuredGrid", GhostLevel="0")
    fields = ET.SubElement(grid, "PPointData")
    for name, values in point_data.items():
        values = _vtk_field(name, values, len(values))
        ET.SubElement(
            fields,
            "PDataArray",
            type=VTK_TYPES[values.dtype.name],
            Name=name,
            NumberOfComponents=str(1 if values.ndim == 1 else values.shape[1]),
        )
    points = ET.SubElement(grid, "PPoints")
    ET.SubElement(points, "PDataArray", type="Float64", NumberOfComponents="3")
    for piece in pieces:
        ET.SubElement(grid, "Piece", Source=Path(piece).as_posix())
    _write_xml(root, Path(path))


def read_pvtu_pieces(path: str | os.PathLike) -> list[Path]:
    """The piece files (absolute paths) that a .pvtu file lists."""
    path = Path(path)
    return [path.parent / piece.attrib["Source"] for piece in ET.parse(path).getroot().iter("Piece")]


class PVDCollection:
    """A ParaView .pvd file listing .vtu files by time.

    The whole file is rewritten atomically on each change, so it is valid at
    any moment, even while a run is still writing.

    Parameters
    ----------
    path : str or path-like
        The .pvd file.
    mode : {"w", "a"}
        ``"w"`` starts an empty collection (the file is written on the first
        :meth:`add`); ``"a"`` keeps the entries of an existing file, e.g. on
        restart from a checkpoint (a missing file starts empty).
    """

    def __init__(self, path: str | os.PathLike, mode: str = "w"):
        if mode not in ("w", "a"):
            raise InputError(f"PVDCollection: mode must be 'w' or 'a', got {mode!r}")
        self.path = Path(path)
        self._entries: list[tuple[float, str]] = []
        if mode == "a" and self.path.exists():
            self._entries = _read_pvd(self.path)

    @property
    def entries(self) -> list[tuple[float, str]]:
        """``(time in s, file)`` of each data set, in order."""
        return list(self._entries)

    def add(self, time: float, vtu_relative_path: str | os.PathLike) -> None:
        """List one more .vtu file and rewrite the collection.

        Parameters
        ----------
        time : float
            Simulated time in s; must exceed the last time listed.
        vtu_relative_path : str or path-like
            The .vtu file, relative to the directory of the .pvd file.

        Raises
        ------
        InputError
            The time is not finite or does not increase.
        """
        time = float(time)
        if not math.isfinite(time):
            raise InputError(f"{self.path}: time must be finite, got {time!r}")
        if self._entries and time <= self._entries[-1][0]:
            raise InputError(
                f"{self.path}: time {time!r} s does not exceed the last listed time "
                f"{self._entries[-1][0]!r} s (call truncate(time) after a restart)"
            )
        self._entries.append((time, Path(vtu_relative_path).as_posix()))
        self._write()

    def truncate(self, time: float) -> None:
        """Drop the entries later than ``time`` (s) and rewrite the collection."""
        self._entries = [entry for entry in self._entries if entry[0] <= time]
        self._write()

    def _write(self) -> None:
        root = ET.Element("VTKFile", type="Collection", version="0.1", byte_order="LittleEndian")
        collection = ET.SubElement(root, "Collection")
        for time, file in self._entries:
            ET.SubElement(collection, "DataSet", timestep=repr(time), group="", part="0", file=file)
        _write_xml(root, self.path)


def _write_xml(root: ET.Element, path: Path) -> None:
    """Write the XML tree ``root`` to ``path`` atomically (a temporary file renamed)."""
    ET.indent(root)
    tmp = path.with_name(path.name + ".tmp")
    ET.ElementTree(root).write(tmp, encoding="utf-8", xml_declaration=True)
    os.replace(tmp, path)


def _read_pvd(path: Path) -> list[tuple[float, str]]:
    """``(time, file)`` entries of an existing .pvd file."""
    try:
        root = ET.parse(path).getroot()
        return [(float(item.attrib["timestep"]), item.attrib["file"]) for item in root.iter("DataSet")]
    except (ET.ParseError, KeyError, ValueError) as exc:
        raise InputError(
            f"{path}: not a valid .pvd collection (expected DataSet elements with "
            f"'timestep' and 'file' attributes): {exc}"
        ) from None


def _time_value(time: float) -> bytes:
    """The VTK field data holding a data set's time in s (``TimeValue``, read by ParaView)."""
    return (
        '<FieldData><DataArray type="Float64" Name="TimeValue" NumberOfTuples="1" format="ascii">'
        f"{float(time)!r}</DataArray></FieldData>"
    ).encode()


def _pad_columns(array: np.ndarray) -> np.ndarray:
    """Pad a ``(n, 2)`` array with a zero third column; other shapes pass through."""
    if array.ndim == 2 and array.shape[1] == 2:
        return np.column_stack([array, np.zeros(array.shape[0], dtype=array.dtype)])
    return array


def _vtk_field(name: str, values, n: int) -> np.ndarray:
    values = np.asarray(values)
    if values.ndim not in (1, 2) or values.shape[0] != n:
        raise InputError(
            f"write_vtu: field {name!r} has shape {values.shape}, expected ({n},) or ({n}, k) for {n} points"
        )
    if values.dtype.kind == "b":
        values = values.astype(np.uint8)
    if values.dtype.kind not in "iuf":
        raise InputError(f"write_vtu: field {name!r} must be numeric, got dtype {values.dtype}")
    return _pad_columns(values)
