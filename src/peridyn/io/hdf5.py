"""Incremental HDF5 results files: the writer (read them with ``peridyn.io.results``).

Layout of a results file::

    /                       root attributes: the run's provenance and ``schema_version``
    /geometry/points        (n_points, dim) float64, m; dimensions (point, coordinate)
    /geometry/volumes       (n_points,) float64, m^3; dimension (point)
    /series/<name>/data     (n_records, *shape), resizable, chunked along time; dimensions
                            (time, *the record's), ``units`` and ``long_name``
    /series/<name>/time     (n_records,) float64, s: the coordinate of the time dimension
    /series/<name>/step     (n_records,) int64, strictly increasing
    /<series>, /time, ...   the root's view of one series (``peridyn.io.netcdf.write_root_view``):
                            virtual datasets of its data, time and step along ``record``
    /summary/json           the job's summary, JSON text (docs/user-guide.md, "Summaries and
                            results files")
    /<any>/<name>           one-off arrays, e.g. /final/damage

Since schema 3 every dataset is labelled as netCDF-4 labels it (``peridyn.io.netcdf``: HDF5
dimension scales, coordinates, ``units`` and ``long_name``): each group opens with
``xarray.open_dataset(path, engine="h5netcdf", group=...)`` (``Results.to_xarray``).

Every dataset carries the CRC-32 of its bytes (``peridyn.io.integrity``), kept up to date as
records are appended. Once the writer has closed it, the file ends with its seal
(``peridyn.io.seal``: the CRC-32 of the whole file), checked before the file is read or
continued.

The writer flushes after every ``flush_every`` appends, so a process that
crashes loses at most the records appended since the last flush (with ``flush_every=None``
the caller flushes, e.g. ``peridyn.io.series_buffer.SeriesBuffer`` after each block).
"""

from __future__ import annotations

import json
import math
import operator
import os
import uuid
from dataclasses import dataclass, field

import h5py
import numpy as np

from peridyn.errors import InputError, did_you_mean
from peridyn.io import integrity, seal
from peridyn.io.netcdf import COMPONENTS, describe, drop_root_view, label, root_series, write_root_view
from peridyn.io.reserve import as_disk_error, ensure_room

CHUNK_BYTES = 1 << 20
"""Target size of one chunk of a series' data, in bytes."""

MIN_INDEX_CHUNK = 1024
"""Smallest chunk, in records, of the ``time`` and ``step`` datasets."""

JSON_KEYS_ATTR = "_peridyn_json_keys"
"""Root attribute listing the attributes stored as JSON text."""

SCHEMA_VERSION = 3
"""Version of the results layout and of the job summaries (docs/user-guide.md, "Summaries and
results files"). 1: files written before the version was recorded (no attribute; a fatigue
summary counted each bond once, as ``bonds`` and ``bonds_broken``). 2: the common summary keys,
every bond count directed. 3: netCDF-4 labels (dimension scales, coordinates, ``units``,
``long_name``: ``peridyn.io.netcdf``); a file of schema 2 continued (``mode="a"``) stays 2."""

SCHEMA_ATTR = "schema_version"
"""Root attribute holding :data:`SCHEMA_VERSION`."""

#: Root attribute holding the job's status (``HDF5Writer.set_status``).
STATUS_ATTR = "status"
#: Root attribute holding the run id: a random hex string given when the file is created, that
#: a checkpoint records to find its own results file on restart (``peridyn.io.checkpoint``).
RUN_ID_ATTR = "run_id"
SUMMARY = "summary/json"
"""Dataset holding the job's summary as JSON text."""

_CHUNK_CACHE_BYTES = 4 * CHUNK_BYTES
_RESERVED_GROUPS = ("geometry", "series")


