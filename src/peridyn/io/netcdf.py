"""netCDF-4 conventions in results files: named dimensions, coordinates, units.

A results file (``peridyn.io.hdf5``) labels each dataset the way netCDF-4 does, with HDF5
dimension scales, so that netCDF readers (``xarray.open_dataset(path, engine="h5netcdf",
group="series/sensor_u")``, ``xarray.open_datatree``, ``ncdump``) see named dimensions and
coordinates:

- every axis of a dataset is a dimension, a scale in the dataset's own group: a coordinate
  variable (its values label the axis: ``time`` in s, ``component`` x/y/z, ``sensor`` names,
  ``point`` indices of a probe) or a bare dimension (netCDF's "dimension but not a variable"),
  so that each group opens on its own;
- data variables carry ``units`` (UDUNITS spelling, "1" for a ratio) and ``long_name``;
- the root shows one series (``write_root_view``), so that ``xarray.open_dataset(path)``
  without a group reads a labelled time series: the sensors' displacement when there are
  sensors, else the first series by name. Its records run along the root's own dimension
  ``record``, with ``time`` (s) and ``step`` as coordinates: a root dimension is inherited by
  every group (netCDF-4), and ``time`` has another length in each series, so the root does not
  name its records ``time``; for the same reason an axis whose name another group uses with
  other labels (a line's ``point``) is prefixed with the series' name at the root.
"""

from __future__ import annotations

import h5py
import numpy as np

from peridyn.errors import InputError
from peridyn.io import integrity

#: Labels of the x, y, z component axis of vectors.
COMPONENTS = ("x", "y", "z")

#: The NAME netCDF-4 gives a dimension that has no coordinate values (its length follows).
BARE_DIMENSION = "This is a netCDF dimension but not a netCDF variable."


def label(dataset: h5py.Dataset, dims, coords: dict | None = None) -> None:
    """Name each axis of ``dataset``: attach the scale ``dims[i]`` of its group, made here if
    missing: the coordinate ``coords[name]`` (values along the axis: numbers, or strings such as
    :data:`COMPONENTS`) or a bare dimension.

    Raises
    ------
    InputError
        ``dims`` does not name every axis, or a dimension of the group already has another length.
    """
    dims = tuple(dims)
    if len(dims) != dataset.ndim:
        raise InputError(f"{dataset.name}: {len(dims)} dimension names {dims} for {dataset.ndim} axes")
    group = dataset.parent
    for axis, name in enumerate(dims):
        scale = _scale(group, name, dataset.shape[axis], (coords or {}).get(name), dataset.name)
        dataset.dims[axis].attach_scale(scale)


def describe(node: h5py.Dataset | h5py.Group, units: str, long_name: str) -> None:
    """The CF attributes ``units`` and ``long_name`` of a variable."""
    node.attrs["units"] = units
    node.attrs["long_name"] = long_name


def _scale(group: h5py.Group, name: str, length: int, values, user: str) -> h5py.Dataset:
    if name in group:
        scale = group[name]
        if not isinstance(scale, h5py.Dataset) or scale.ndim != 1:
            raise InputError(f"{user}: dimension {name!r} clashes with {scale.name}")
        if scale.maxshape[0] is not None and len(scale) != length:  # an unlimited one grows
            raise InputError(
                f"{user}: dimension {name!r} has length {len(scale)} in {group.name}, not {length}"
            )
        if not scale.is_scale:
            scale.make_scale(name)
        return scale
    if values is None:
        scale = group.create_dataset(name, (length,), np.float32)
        integrity.stamp_whole(scale, np.zeros(length, np.float32))
        scale.make_scale(name)
        scale.attrs["NAME"] = np.bytes_(f"{BARE_DIMENSION}{length:10d}")
        return scale
    values = np.asarray(values)
    if values.shape != (length,):
        raise InputError(f"{user}: coordinate {name!r} has shape {values.shape}, not ({length},)")
    if values.dtype.kind in "US":
        values = np.array([str(v) for v in values], dtype=h5py.string_dtype())
    scale = group.create_dataset(name, data=values)
    integrity.stamp_whole(scale, values)
    scale.make_scale(name)
    return scale


#: The root's dimension of its series' records (see the module docstring).
ROOT_RECORDS = "record"


def root_series(names) -> str | None:
    """The series the root shows: ``sensor_u`` if among ``names``, else the first by name."""
    names = sorted(names)
    return "sensor_u" if "sensor_u" in names else (names[0] if names else None)


def write_root_view(f: h5py.File, name: str) -> None:
    """Show the series ``/series/<name>`` at the root of ``f``: its data, time and step as HDF5
    virtual datasets of the series' own (nothing copied), labelled along ``record`` and the
    series' other axes (copies of their coordinates), with the series' checksums (nothing is
    read).
    Replaces the view a run continued from a checkpoint left (``drop_root_view``); none when the
    series' data, time and step hold different numbers of records (a write that failed)."""
    drop_root_view(f)
    group = f["series"][name]
    sources = {name: group["data"], "time": group["time"], "step": group["step"]}
    if len({len(source) for source in sources.values()}) > 1:
        return  # a write failed part-way through a record (a full or failing disk): no view of it
    root = f["/"]
    views = {}
    for key, source in sources.items():
        layout = h5py.VirtualLayout(shape=source.shape, dtype=source.dtype)
        layout[...] = h5py.VirtualSource(source)
        views[key] = root.create_virtual_dataset(key, layout)
        # the same bytes: the source's checksum, carried along as it grew, is the view's
        integrity.stamp(
            views[key], int(source.attrs[integrity.CRC_ATTR]), int(source.attrs[integrity.ROWS_ATTR])
        )
        for attr in ("units", "long_name"):
            if attr in source.attrs:
                views[key].attrs[attr] = source.attrs[attr]
    dims, coords = [ROOT_RECORDS], {}
    for axis in list(group["data"].dims)[1:]:
        scale = axis[0]
        dim = scale.name.rsplit("/", 1)[-1]
        values = None if _is_bare(scale) else scale[()]
        if _clashes(f, dim, len(scale), values):
            dim = f"{name}_{dim}"
        dims.append(dim)
        if values is not None:
            coords[dim] = [v.decode() if isinstance(v, bytes) else v for v in values]
    label(views[name], dims, coords)
    label(views["time"], (ROOT_RECORDS,))
    label(views["step"], (ROOT_RECORDS,))
    views[name].attrs["coordinates"] = "time step"


def drop_root_view(f: h5py.File) -> None:
    """Remove the root's view of a series (every dataset directly at the root)."""
    for key in [k for k, v in f["/"].items() if isinstance(v, h5py.Dataset)]:
        del f[key]


def _is_bare(scale: h5py.Dataset) -> bool:
    name = scale.attrs.get("NAME", b"")
    return (name.decode() if isinstance(name, bytes) else str(name)).startswith(BARE_DIMENSION)


def _clashes(f: h5py.File, dim: str, length: int, values) -> bool:
    """Whether a group of ``f`` has a dimension ``dim`` of another length or other labels."""
    found = []

    def visit(path, obj):
        if isinstance(obj, h5py.Dataset) and path.rsplit("/", 1)[-1] == dim and "/" in path:
            found.append(obj)

    f.visititems(visit)
    for scale in found:
        if len(scale) != length:
            return True
        if values is not None and (_is_bare(scale) or not np.array_equal(scale[()], values)):
            return True
    return False
