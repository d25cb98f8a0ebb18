"""Room kept on the disk of an output folder, so that a run that fills the disk can still
close its files with a status that says so.

A full disk (ENOSPC) or a failing one (EIO) found while a run writes leaves its HDF5 file
with records it could not write: closing it writes them again and fails again, and the HDF5
library, left with a file it cannot flush, may crash the process (a segfault at exit was
measured). A run therefore writes ``RESERVE_BYTES`` of zeros to ``<output>/.peridyn.reserve``
when it opens its results; on a disk failure the reserve is deleted, which gives back the room
the pending records and the status need, and the run ends with one line and the status
``failed: No space left on device (...)``. The reserve is deleted when the run's files close.
Every write of a results file or a snapshot first checks that it leaves ``GUARD_BYTES`` free
(``ensure_room``): a write is refused whole rather than failed half-way, so that the records
already written stay as their checksums say.
"""

from __future__ import annotations

import errno
import os
import re
import shutil
from pathlib import Path

#: Bytes kept: the HDF5 chunk cache of the results file (``peridyn.io.hdf5``, 4 MiB) and its
#: metadata, twice over.
RESERVE_BYTES = 8 << 20

#: Bytes a write must leave free (``ensure_room``): a write is refused before it starts rather
#: than failed half-way, which would leave an HDF5 chunk half written.
GUARD_BYTES = 1 << 20

#: The reserve file in an output folder.
RESERVE_FILE = ".peridyn.reserve"

#: The errors of a disk that fails a write.
DISK_ERRNOS = (errno.ENOSPC, errno.EIO, errno.EDQUOT, errno.EFBIG)

#: HDF5's report of a failed system call (h5py raises it as an OSError or RuntimeError).
_HDF5_ERRNO = re.compile(r"errno = (\d+)")


class Reserve:
    """``RESERVE_BYTES`` held in ``<folder>/.peridyn.reserve`` until :meth:`release`. A disk
    without that room fails here, before the run writes its results."""

    def __init__(self, folder, nbytes: int = RESERVE_BYTES):
        self.path = Path(folder) / RESERVE_FILE
        try:
            with open(self.path, "wb") as f:
                chunk = bytes(1 << 20)
                for start in range(0, nbytes, len(chunk)):
                    f.write(chunk[: min(len(chunk), nbytes - start)])
                f.flush()
                os.fsync(f.fileno())
        except OSError as exc:
            self.path.unlink(missing_ok=True)
            raise as_disk_error(exc, self.path) from exc

    def release(self) -> None:
        """Delete the reserve (again: nothing)."""
        self.path.unlink(missing_ok=True)


def disk_errno(exc: BaseException) -> int | None:
    """The errno of a disk that failed a write behind ``exc`` (an OSError, or HDF5's report of
    one as an OSError or RuntimeError, or one in its chain of causes), else None."""
    seen = set()
    node = exc
    while node is not None and id(node) not in seen:
        seen.add(id(node))
        number = getattr(node, "errno", None)
        if number is None and isinstance(node, OSError | RuntimeError):
            match = _HDF5_ERRNO.search(str(node))
            number = int(match[1]) if match else None
        if number in DISK_ERRNOS:
            return number
        node = node.__cause__ or node.__context__
    return None


def as_disk_error(exc: BaseException, path) -> BaseException:
    """``exc`` as an ``OSError(errno, strerror, path)`` when a failing disk is behind it, else
    ``exc`` itself."""
    number = disk_errno(exc)
    if number is None:
        return exc
    return OSError(number, os.strerror(number), str(path))


def ensure_room(path, nbytes: float) -> None:
    """Refuse a write of ``nbytes`` to the file ``path`` that would leave less than
    ``GUARD_BYTES`` free on its disk, before anything is written.

    Raises
    ------
    OSError
        ENOSPC, naming ``path``.
    """
    try:
        free = shutil.disk_usage(Path(path).parent).free
    except OSError:  # the folder is gone or unreadable: the write itself reports it
        return
    if free < nbytes + GUARD_BYTES:
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))