class HDF5Writer:
    """Write a results file incrementally.

    Parameters
    ----------
    path : str or path-like
        The results file.
    points : array_like, shape (n_points, dim)
        Reference coordinates in m, ``dim`` 2 or 3.
    volumes : array_like, shape (n_points,)
        Point volumes in m^3 (m^2 times thickness in 2-D).
    provenance : dict
        Run metadata stored as root attributes, next to ``schema_version``
        (a reserved name). Values may be strings, numbers, booleans or numeric
        arrays; dicts, lists, tuples and ``None`` are stored as JSON text and
        decoded by ``peridyn.io.results.Results.provenance``.
    mode : {"w", "a"}
        ``"w"`` creates the file (overwriting it). ``"a"`` continues an
        existing file, e.g. on restart from a checkpoint; its geometry must
        equal ``points`` and ``volumes``, and ``provenance`` updates the root
        attributes. A missing file is created.
    flush_every : int or None
        Flush the file to the operating system after this many appends; None: only
        when asked (``flush``) and by the methods other than the appends.

    Raises
    ------
    InputError
        Bad arguments, or in append mode a geometry that differs from the one
        in the file or a file written with a newer schema.

    Examples
    --------
    A series written, then read back through ``peridyn.io.results.Results``:

    >>> import tempfile
    >>> from pathlib import Path
    >>> from peridyn.io.results import Results
    >>> path = Path(tempfile.mkdtemp()) / "run.h5"
    >>> x, vol = np.zeros((2, 3)), np.ones(2)
    >>> with HDF5Writer(path, x, vol, {"solver": "explicit"}) as out:
    ...     out.create_series("u", x.shape)
    ...     out.append("u", step=0, time=0.0, values=x + 1e-6)
    >>> steps, times, u = Results(path).series("u")
    >>> steps.tolist(), u.shape, float(u.max())
    ([0], (1, 2, 3), 1e-06)
    """

    def __init__(
        self,
        path: str | os.PathLike,
        points,
        volumes,
        provenance: dict,
        mode: str = "w",
        flush_every: int | None = 1,
    ):
        if mode not in ("w", "a"):
            raise InputError(f"mode must be 'w' or 'a', got {mode!r}")
        if flush_every is not None and (not is_integer(flush_every) or flush_every < 1):
            raise InputError(f"flush_every must be a positive integer, got {flush_every!r}")
        points, volumes = _check_geometry(points, volumes)
        self.path = os.fspath(path)
        self.flush_every = flush_every
        self._pending = 0
        self._series: dict[str, _Series] = {}
        try:
            self._file = self._open(mode)
        except OSError as exc:
            raise InputError(f"cannot open results file {self.path!r} for writing: {exc}") from None
        try:
            version = check_schema(self._file.attrs, self.path)
            #: whether datasets get netCDF-4 labels: not in a file of an older schema continued
            self.labelled = "geometry" not in self._file or version >= 3
            if mode == "a" and not integrity.is_marked(self._file):
                self._stamp_unchecked()
            integrity.mark_file(self._file)
            if RUN_ID_ATTR not in self._file.attrs:
                self._file.attrs[RUN_ID_ATTR] = uuid.uuid4().hex
            self._write_geometry(points, volumes)
            for reserved in (SCHEMA_ATTR, RUN_ID_ATTR, integrity.FILE_ATTR):
                if reserved in provenance:
                    raise InputError(f"{self.path}: provenance: {reserved!r} is reserved for the writer")
            _write_attrs(self._file.attrs, provenance, f"{self.path}: provenance")
            self._file.attrs[SCHEMA_ATTR] = SCHEMA_VERSION if self.labelled else version
            self._open_existing_series()
            drop_root_view(self._file)  # written again, for the records then, on closing
            self._file.flush()
        except BaseException:
            self._file.close()
            raise

    def _open(self, mode: str) -> h5py.File:
        """The file opened for writing; an existing one continued is checked whole first
        (``peridyn.io.seal.check``) and its seal cut off until :meth:`close` seals it again."""
        if mode == "a" and os.path.exists(self.path):
            seal.check(self.path)
            seal.unseal(self.path)
        return h5py.File(self.path, mode, rdcc_nbytes=_CHUNK_CACHE_BYTES)

    def __enter__(self) -> HDF5Writer:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        self.close()

    def close(self) -> None:
        """Flush and close the file; calling it again does nothing. The file is closed even
        when the flush fails (whose error is raised)."""
        if self._file.id.valid:
            try:
                shown = root_series(self._series) if self.labelled else None
                if shown is not None:
                    write_root_view(self._file, shown)
                self.flush()
            finally:
                self._file.close()
            try:
                seal.seal(self.path)
            except OSError:  # no room left for it: unsealed, the file is read through the probe
                pass

    def flush(self) -> None:
        """Flush everything written so far to the operating system.

        Raises
        ------
        OSError
            The disk failed the write (full, or an I/O error), naming the file.
        """
        try:
            self._file.flush()
        except (OSError, RuntimeError) as exc:
            raise as_disk_error(exc, self.path) from exc
        self._pending = 0

    def create_series(
        self,
        name: str,
        shape,
        dtype="float64",
        attrs: dict | None = None,
        dims=None,
        coords: dict | None = None,
        units: str = "1",
        long_name: str | None = None,
    ) -> None:
        """Create the time series ``/series/<name>``, with no records yet.

        Parameters
        ----------
        name : str
            Series name, without ``/``.
        shape : tuple of int
            Shape of one record, e.g. ``(n_points, dim)`` for a vector field,
            ``()`` for a scalar.
        dtype : str or numpy dtype
            Storage type; ``"float32"`` halves the size of big plane records.
        attrs : dict, optional
            Attributes of the series group (e.g. sensor names), encoded like
            provenance.
        dims : sequence of str, optional
            Names of the record's dimensions (``peridyn.io.netcdf``), e.g.
            ``("sensor", "component")``; "component" is labelled x, y, z. Default
            ``axis_1, axis_2, ...``.
        coords : dict, optional
            Values along some of ``dims`` (e.g. ``{"sensor": names}``).
        units, long_name : str
            The records' unit (UDUNITS, "1" for none) and description; the long
            name defaults to the series name.

        Raises
        ------
        InputError
            Bad name, shape or dtype, or a series of that name already exists
            with a different shape or dtype (an identical one is reused, so a
            restarted run may create its series again).
        """
        _check_series_name(name)
        shape = _check_shape(name, shape)
        dtype = _check_dtype(name, dtype)
        if name in self._series:
            self._check_existing_series(name, shape, dtype)
        else:
            group = self._file.require_group("series").create_group(name)
            self._series[name] = series = _Series.create(group, shape, dtype)
            if self.labelled:
                dims = tuple(dims) if dims is not None else tuple(f"axis_{i + 1}" for i in range(len(shape)))
                series.label(dims, {"component": COMPONENTS, **(coords or {})}, units, long_name or name)
        if attrs:
            group = self._file["series"][name]
            _write_attrs(group.attrs, attrs, f"{self.path}: series {name!r} attrs")
        self.flush()

    def append(self, name: str, step: int, time: float, values) -> None:
        """Append one record to a series.

        Parameters
        ----------
        name : str
            A series made by :meth:`create_series`.
        step : int
            Time step number; must exceed the last step of the series.
        time : float
            Simulated time in s.
        values : array_like, shape of the series' record
            The record, cast to the series' dtype.

        Raises
        ------
        InputError
            Unknown series, non-increasing step, non-finite time or a record
            of the wrong shape.
        """
        values = np.asarray(values)
        self._check_record_shape(name, values.shape)
        self.append_block(name, [step], [time], values[np.newaxis])

    def append_block(self, name: str, steps, times, values) -> None:
        """Append ``k`` records to a series at once (one write per dataset), counted as one
        append by ``flush_every``.

        Parameters
        ----------
        name : str
            A series made by :meth:`create_series`.
        steps : sequence of int, length k
            Strictly increasing time step numbers above the last step of the series.
        times : sequence of float, length k
            Simulated times in s.
        values : array_like, shape (k, *record shape)
            The records, cast to the series' dtype as in :meth:`append`.

        Raises
        ------
        InputError
            As :meth:`append`, for any of the records (nothing is written then).
        """
        series = self._get_series(name)
        values = np.asarray(values)
        if values.ndim == 0 or len(values) != len(steps) or len(times) != len(steps):
            raise InputError(
                f"series {name!r}: a block of {len(steps)} steps needs as many times and records, "
                f"got {len(times)} times and values of shape {values.shape}"
            )
        self._check_record_shape(name, values.shape[1:])
        last = series.last_step
        checked = []
        for step, time in zip(steps, times, strict=True):
            step, time = _check_step_time(name, last, step, time)
            checked.append((step, time))
            last = step
        if not checked:
            return
        ensure_room(self.path, values.nbytes + 16 * len(checked))
        try:
            series.append(
                np.array([s for s, _ in checked], dtype=np.int64), np.array([t for _, t in checked]), values
            )
        except (OSError, RuntimeError) as exc:
            raise as_disk_error(exc, self.path) from exc
        self._pending += 1
        if self.flush_every is not None and self._pending >= self.flush_every:
            self.flush()

    def write_array(
        self, name: str, array, attrs: dict | None = None, dims=None, coords: dict | None = None
    ) -> None:
        """Write a one-off dataset, replacing any dataset of that name.

        Parameters
        ----------
        name : str
            Dataset path, e.g. ``"final/damage"``; not under ``geometry`` or
            ``series``.
        array : array_like
            The data, stored with its own dtype.
        attrs : dict, optional
            Dataset attributes, encoded like provenance (``units`` and
            ``long_name`` for netCDF readers).
        dims : sequence of str, optional
            Names of the array's dimensions as in :meth:`create_series`
            ("point" and "component" name the body's points and x, y, z);
            default ``<name>_axis_1, ...``.
        coords : dict, optional
            Values along some of ``dims``.
        """
        key = name.strip("/") if isinstance(name, str) else ""
        if not key or key.split("/")[0] in _RESERVED_GROUPS:
            raise InputError(
                f"write_array: name {name!r} must be a non-empty path outside "
                f"{', '.join('/' + g for g in _RESERVED_GROUPS)}"
            )
        if key in self._file:
            del self._file[key]
        values = np.asarray(array)
        ensure_room(self.path, values.nbytes)
        dataset = self._file.create_dataset(key, data=values)
        integrity.stamp_whole(dataset, values)
        if self.labelled and dataset.ndim:
            base = key.rsplit("/", 1)[-1]
            dims = dims if dims is not None else [f"{base}_axis_{i + 1}" for i in range(dataset.ndim)]
            label(dataset, dims, {"component": COMPONENTS, **(coords or {})})
        if attrs:
            _write_attrs(dataset.attrs, attrs, f"{self.path}: {key!r} attrs")
        self.flush()

    def write_summary(self, summary: dict) -> None:
        """(Re)write the job's summary as JSON text in ``/summary/json``.

        Raises
        ------
        InputError
            A value JSON cannot hold (numpy scalars and arrays are stored as numbers and lists).
        """
        self.write_array(SUMMARY, np.bytes_(to_json(summary, f"{self.path}: summary")))

    def identity(self, step: int) -> dict:
        """The file's run id and each series' records before ``step``: what a checkpoint saved at
        ``step`` expects of the file on restart (``peridyn.io.checkpoint.check_results``). A
        record at ``step`` itself may be written before the checkpoint or after it (the final
        state's), so it is not counted."""
        run_id = self._file.attrs[RUN_ID_ATTR]
        return {
            "run_id": run_id.decode() if isinstance(run_id, bytes) else str(run_id),
            "records": {
                name: int(np.searchsorted(series.step[:], step, side="left"))
                for name, series in self._series.items()
            },
        }

    def set_status(self, status: str) -> None:
        """Set the job's status (root attribute ``status``: ``running``, ``complete``,
        ``failed: <reason>`` or ``interrupted at step N``) and flush it to disk."""
        self._file.attrs[STATUS_ATTR] = str(status)
        self.flush()

    def truncate(self, step: int) -> None:
        """Drop the records with a step greater than ``step`` in every series.

        Used on restart from the checkpoint taken at ``step``, so that records
        written after the checkpoint are not duplicated.
        """
        if not is_integer(step):
            raise InputError(f"truncate: step must be an integer, got {step!r}")
        for series in self._series.values():
            integrity.verify(series.step, self.path)
            series.resize(int(np.searchsorted(series.step[:], step, side="right")), self.path)
        self.flush()

    def _stamp_unchecked(self) -> None:
        """Checksum the datasets of a file written before checksums were recorded, so that it
        can be continued (``mode="a"``) as a checksummed file."""
        datasets = []
        self._file.visititems(lambda _, obj: datasets.append(obj) if isinstance(obj, h5py.Dataset) else None)
        for dataset in datasets:
            integrity.stamp_whole(dataset)

    def _write_geometry(self, points: np.ndarray, volumes: np.ndarray) -> None:
        if "geometry" not in self._file:
            geometry = self._file.create_group("geometry")
            x = geometry.create_dataset("points", data=points)
            volumes_set = geometry.create_dataset("volumes", data=volumes)
            integrity.stamp_whole(x, points)
            integrity.stamp_whole(volumes_set, volumes)
            label(x, ("point", "coordinate"), {"coordinate": COMPONENTS[: points.shape[1]]})
            label(volumes_set, ("point",))
            describe(x, "m", "reference position of the point")
            describe(volumes_set, "m3", "volume of the point (area times thickness in 2D)")
            return
        for name in ("points", "volumes"):
            integrity.verify(self._file["geometry"][name], self.path)
        old_points = self._file["geometry/points"][:]
        old_volumes = self._file["geometry/volumes"][:]
        if not (np.array_equal(old_points, points) and np.array_equal(old_volumes, volumes)):
            raise InputError(
                f"{self.path}: points/volumes differ from the geometry already in the file "
                f"(points {old_points.shape} there, {points.shape} given); "
                "append mode needs the same geometry"
            )

    def _open_existing_series(self) -> None:
        for name, group in self._file.get("series", {}).items():
            self._series[name] = _Series.open(group, self.path)

    def series_dtype(self, name: str) -> np.dtype:
        """The dtype in which series ``name`` (made by :meth:`create_series`) stores its records."""
        return self._get_series(name).data.dtype

    def _check_existing_series(self, name: str, shape: tuple, dtype: np.dtype) -> None:
        data = self._series[name].data
        if data.shape[1:] != shape or data.dtype != dtype:
            raise InputError(
                f"{self.path}: series {name!r} already exists with record shape "
                f"{data.shape[1:]} and dtype {data.dtype}, not {shape} and {dtype}"
            )

    def _check_record_shape(self, name: str, shape: tuple) -> None:
        expected = self._get_series(name).data.shape[1:]
        if shape != expected:
            raise InputError(f"series {name!r}: record has shape {shape}, expected {expected}")

    def _get_series(self, name: str) -> _Series:
        if name not in self._series:
            raise InputError(
                f"series {name!r} does not exist; call create_series first" + did_you_mean(name, self._series)
            )
        return self._series[name]


