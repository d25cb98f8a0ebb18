"""Checksums of the datasets of peridyn's HDF5 files (results, checkpoints).

Every dataset written by ``peridyn.io.hdf5.HDF5Writer`` and ``peridyn.io.checkpoint`` carries
the CRC-32 (``zlib.crc32``) of its stored bytes in C order, in the attribute ``crc32``, and the
number of rows along its first axis that the checksum covers in ``crc32_rows`` (a series grows
by rows: appending rows appends bytes, so the checksum is carried along, ``zlib.crc32(new,
old)``, without reading the file again). A file whose root attribute ``checksums`` is
``"crc32"`` has one on every dataset, and a dataset whose bytes differ (a flipped bit on disk,
a truncated copy) is refused with an error naming it: when a file without a seal is read
(``peridyn.io.hdf5_probe``; a sealed file's seal covers every byte, ``peridyn.io.seal``), when a
checkpoint is loaded and when a series is truncated or continued. Files written before
checksums were recorded have no ``checksums`` attribute and are read unchecked.

CRC-32 finds every burst error of up to 32 bits and any other change with probability
1 - 2^-32; it guards against corruption, not against deliberate tampering.
"""

from __future__ import annotations

import zlib

import h5py
import numpy as np

from peridyn.errors import InputError

#: Root attribute naming the checksum that every dataset of the file carries.
FILE_ATTR = "checksums"
#: Its value.
KIND = "crc32"
#: Dataset attribute: the CRC-32 of the covered rows' bytes.
CRC_ATTR = "crc32"
#: Dataset attribute: the rows (along the first axis) the checksum covers.
ROWS_ATTR = "crc32_rows"

#: Bytes read at a time while checking a dataset.
READ_BYTES = 64 << 20


def crc_of(values: np.ndarray, crc: int = 0) -> int:
    """The CRC-32 of ``values``' bytes in C order, continuing ``crc`` (0: a new checksum).

    Variable-length strings (an object array: ``str`` as written, ``bytes`` as h5py reads them
    back) count as their UTF-8 bytes, each followed by a NUL."""
    values = np.asarray(values)
    if values.dtype.kind == "O":
        data = b"".join((v.encode() if isinstance(v, str) else bytes(v)) + b"\0" for v in values.reshape(-1))
        return zlib.crc32(data, crc)
    return zlib.crc32(np.ascontiguousarray(values).reshape(-1).view(np.uint8), crc)


def rows_of(dataset: h5py.Dataset) -> int:
    """Rows of ``dataset`` along its first axis (1 for a scalar)."""
    return dataset.shape[0] if dataset.shape else 1


def stamp(dataset: h5py.Dataset, crc: int, rows: int | None = None) -> None:
    """Record ``crc`` as the checksum of the first ``rows`` rows of ``dataset`` (all by default)."""
    dataset.attrs[CRC_ATTR] = np.uint32(crc)
    dataset.attrs[ROWS_ATTR] = np.int64(rows_of(dataset) if rows is None else rows)


def stamp_whole(dataset: h5py.Dataset, values=None) -> None:
    """Checksum all of ``dataset`` (from ``values``, its content, when given: no read back)."""
    stamp(dataset, crc_of(np.asarray(dataset[()] if values is None else values, dtype=dataset.dtype)))


def mark_file(f: h5py.File) -> None:
    """Declare that every dataset of ``f`` carries a checksum."""
    f.attrs[FILE_ATTR] = KIND


def is_marked(f: h5py.File) -> bool:
    """True when ``f`` declares a checksum on every dataset."""
    value = f.attrs.get(FILE_ATTR)
    return (value.decode() if isinstance(value, bytes) else value) == KIND


def prefix_crcs(dataset: h5py.Dataset, ends) -> dict:
    """CRC-32 of the first ``end`` rows of ``dataset`` for each of ``ends``, in one read."""
    if not dataset.shape:
        return {end: crc_of(np.asarray(dataset[()], dtype=dataset.dtype)) for end in ends}
    row_bytes = max(1, dataset.dtype.itemsize * int(np.prod(dataset.shape[1:], dtype=np.int64)))
    step = max(1, READ_BYTES // row_bytes)
    wanted = sorted(set(int(e) for e in ends))
    out, crc, done = {}, 0, 0
    for end in wanted:
        while done < end:
            stop = min(end, done + step)
            crc = crc_of(dataset[done:stop], crc)
            done = stop
        out[end] = crc
    return out


def covered_rows(dataset: h5py.Dataset) -> int | None:
    """The rows the checksum of ``dataset`` covers, None without one."""
    if CRC_ATTR not in dataset.attrs:
        return None
    return int(dataset.attrs.get(ROWS_ATTR, rows_of(dataset)))


def verify(dataset: h5py.Dataset, path: str, keep: int | None = None) -> int | None:
    """Check ``dataset`` against its checksum; returns the CRC-32 of its first ``keep`` rows
    (read in the same pass; None when ``keep`` is None).

    Raises
    ------
    InputError
        Naming the file and the dataset: the checksum differs, the dataset holds fewer rows
        than its checksum covers, cannot be read, or a checksummed file's dataset has none.
    """
    name = dataset.name
    rows = covered_rows(dataset)
    if rows is None:
        raise InputError(f"{path}: dataset {name} has no checksum: the file is damaged or was altered")
    if rows > rows_of(dataset):
        raise InputError(
            f"{path}: dataset {name} holds {rows_of(dataset)} rows, fewer than the {rows} its checksum "
            "covers: the file is truncated or damaged"
        )
    ends = [rows] if keep is None else [rows, keep]
    try:
        crcs = prefix_crcs(dataset, ends)
    except (OSError, RuntimeError, ValueError, TypeError) as exc:  # HDF5 finds a damaged structure
        raise InputError(
            f"{path}: dataset {name} cannot be read ({exc}): the file is damaged; it is not used"
        ) from None
    if crcs[rows] != int(dataset.attrs[CRC_ATTR]):
        raise InputError(
            f"{path}: dataset {name} does not match its checksum (CRC-32): the file is corrupted; "
            "it is not used"
        )
    return None if keep is None else crcs[keep]


def verify_file(f: h5py.File, path: str) -> None:
    """Check every dataset of ``f`` when it declares checksums (``mark_file``); files without the
    declaration (written before checksums were recorded) pass unchecked."""
    if not is_marked(f):
        return
    datasets = []
    try:
        f.visititems(lambda _, obj: datasets.append(obj) if isinstance(obj, h5py.Dataset) else None)
    except (OSError, RuntimeError, KeyError, ValueError) as exc:  # HDF5 finds a damaged structure
        raise InputError(
            f"{path}: its groups cannot be read ({exc}): the file is damaged; it is not used"
        ) from None
    for dataset in datasets:
        verify(dataset, path)


def attrs_crc(attrs: h5py.AttributeManager, names) -> int:
    """CRC-32 of the attributes ``names`` (their text, in order): guards the scalars that a file
    keeps in attributes (a checkpoint's time and step)."""
    text = "\x1f".join(f"{name}={_attr_text(attrs.get(name))}" for name in names)
    return zlib.crc32(text.encode())


def _attr_text(value) -> str:
    if isinstance(value, bytes):
        return value.decode(errors="replace")
    if isinstance(value, np.ndarray):
        return repr(value.tolist())
    if isinstance(value, float | np.floating):
        return repr(float(value))
    if isinstance(value, np.generic):
        return repr(value.item())
    return repr(value)
