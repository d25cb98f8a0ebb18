"""Exodus II results out: points as SPHERE elements, time steps appended as a run goes.

The file follows the layout Peridigm writes (see ``peridyn.io.exodus`` for the schema):
one SPHERE element of one node per point, one element block per material block, node sets,
``time_whole``, nodal variables ``vals_nod_var<i>`` (a vector field ``Displacement`` becomes
``DisplacementX``, ``DisplacementY`` [, ``DisplacementZ``], Peridigm's names), element
variables ``vals_elem_var<i>eb<j>`` on every block, and global variables ``vals_glo_var``.
It is netCDF-3 (64-bit offset, as Exodus's ``file_size = 1`` says) written with
``scipy.io.netcdf_file``: no extra dependency, and readable by ParaView, the Exodus library,
netCDF4 and scipy.

Why append: scipy writes a whole file at once, so the first :meth:`ExodusWriter.append` writes
the mesh and the first time step with scipy, and each later step is appended in place as one
netCDF-3 record (the values of every ``time_step`` variable, big-endian, in header order)
before the record count in the header is raised. The file is valid after every step (a run
that fails keeps what it wrote), memory stays that of one step, and a restart drops the steps
after its checkpoint (:meth:`ExodusWriter.resume`).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import scipy.io

from peridyn.errors import InputError
from peridyn.io.reserve import as_disk_error, ensure_room

#: Exodus API version written in the file (the attributes ``api_version`` and ``version``).
EXODUS_VERSION = np.float32(8.06)
#: Offset of the record count in a netCDF-3 file (after the magic "CDF" and version byte).
NUMRECS_OFFSET = 4
#: Longest name the Exodus library reads.
MAX_NAME = 255
COMPONENTS = "XYZ"
#: Peridigm's output variables that peridyn writes: name -> (placement, vector). Nodal vectors:
#: displacement (m), velocity (m/s), force (N), force density (N/m^3), acceleration (m/s^2),
#: external (body) force density (N/m^3); element scalars: 1-based id, 0-based id (``ID``, the
#: older decks' name), rank, volume (m^3), dilatation, weighted volume (m^5), stored elastic
#: energy (J, energy density times volume), number of neighbours, damage and the plastic
#: multiplier (``Lambda``: 0, elastic materials); global: the kinetic energy (J).
PERIDIGM_VARIABLES = {
    "Displacement": ("nodal", True),
    "Velocity": ("nodal", True),
    "Force": ("nodal", True),
    "Force_Density": ("nodal", True),
    "Acceleration": ("nodal", True),
    "External_Force_Density": ("nodal", True),
    "Element_Id": ("element", False),
    "ID": ("element", False),
    "Proc_Num": ("element", False),
    "Volume": ("element", False),
    "Dilatation": ("element", False),
    "Weighted_Volume": ("element", False),
    "Stored_Elastic_Energy": ("element", False),
    "Number_Of_Neighbors": ("element", False),
    "Horizon": ("element", False),
    "Damage": ("element", False),
    "Lambda": ("element", False),
    "Global_Kinetic_Energy": ("global", False),
}


def component_names(fields: dict[str, int], dim: int) -> list[str]:
    """Exodus variable names of ``fields`` (name -> components, 1 for a scalar): a vector field
    ``F`` of ``dim`` components gives ``FX``, ``FY`` (, ``FZ``)."""
    names = []
    for name, k in fields.items():
        if k == 1:
            names.append(name)
        elif k == dim:
            names += [name + c for c in COMPONENTS[:dim]]
        else:
            raise InputError(f"Exodus field {name!r}: {k} components, expected 1 or {dim}")
    return names


class ExodusWriter:
    """Write points and their fields, one time step at a time, as an Exodus II file.

    Parameters
    ----------
    path : str or path-like
        The file to write (overwritten at the first :meth:`append`).
    points : (n, dim) float64, m
        Point coordinates, ``dim`` 2 or 3.
    blocks : list of (id, name, indices) or None
        Element blocks: integer id, name and (k,) point indices; every point in exactly one.
        None: one block ``block_1`` (id 1) of all points.
    node_sets : dict of name -> (k,) point indices
        Written with ids 1, 2, ... in this order; empty sets are left out (netCDF-3 has no
        empty dimension).
    nodal, element, global_ : dict of name -> components
        The fields given to :meth:`append`: 1 for a scalar, ``dim`` for a vector. Nodal and
        element fields have a value per point, global fields one value (or vector).
    title : str
    volumes : (n,) float64 or None, m^3
        Each point's volume, written as its SPHERE element's attributes (radius of the sphere
        of that volume, volume), Peridigm's sphere-mesh convention: the file then reads back as
        a mesh (``peridyn.io.exodus.mesh_points``). None: no attributes.
    """

    def __init__(
        self,
        path,
        points,
        blocks=None,
        node_sets=None,
        nodal=None,
        element=None,
        global_=None,
        title: str = "peridyn",
        volumes=None,
    ):
        self.path = Path(path)
        self.points = np.asarray(points, dtype=np.float64)
        if self.points.ndim != 2 or self.points.shape[1] not in (2, 3):
            raise InputError(f"Exodus points must have shape (n, 2 or 3), got {self.points.shape}")
        n = len(self.points)
        if n == 0:
            raise InputError("an Exodus file needs at least one point")
        self.dim = self.points.shape[1]
        self.blocks = [(1, "block_1", np.arange(n))] if blocks is None else _checked_blocks(blocks, n)
        self.node_sets = {k: np.asarray(v, dtype=np.int64) for k, v in (node_sets or {}).items() if len(v)}
        self.fields = {
            "nodal": dict(nodal or {}),
            "element": dict(element or {}),
            "global": dict(global_ or {}),
        }
        self.names = {kind: component_names(f, self.dim) for kind, f in self.fields.items()}
        self.title = title
        self.volumes = None if volumes is None else np.asarray(volumes, dtype=np.float64)
        if self.volumes is not None and self.volumes.shape != (n,):
            raise InputError(f"Exodus volumes must have shape ({n},), got {self.volumes.shape}")
        self.n_steps = 0
        self._begin = None  # file offset of the first record

    @property
    def record_size(self) -> int:
        """Bytes of one record: time, nodal, element and global values, all float64."""
        n = len(self.points)
        values = 1 + n * len(self.names["nodal"]) + n * len(self.names["element"])
        return 8 * (values + len(self.names["global"]))

    def append(self, time: float, nodal=None, element=None, global_=None) -> None:
        """Add a time step (s) with the value of every declared field.

        ``nodal`` and ``element``: dict of name -> (n,) or (n, dim); ``global_``: dict of
        name -> scalar or (dim,).
        """
        values = {
            "nodal": self._columns("nodal", nodal or {}, len(self.points)),
            "element": self._columns("element", element or {}, len(self.points)),
            "global": self._columns("global", global_ or {}, None),
        }
        if self._begin is None:
            self._create(float(time), values)
            return
        record = [np.array([time], dtype=">f8")]
        record += [c.astype(">f8") for c in values["nodal"]]
        for _, _, idx in self.blocks:
            record += [c[idx].astype(">f8") for c in values["element"]]
        record.append(np.array(values["global"], dtype=">f8"))
        data = b"".join(r.tobytes() for r in record)
        at = self._begin + self.n_steps * self.record_size
        ensure_room(self.path, len(data))  # refused whole rather than failed half-way
        try:
            with open(self.path, "r+b") as f:
                f.seek(at)
                f.write(data)
                f.flush()  # the record on disk before the count that makes it part of the file
                f.seek(NUMRECS_OFFSET)
                f.write(np.array(self.n_steps + 1, dtype=">i4").tobytes())
        except OSError as exc:  # a full or failing disk: the steps written stay the file's
            self._drop_from(at)
            raise as_disk_error(exc, self.path) from exc
        self.n_steps += 1

    def _drop_from(self, at: int) -> None:
        """Cut a record that failed to be written at byte ``at`` and restore the step count
        (as far as the disk lets: a record past the count is never read)."""
        try:
            with open(self.path, "r+b") as f:
                f.truncate(at)
                f.seek(NUMRECS_OFFSET)
                f.write(np.array(self.n_steps, dtype=">i4").tobytes())
        except OSError:
            pass

    def resume(self, time: float) -> None:
        """Continue an existing file written by this layout, dropping its steps after ``time``
        (s): a restart from a checkpoint. Without the file, the next append starts anew."""
        if not self.path.exists():
            return
        with scipy.io.netcdf_file(self.path, "r", mmap=False) as f:
            times = np.array(f.variables["time_whole"].data)
            names = {k: _read_names(f, key) for k, key in _NAME_VARS.items()}
        if names != self.names or len(times) == 0:
            raise InputError(f"{self.path}: its variables differ from this run's, cannot continue it")
        keep = int(np.count_nonzero(times <= time))
        self._begin = self.path.stat().st_size - len(times) * self.record_size
        self.n_steps = keep
        with open(self.path, "r+b") as f:
            f.truncate(self._begin + keep * self.record_size)
            f.seek(NUMRECS_OFFSET)
            f.write(np.array(keep, dtype=">i4").tobytes())

    def _columns(self, kind: str, given: dict, n: int | None) -> list[np.ndarray]:
        """The declared fields of one kind as a list of columns in variable-name order."""
        declared = self.fields[kind]
        if set(given) != set(declared):
            raise InputError(f"Exodus {kind} fields: got {sorted(given)}, declared {sorted(declared)}")
        columns = []
        for name, k in declared.items():
            shape = ((n,) if n is not None else ()) + ((k,) if k > 1 else ())
            value = np.asarray(given[name], dtype=np.float64)
            if value.shape != shape:
                raise InputError(f"Exodus field {name!r}: shape {value.shape}, expected {shape}")
            columns += [value[..., c] for c in range(k)] if k > 1 else [value]
        return columns

    def _create(self, time: float, values: dict) -> None:
        """Write the mesh and the first step with scipy."""
        names = [b[1] for b in self.blocks] + list(self.node_sets) + sum(self.names.values(), [])
        longest = max(max(len(s) for s in names), 32)
        if longest > MAX_NAME:
            raise InputError(f"Exodus names are at most {MAX_NAME} characters: {max(names, key=len)!r}")
        tmp = self.path.with_name(self.path.name + ".tmp")
        try:
            with scipy.io.netcdf_file(tmp, "w", version=2) as f:
                self._header(f, longest + 1)
                self._fixed(f)
                self._records(f, time, values)
            os.replace(tmp, self.path)
        except OSError as exc:  # a full or failing disk, named as the file it was for
            raise as_disk_error(exc, self.path) from exc
        finally:
            tmp.unlink(missing_ok=True)
        self._begin = self.path.stat().st_size - self.record_size
        self.n_steps = 1

    def _header(self, f, len_name: int) -> None:
        f.api_version = EXODUS_VERSION
        f.version = EXODUS_VERSION
        f.floating_point_word_size = np.int32(8)
        f.file_size = np.int32(1)
        f.maximum_name_length = np.int32(len_name - 1)
        f.int64_status = np.int32(0)
        f.title = self.title
        n = len(self.points)
        f.createDimension("time_step", None)  # scipy wants the unlimited dimension first
        f.createDimension("len_name", len_name)
        f.createDimension("num_dim", self.dim)
        f.createDimension("num_nodes", n)
        f.createDimension("num_elem", n)
        f.createDimension("num_el_blk", len(self.blocks))
        if self.node_sets:
            f.createDimension("num_node_sets", len(self.node_sets))
        for kind, dim_name in _COUNT_DIMS.items():
            if self.names[kind]:
                f.createDimension(dim_name, len(self.names[kind]))

    def _fixed(self, f) -> None:
        n = len(self.points)
        _int_var(f, "eb_status", ("num_el_blk",), np.ones(len(self.blocks)))
        _int_var(f, "eb_prop1", ("num_el_blk",), [b[0] for b in self.blocks]).name = "ID"
        _name_var(f, "eb_names", "num_el_blk", [b[1] for b in self.blocks])
        if self.node_sets:
            ids = np.arange(1, len(self.node_sets) + 1)
            _int_var(f, "ns_status", ("num_node_sets",), np.ones(len(ids)))
            _int_var(f, "ns_prop1", ("num_node_sets",), ids).name = "ID"
            _name_var(f, "ns_names", "num_node_sets", list(self.node_sets))
            for k, idx in enumerate(self.node_sets.values(), start=1):
                f.createDimension(f"num_nod_ns{k}", len(idx))
                _int_var(f, f"node_ns{k}", (f"num_nod_ns{k}",), idx + 1)
        for axis, c in enumerate("xyz"[: self.dim]):
            f.createVariable(f"coord{c}", "d", ("num_nodes",))[:] = self.points[:, axis]
        _name_var(f, "coor_names", "num_dim", list("xyz"[: self.dim]))
        element_order = np.concatenate([idx for _, _, idx in self.blocks])
        _int_var(f, "node_num_map", ("num_nodes",), np.arange(1, n + 1))
        _int_var(f, "elem_num_map", ("num_elem",), element_order + 1)
        for j, (_, _, idx) in enumerate(self.blocks, start=1):
            f.createDimension(f"num_el_in_blk{j}", len(idx))
            f.createDimension(f"num_nod_per_el{j}", 1)
            conn = _int_var(f, f"connect{j}", (f"num_el_in_blk{j}", f"num_nod_per_el{j}"), idx[:, None] + 1)
            conn.elem_type = "SPHERE"
            if self.volumes is not None:
                f.createDimension(f"num_att_in_blk{j}", 2)
                volume = self.volumes[idx]
                radius = np.cbrt(3.0 * volume / (4.0 * np.pi))
                attrib = f.createVariable(f"attrib{j}", "d", (f"num_el_in_blk{j}", f"num_att_in_blk{j}"))
                attrib[:] = np.column_stack([radius, volume])
        if self.names["element"]:
            tab = np.ones((len(self.blocks), len(self.names["element"])))
            _int_var(f, "elem_var_tab", ("num_el_blk", "num_elem_var"), tab)
        for kind, key in _NAME_VARS.items():
            if self.names[kind]:
                _name_var(f, key, _COUNT_DIMS[kind], self.names[kind])

    def _records(self, f, time: float, values: dict) -> None:
        """Declare the record variables in the order :meth:`append` writes them."""
        f.createVariable("time_whole", "d", ("time_step",))[:] = [time]
        for i, column in enumerate(values["nodal"], start=1):
            var = f.createVariable(f"vals_nod_var{i}", "d", ("time_step", "num_nodes"))
            var[:] = column[None, :]
        for j, (_, _, idx) in enumerate(self.blocks, start=1):
            for i, column in enumerate(values["element"], start=1):
                var = f.createVariable(f"vals_elem_var{i}eb{j}", "d", ("time_step", f"num_el_in_blk{j}"))
                var[:] = column[idx][None, :]
        if self.names["global"]:
            var = f.createVariable("vals_glo_var", "d", ("time_step", "num_glo_var"))
            var[:] = np.array(values["global"], dtype=np.float64)[None, :]


_NAME_VARS = {"nodal": "name_nod_var", "element": "name_elem_var", "global": "name_glo_var"}
_COUNT_DIMS = {"nodal": "num_nod_var", "element": "num_elem_var", "global": "num_glo_var"}


def _checked_blocks(blocks, n: int) -> list:
    out = [(int(i), str(name), np.asarray(idx, dtype=np.int64)) for i, name, idx in blocks]
    counts = np.bincount(np.concatenate([idx for _, _, idx in out]), minlength=n)
    if len(counts) != n or np.any(counts != 1):
        raise InputError(f"Exodus blocks must hold each of the {n} points exactly once")
    if any(len(idx) == 0 for _, _, idx in out):
        raise InputError("an Exodus block must hold at least one point")
    return out


def _int_var(f, name: str, dims: tuple, values):
    var = f.createVariable(name, "i", dims)
    var[:] = np.asarray(values, dtype=np.int32)
    return var


def _name_var(f, name: str, count_dim: str, names: list[str]) -> None:
    width = f.dimensions["len_name"]
    table = np.zeros((len(names), width), dtype="S1")
    for k, s in enumerate(names):
        raw = s.encode("latin-1")
        table[k, : len(raw)] = np.frombuffer(raw, dtype="S1")
    f.createVariable(name, "c", (count_dim, "len_name"))[:] = table


def _read_names(f, key: str) -> list[str]:
    if key not in f.variables:
        return []
    return [row.tobytes().split(b"\x00", 1)[0].decode("latin-1") for row in np.asarray(f.variables[key].data)]