@dataclass
class _Series:
    """Open handles of one series' datasets, kept for fast appends, and the CRC-32 of each
    dataset's records so far (``peridyn.io.integrity``), carried along as records are appended."""

    data: h5py.Dataset
    time: h5py.Dataset
    step: h5py.Dataset
    last_step: int | None
    crcs: dict = field(default_factory=dict)

    @classmethod
    def create(cls, group: h5py.Group, shape: tuple, dtype: np.dtype) -> _Series:
        record_bytes = dtype.itemsize * math.prod(shape)
        records = max(1, CHUNK_BYTES // max(record_bytes, 1))
        index_chunk = (max(records, MIN_INDEX_CHUNK),)
        data = group.create_dataset(
            "data", (0, *shape), dtype, maxshape=(None, *shape), chunks=(records, *shape)
        )
        time = group.create_dataset("time", (0,), np.float64, maxshape=(None,), chunks=index_chunk)
        step = group.create_dataset("step", (0,), np.int64, maxshape=(None,), chunks=index_chunk)
        series = cls(data, time, step, None)
        for dataset in series.datasets:
            integrity.stamp(dataset, 0, 0)
            series.crcs[dataset.name] = 0
        return series

    @property
    def datasets(self) -> tuple[h5py.Dataset, h5py.Dataset, h5py.Dataset]:
        return self.data, self.time, self.step

    def label(self, dims: tuple, coords: dict, units: str, long_name: str) -> None:
        """netCDF-4 labels: time the coordinate of the records, ``dims`` (with ``coords``)
        their own axes, ``units`` and ``long_name`` the records'."""
        self.time.make_scale("time")
        describe(self.time, "s", "time")
        label(self.data, ("time", *dims), coords)
        label(self.step, ("time",))
        describe(self.data, units, long_name)
        describe(self.step, "1", "time step number")

    @classmethod
    def open(cls, group: h5py.Group, path: str) -> _Series:
        """Open an existing series, dropping a record half-written by a crash (and records
        that their checksums do not cover yet)."""
        series = cls(group["data"], group["time"], group["step"], None)
        n = n_records(group)
        if all(integrity.covered_rows(d) == n == d.shape[0] for d in series.datasets):
            series.crcs = {d.name: int(d.attrs[integrity.CRC_ATTR]) for d in series.datasets}
            series.last_step = int(series.step[n - 1]) if n else None
        else:
            series.resize(n, path)
        return series

    def append(self, steps: np.ndarray, times: np.ndarray, values: np.ndarray) -> None:
        """Write ``k`` records ((k,) steps and times, (k, *shape) values): data, then time,
        then step (the step marks them complete)."""
        n, k = self.data.shape[0], len(steps)
        for dataset, value in zip(self.datasets, (values, times, steps), strict=True):
            value = np.asarray(value, dtype=dataset.dtype)
            dataset.resize(n + k, axis=0)
            dataset[n : n + k] = value
            self.crcs[dataset.name] = integrity.crc_of(value, self.crcs[dataset.name])
            integrity.stamp(dataset, self.crcs[dataset.name], n + k)
        self.last_step = int(steps[-1])

    def resize(self, n: int, path: str) -> None:
        """Keep the first ``n`` records, after checking the datasets against their checksums
        (``path``: the file, for the message)."""
        for dataset in self.datasets:
            self.crcs[dataset.name] = integrity.verify(dataset, path, keep=n)
            dataset.resize(n, axis=0)
            integrity.stamp(dataset, self.crcs[dataset.name], n)
        self.last_step = int(self.step[n - 1]) if n else None


def _check_step_time(name: str, last_step: int | None, step, time) -> tuple[int, float]:
    if not is_integer(step):
        raise InputError(f"series {name!r}: step must be an integer, got {step!r}")
    if last_step is not None and step <= last_step:
        raise InputError(
            f"series {name!r}: step {step} does not exceed the last recorded step {last_step} "
            "(call truncate(step) after restarting from a checkpoint)"
        )
    try:
        time = float(time)
    except (TypeError, ValueError):
        time = math.nan
    if not math.isfinite(time):
        raise InputError(f"series {name!r}: time must be a finite number of seconds")
    return int(step), time


def check_schema(attrs: h5py.AttributeManager, path: str) -> int:
    """The schema version of a results file's root ``attrs`` (1 without the attribute).

    Raises
    ------
    InputError
        The file was written with a newer schema than this peridyn knows.
    """
    version = int(attrs.get(SCHEMA_ATTR, 1))
    if version > SCHEMA_VERSION:
        raise InputError(
            f"{path}: written with results schema {version}, newer than the schema {SCHEMA_VERSION} "
            "this peridyn reads: upgrade peridyn to read it"
        )
    return version


def is_integer(value) -> bool:
    """An int or numpy integer, not a bool."""
    return isinstance(value, int | np.integer) and not isinstance(value, bool)


def _check_geometry(points, volumes) -> tuple[np.ndarray, np.ndarray]:
    points = np.asarray(points, dtype=np.float64)
    volumes = np.asarray(volumes, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] not in (2, 3):
        raise InputError(f"points must have shape (n_points, 2 or 3), got {points.shape}")
    if volumes.shape != points.shape[:1]:
        raise InputError(f"volumes must have shape ({points.shape[0]},) like points, got {volumes.shape}")
    return points, volumes


def _check_series_name(name) -> None:
    if not isinstance(name, str) or not name or "/" in name or name == ".":
        raise InputError(f"series name must be a non-empty string without '/', got {name!r}")


def _check_shape(name: str, shape) -> tuple[int, ...]:
    if isinstance(shape, int | np.integer):
        shape = (shape,)
    try:
        shape = tuple(operator.index(s) for s in shape)
    except TypeError:
        raise InputError(f"series {name!r}: shape must be a tuple of ints, got {shape!r}") from None
    if any(s < 1 for s in shape):
        raise InputError(f"series {name!r}: record dimensions must be positive, got {shape}")
    return shape


def _check_dtype(name: str, dtype) -> np.dtype:
    try:
        dtype = np.dtype(dtype)
    except TypeError:
        raise InputError(f"series {name!r}: unknown dtype {dtype!r}") from None
    if dtype.kind not in "biuf":
        raise InputError(f"series {name!r}: dtype must be numeric, got {dtype}")
    return dtype


def n_records(group: h5py.Group) -> int:
    """Number of complete records (a crash may leave data or time one longer, or records that
    their checksums do not cover yet)."""
    datasets = [group[key] for key in ("data", "time", "step")]
    covered = [integrity.covered_rows(d) for d in datasets]
    return min(
        d.shape[0] if c is None else min(c, d.shape[0]) for d, c in zip(datasets, covered, strict=True)
    )


def _write_attrs(attrs: h5py.AttributeManager, values: dict, where: str) -> None:
    """Store ``values`` as HDF5 attributes, JSON-encoding containers and None."""
    json_keys = set(json.loads(attrs.get(JSON_KEYS_ATTR, "[]")))
    for key, value in values.items():
        if not isinstance(key, str) or key == JSON_KEYS_ATTR:
            raise InputError(f"{where}: invalid attribute name {key!r}")
        if isinstance(value, dict | list | tuple) or value is None:
            attrs[key] = to_json(value, f"{where}: {key!r}")
            json_keys.add(key)
        elif isinstance(value, str | bool | int | float | np.generic | np.ndarray):
            _set_attr(attrs, key, value, where)
            json_keys.discard(key)
        else:
            raise InputError(
                f"{where}: {key!r} has type {type(value).__name__}; expected a string, "
                "number, boolean, numeric array, dict, list or None"
            )
    if json_keys:
        attrs[JSON_KEYS_ATTR] = json.dumps(sorted(json_keys))
    elif JSON_KEYS_ATTR in attrs:
        del attrs[JSON_KEYS_ATTR]


def _set_attr(attrs: h5py.AttributeManager, key: str, value, where: str) -> None:
    try:
        attrs[key] = value
    except (OSError, TypeError) as exc:
        raise InputError(
            f"{where}: {key!r} cannot be stored as an HDF5 attribute ({exc}); "
            "arrays over 64 KiB belong in write_array"
        ) from None


def to_json(value, where: str) -> str:
    """``value`` as JSON text (numpy scalars and arrays as numbers and lists, keys sorted).

    Raises
    ------
    InputError
        A value JSON cannot hold, naming ``where`` it was to be stored.
    """
    try:
        return json.dumps(value, default=_json_default, sort_keys=True)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{where} cannot be stored as JSON: {exc}") from None


def _json_default(value):
    if isinstance(value, np.generic | np.ndarray):
        return value.tolist()
    raise TypeError(f"{type(value).__name__} is not JSON serializable")


def decode_attrs(attrs: h5py.AttributeManager) -> dict:
    """Attributes as written by the writer: JSON entries decoded, numpy scalars as Python ones."""
    json_keys = set(json.loads(attrs.get(JSON_KEYS_ATTR, "[]")))
    out = {}
    for key, value in attrs.items():
        if key == JSON_KEYS_ATTR:
            continue
        if key in json_keys:
            out[key] = json.loads(value)
        else:
            out[key] = value.item() if isinstance(value, np.generic) else value
    return out
