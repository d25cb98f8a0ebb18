"""The reader of results files (layout in ``peridyn.io.hdf5``, written by its ``HDF5Writer``).

Every reader of a ``results.h5`` (figures, the command line, the jobs, the analyses) goes
through :class:`Results`, so that each read checks the same things: the file exists, its
bytes are whole before HDF5 opens it (``peridyn.io.seal``: a sealed file matches its seal's
CRC-32, which covers every dataset's bytes; a file without a seal is read whole by a probe in a
child process with a time limit, every dataset against its checksum, ``peridyn.io.integrity``),
its schema is one this peridyn knows, and a series is read up to its last complete record (a
crash may leave ``data`` or ``time`` one record longer than ``step``). The whole file is
checked once per process for each version of the file (its size and modification time).
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterator
from contextlib import contextmanager

import h5py
import numpy as np

from peridyn.errors import InputError, did_you_mean
from peridyn.io import integrity, seal
from peridyn.io.hdf5 import (
    RUN_ID_ATTR,
    SCHEMA_ATTR,
    STATUS_ATTR,
    SUMMARY,
    check_schema,
    decode_attrs,
    is_integer,
    n_records,
)
from peridyn.io.netcdf import BARE_DIMENSION, COMPONENTS


class Results:
    """A results file, read on demand (each method opens and closes the file).

    Parameters
    ----------
    path : str or path-like
        A results file.

    Attributes
    ----------
    path : str
    schema_version : int
        The file's schema (``peridyn.io.hdf5.SCHEMA_VERSION``; 1 for files written before
        the version was recorded).

    Raises
    ------
    InputError
        The file is missing, not HDF5, written with a newer schema than this peridyn reads, or
        one of its datasets does not match its checksum.

    Examples
    --------
    See ``peridyn.io.hdf5.HDF5Writer`` for a file written and read back; on a finished run:
    ``Results("peridyn-out/bar_pulse/results.h5").series("sensor_u")`` gives its steps, times
    and values, ``.summary()`` its summary.
    """

    def __init__(self, path: str | os.PathLike):
        self.path = os.fspath(path)
        with self._open() as f:
            self.schema_version = check_schema(f.attrs, self.path)

    @classmethod
    def of(cls, source: Results | str | os.PathLike) -> Results:
        """``source`` itself when it is a ``Results`` (a file opened once and handed on, e.g. to
        the figures of a run), else the ``Results`` of the file at that path."""
        return source if isinstance(source, cls) else cls(source)

    def series(self, name: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """A whole series: steps (n_records,) int64, times (n_records,) float64 in s, and the
        records ``(n_records, *record_shape)`` in their stored dtype."""
        with self._series(name) as group:
            n = n_records(group)
            return group["step"][:n], group["time"][:n], group["data"][:n]

    def iter_series(self, name: str, chunk_records: int) -> Iterator[tuple[np.ndarray, np.ndarray]]:
        """A series a few records at a time, without loading it whole: yields times (k,) in s
        and records ``(k, *record_shape)``, ``k <= chunk_records`` (the last chunk may be shorter)."""
        if not is_integer(chunk_records) or chunk_records < 1:
            raise InputError(f"chunk_records must be a positive integer, got {chunk_records!r}")
        with self._series(name) as group:
            times, data = group["time"], group["data"]
            n = n_records(group)
            for start in range(0, n, chunk_records):
                stop = min(start + chunk_records, n)
                yield times[start:stop], data[start:stop]

    def to_xarray(self, name: str):
        """A series as an ``xarray.Dataset`` (needs the ``sweep`` extra): the records as the
        variable ``name``, dimensions ``(time, *record dims)``, coordinates ``time`` (s),
        ``step`` and those of the record's dimensions (``component`` x, y, z; ``sensor`` names;
        ``point`` indices of a probe), with the file's ``units`` and ``long_name``.

        A file written before schema 3 has no labels: its vector axis is still ``component``,
        its other axes ``axis_1, ...``, and there are no units.
        """
        try:
            import xarray as xr
        except ModuleNotFoundError:
            raise InputError("Results.to_xarray needs xarray: pip install 'peridyn[sweep]'") from None
        steps, times, data = self.series(name)
        with self._series(name) as group:
            dims, coords = _record_dims(group["data"])
            attrs = {k: group["data"].attrs[k] for k in ("units", "long_name") if k in group["data"].attrs}
            time_attrs = {
                k: group["time"].attrs[k] for k in ("units", "long_name") if k in group["time"].attrs
            }
        coords = {
            "time": ("time", times, time_attrs or {"units": "s", "long_name": "time"}),
            "step": ("time", steps, {"long_name": "time step number"}),
            **coords,
        }
        return xr.Dataset({name: (("time", *dims), data, attrs)}, coords=coords)

    def series_about(self, name: str) -> dict:
        """``units`` and ``long_name`` of a series' records (empty before schema 3)."""
        with self._series(name) as group:
            return _cf_attrs(group["data"])

    def n_records(self, name: str) -> int:
        """Number of complete records of a series."""
        with self._series(name) as group:
            return n_records(group)

    def series_names(self) -> list[str]:
        """Names of the series in the file."""
        with self._open() as f:
            return list(f.get("series", {}))

    def series_attrs(self, name: str) -> dict:
        """Attributes of a series (e.g. ``names`` of sensors, ``points`` of a line probe),
        JSON entries decoded."""
        with self._series(name) as group:
            return decode_attrs(group.attrs)

    def array(self, name: str) -> np.ndarray:
        """One dataset, e.g. ``"final/damage"`` or ``"geometry/points"``."""
        with self._open() as f:
            key = name.strip("/")
            if not key or not isinstance(f.get(key), h5py.Dataset):
                raise InputError(f"{self.path}: no dataset {name!r}")
            return f[key][()]

    def has(self, name: str) -> bool:
        """Whether the file holds the dataset ``name``."""
        with self._open() as f:
            key = name.strip("/")
            return bool(key) and isinstance(f.get(key), h5py.Dataset)

    def provenance(self) -> dict:
        """The root attributes as given to the writer (without ``schema_version``, ``status``,
        ``run_id`` and ``checksums``), JSON entries decoded; numbers come back as Python
        scalars, tuples as lists."""
        with self._open() as f:
            attrs = decode_attrs(f.attrs)
        for key in (SCHEMA_ATTR, STATUS_ATTR, RUN_ID_ATTR, integrity.FILE_ATTR):
            attrs.pop(key, None)
        return attrs

    def run_id(self) -> str | None:
        """The run id given when the file was created (None for files written before it was)."""
        with self._open() as f:
            value = f.attrs.get(RUN_ID_ATTR)
        return value.decode() if isinstance(value, bytes) else None if value is None else str(value)

    def steps(self, name: str) -> np.ndarray:
        """The steps (n_records,) int64 of a series' complete records."""
        with self._series(name) as group:
            return group["step"][: n_records(group)]

    def status(self) -> str:
        """The job's status: ``running``, ``complete``, ``failed: <reason>``, ``interrupted at
        step N`` or ``interrupted while ...`` ("unknown" for files written before it was
        recorded)."""
        with self._open() as f:
            status = f.attrs.get(STATUS_ATTR, "unknown")
        return status.decode() if isinstance(status, bytes) else str(status)

    def summary(self) -> dict:
        """The job's summary (docs/user-guide.md, "Summaries and results files")."""
        if not self.has(SUMMARY):
            raise InputError(f"{self.path}: no summary (the job did not finish)")
        return json.loads(self.array(SUMMARY))

    @contextmanager
    def _open(self) -> Iterator[h5py.File]:
        if not os.path.exists(self.path):
            raise InputError(f"results file {self.path!r} does not exist")
        seal.check(self.path)
        try:
            f = h5py.File(self.path, "r")
        except OSError as exc:
            raise InputError(f"{self.path}: not a readable HDF5 file ({exc})") from None
        with f:
            try:
                yield f
            except InputError:
                raise
            except (OSError, RuntimeError, KeyError, TypeError) as exc:  # HDF5 finds a damaged structure
                raise InputError(f"{self.path}: cannot be read ({exc}): the file is damaged") from None

    @contextmanager
    def _series(self, name: str) -> Iterator[h5py.Group]:
        with self._open() as f:
            available = list(f.get("series", {}))
            if name not in available:
                raise InputError(
                    f"{self.path}: no series {name!r}; it has {available}" + did_you_mean(name, available)
                )
            yield f["series"][name]


