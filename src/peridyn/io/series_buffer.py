"""A bounded in-memory buffer of series records in front of an ``HDF5Writer``.

Appending a record to an HDF5 series resizes three datasets and writes three small pieces;
flushing the file after every record (what keeps it readable after a crash) costs more
still. ``SeriesBuffer`` holds the records of every series in memory, each series in one
preallocated block of at most ``max_bytes`` (and at most ``max_records`` records), and
writes them with one ``HDF5Writer.append_block`` per series, then one file flush, when a
block is full or when asked (``flush``). The records are kept in the dtype they are given
in: the writer casts them to the series' dtype exactly as an ``append`` of each would.
"""

from __future__ import annotations

import numpy as np

from peridyn.errors import InputError
from peridyn.io.hdf5 import HDF5Writer

#: Default bytes held per series before the buffer is written (about 8 plane records of
#: 125 000 points in float64).
MAX_BYTES = 8 << 20

#: Default records held per series before the buffer is written (small series).
MAX_RECORDS = 256


class _Block:
    """The records of one series not yet written: (capacity, *shape) values, steps and times."""

    def __init__(self, values: np.ndarray, max_bytes: int, max_records: int):
        capacity = max(1, min(max_records, max_bytes // max(values.nbytes, 1)))
        self.values = np.empty((capacity, *values.shape), dtype=values.dtype)
        self.steps = np.empty(capacity, dtype=np.int64)
        self.times = np.empty(capacity)
        self.count = 0

    def fits(self, values: np.ndarray) -> bool:
        """True when a record like ``values`` goes into this block as it is."""
        return values.shape == self.values.shape[1:] and values.dtype == self.values.dtype


class SeriesBuffer:
    """Records appended to ``writer``'s series, held in memory and written in blocks.

    Parameters
    ----------
    writer : HDF5Writer
        Its series must exist (``create_series``) before their first ``append``.
    max_bytes : int
        Bytes of records held per series (at least one record is held).
    max_records : int
        Records held per series.

    A process killed (SIGKILL) loses the records appended since the last ``flush``; an
    error or signal handled by the caller loses nothing if it calls ``flush`` (or
    ``close``), as ``peridyn.io.recorder.Recorder`` does.
    """

    def __init__(self, writer: HDF5Writer, max_bytes: int = MAX_BYTES, max_records: int = MAX_RECORDS):
        if max_bytes < 1 or max_records < 1:
            raise InputError(
                "series buffer: max_bytes and max_records must be positive, "
                f"got {max_bytes} and {max_records}"
            )
        self.writer = writer
        self.max_bytes = int(max_bytes)
        self.max_records = int(max_records)
        self._blocks: dict[str, _Block] = {}

    @property
    def held(self) -> int:
        """Records held in memory, all series together."""
        return sum(block.count for block in self._blocks.values())

    def append(self, name: str, step: int, time: float, values) -> None:
        """Hold one record of series ``name`` ((step, time s, values of the record's shape));
        write every series' records when this one's block is full."""
        values = np.asarray(values)
        block = self._blocks.get(name)
        if block is not None and block.count and not block.fits(values):
            self.flush()  # a record of another shape or dtype: the writer checks it
        if block is None or not block.fits(values):
            block = self._blocks[name] = _Block(values, self.max_bytes, self.max_records)
        k = block.count
        block.values[k] = values
        block.steps[k] = step
        block.times[k] = time
        block.count = k + 1
        if block.count == len(block.steps):
            self.flush()

    def flush(self) -> None:
        """Write the records held, one block per series, and flush the file. The buffer is
        emptied first, so records whose write fails (a full disk) are not tried again."""
        pending = [(name, block, block.count) for name, block in self._blocks.items() if block.count]
        for _, block, _ in pending:
            block.count = 0
        for name, block, k in pending:
            self.writer.append_block(name, block.steps[:k], block.times[:k], block.values[:k])
        self.writer.flush()
