"""A sweep's dataset: one NetCDF-4 file (xarray, engine h5netcdf) with dimension ``run``.

Coordinates along ``run`` are the run ids and the varied parameters; data variables along
``run`` are the scalar results (numbers as float64 with NaN where a run has none, or int64 /
bool when every run has one; text as strings); a collected series ``NAME`` of the results files
is ``NAME`` (run, NAME_record, NAME_axis1, ...) padded with NaN past a run's last record, with
its times ``NAME_time`` (run, NAME_record) in s and, when the series names its entries
(sensors), the coordinate ``NAME_axis1``. Every variable carries ``long_name`` and, when it is
a number, ``units`` (UDUNITS spelling, "1" for a count or a ratio). Needs the ``sweep`` extra
(xarray, h5netcdf).

The file is written to a temporary name and renamed, so a reader never sees half a file.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from peridyn.errors import InputError

#: What ``pip install`` adds for the dataset and the dask executor.
EXTRA_HINT = "install the sweep extra: pip install 'peridyn[sweep]'"


@dataclass(frozen=True)
class SeriesColumn:
    """One series across the runs.

    Attributes
    ----------
    times : list of ndarray (k_i,) or None
        Each run's record times, s (None: the run has no such series).
    values : list of ndarray (k_i, *shape) or None
        Each run's records (the same ``shape`` for every run).
    entry_names : list of str or None
        Names along the first axis after the record (sensor names), if any.
    about : dict
        ``units`` and ``long_name`` of the records (as the results file gives them).
    """

    times: list
    values: list
    entry_names: list | None = None
    about: dict = field(default_factory=dict)


def require_xarray():
    """The xarray module, after checking that h5netcdf is there too.

    Raises
    ------
    InputError
        Either is missing (the message names the extra to install).
    """
    try:
        import h5netcdf  # noqa: F401 - the engine the file is written with
        import xarray
    except ImportError as exc:
        raise InputError(
            f"a sweep dataset needs xarray and h5netcdf ({exc.name} is missing): {EXTRA_HINT}"
        ) from None
    return xarray


def build_dataset(
    coords: dict,
    table: dict,
    series: dict,
    attrs: dict,
    reference: dict | None = None,
    about: dict | None = None,
):
    """The ``xarray.Dataset`` of a sweep.

    Parameters
    ----------
    coords : dict name -> list
        Per-run values of the coordinates along ``run`` (run ids, parameters).
    table : dict name -> list
        Per-run scalar results (None where a run has none).
    series : dict name -> SeriesColumn
    attrs : dict
        Global attributes (text or numbers).
    reference : dict name -> (times (k,), values (k, *shape)), or None
        The series of the sweep's reference run (e.g. the healthy body's sensor signals): each
        becomes ``reference_<name>`` along ``reference_<name>_record`` and the series' own
        entry axes, with ``reference_<name>_time`` (s).
    about : dict name -> (units, long_name), optional
        What the ``coords`` and ``table`` entries are (units None for text); one not named here
        gets its own name as long name and "1" as unit.
    """
    xr = require_xarray()
    n = len(next(iter(coords.values()))) if coords else 0
    ds = xr.Dataset(
        {name: ("run", _column(values)) for name, values in table.items()},
        coords={name: ("run", _column(values)) for name, values in coords.items()},
        attrs=attrs,
    )
    for name in (*coords, *table):
        units, long_name = (about or {}).get(name, ("1", name))
        _describe(ds[name], units, long_name)
    for name, column in series.items():
        values, times, dims = _padded(name, column, n)
        ds[name] = (dims, values, column.about)
        ds[f"{name}_time"] = (dims[:2], times, {"units": "s", "long_name": f"time of the {name} records"})
        if column.entry_names is not None and len(dims) > 2:
            ds.coords[dims[2]] = (dims[2], np.asarray(column.entry_names, dtype=str), {"long_name": "sensor"})
    for name, (times, values) in (reference or {}).items():
        record = f"reference_{name}_record"
        column = series.get(name)
        of = column.about.get("long_name", name) if column else name
        ds[f"reference_{name}"] = (
            (record, *_entry_dims(name, np.ndim(values) - 1)),
            np.asarray(values),
            {**(column.about if column else {}), "long_name": f"{of}, reference run"},
        )
        ds[f"reference_{name}_time"] = (
            record,
            np.asarray(times),
            {"units": "s", "long_name": f"time of the reference run's {name} records"},
        )
    return ds


def _describe(variable, units: str | None, long_name: str) -> None:
    """``long_name`` and, for a number, ``units`` of a dataset variable."""
    variable.attrs["long_name"] = long_name
    if units is not None and variable.dtype.kind in "biuf":
        variable.attrs["units"] = units


def write_dataset(ds, path) -> Path:
    """Write ``ds`` to ``path`` (NetCDF-4 via h5netcdf) atomically; returns the path."""
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    ds.to_netcdf(tmp, engine="h5netcdf")
    os.replace(tmp, path)
    return path


def load_sweep(path):
    """A sweep's dataset, read whole into memory (the file is closed after), e.g.
    ``peridyn.load_sweep("peridyn-out/demo/dataset.nc")["max_damage"].to_series()``."""
    return load_dataset(path, "sweep dataset")


def load_dataset(path, what: str):
    """The NetCDF-4 dataset at ``path`` read whole into memory (the file is closed after);
    ``what`` names it in the error.

    Raises
    ------
    InputError
        No file at ``path``.
    """
    xr = require_xarray()
    if not Path(path).is_file():
        raise InputError(f"{what} {str(path)!r} does not exist")
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        return ds.load()


def _column(values: list) -> np.ndarray:
    """One per-run column as an array: int64 or bool when complete, float64 with NaN for
    missing numbers, else text (lists and mappings as JSON, missing as "")."""
    present = [v for v in values if v is not None]
    if present and all(isinstance(v, bool | np.bool_) for v in present):
        if len(present) == len(values):
            return np.asarray(values, dtype=bool)
        return np.asarray([np.nan if v is None else float(v) for v in values])
    if present and all(isinstance(v, int | np.integer) and not isinstance(v, bool) for v in present):
        if len(present) == len(values):
            return np.asarray(values, dtype=np.int64)
    if present and all(isinstance(v, int | float | np.number) and not isinstance(v, bool) for v in present):
        return np.asarray([np.nan if v is None else float(v) for v in values], dtype=np.float64)
    return np.asarray([_text(v) for v in values], dtype=str)


def _text(value) -> str:
    if value is None:
        return ""
    if isinstance(value, str):
        return value
    return json.dumps(value)


def _padded(name: str, column: SeriesColumn, n: int):
    """(values (n, k_max, *shape), times (n, k_max), dims) with NaN where a run has no record."""
    shapes = {np.shape(v)[1:] for v in column.values if v is not None}
    if len(shapes) > 1:
        raise InputError(f"series {name!r}: the runs record different shapes {sorted(shapes)}")
    shape = shapes.pop() if shapes else ()
    k_max = max((len(t) for t in column.times if t is not None), default=0)
    values = np.full((n, k_max, *shape), np.nan)
    times = np.full((n, k_max), np.nan)
    for i, (t, v) in enumerate(zip(column.times, column.values, strict=True)):
        if t is not None:
            times[i, : len(t)] = t
            values[i, : len(t)] = v
    return values, times, ("run", f"{name}_record", *_entry_dims(name, len(shape)))


def _entry_dims(name: str, n_axes: int) -> tuple[str, ...]:
    """The names of a series' ``n_axes`` axes after its record axis."""
    return tuple(f"{name}_axis{j + 1}" for j in range(n_axes))