def _cf_attrs(dataset: h5py.Dataset) -> dict:
    """The ``units`` and ``long_name`` of a dataset, those it has."""
    return {k: _text(dataset.attrs[k]) for k in ("units", "long_name") if k in dataset.attrs}


def _text(value) -> str:
    return value.decode() if isinstance(value, bytes) else str(value)


def _record_dims(data: h5py.Dataset) -> tuple[list[str], dict]:
    """Names of a series' record axes and the coordinates along them (``{name: (name, values)}``),
    from its dimension scales, or for an unlabelled file (schema 1 and 2) ``component`` for an
    axis of 3 last and ``axis_i`` for the others."""
    dims, coords = [], {}
    for axis in range(1, data.ndim):
        if len(data.dims[axis]):
            scale = data.dims[axis][0]
            name = scale.name.rsplit("/", 1)[-1]
            if not _text(scale.attrs.get("NAME", "")).startswith(BARE_DIMENSION):
                values = scale[()]
                coords[name] = (name, values.astype(str) if values.dtype.kind in "OS" else values)
        elif axis == data.ndim - 1 and data.shape[axis] == 3:
            name = "component"
            coords[name] = (name, list(COMPONENTS))
        else:
            name = f"axis_{axis}"
        dims.append(name)
    return dims, coords
