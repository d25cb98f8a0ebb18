"""netCDF-4 conventions in results files: named dimensions, coordinates, units.

A results file (``peridyn.io.hdf5``) labels each dataset the way netCDF-4 does, with HDF5
dimension scales, so that netCDF readers (``xarray.open_dataset(path, engine="h5netcdf",
group="series/sensor_u")``, ``xarray.open_datatree``, ``ncdump``) see named dimensions and
coordinates:

- every axis of a dataset is a dimension, a scale in the dataset's own group: a coordinate
  variable (its values label the axis: ``time`` in s, ``component`` x/y/z, ``sensor`` names,
  ``point`` indices of a probe) or a bare dimension (netCDF's "dimension but not a variable"),
  so that each group opens on its own;
- data variables carry ``units`` (UDUNITS spelling, "1" for a ratio) and ``long_name``.
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
