"""Reading an input text file (a case, a sweep file, a Peridigm deck) within bounds.

An input file must be a regular file (not a device such as ``/dev/zero``, a pipe or a
folder) of at most ``MAX_BYTES``: a case file is a few kilobytes, and reading an endless or
huge file would take the machine's memory before any check ran. At most ``MAX_BYTES + 1``
bytes are ever read, so a file that grows while it is read is refused too.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from peridyn.errors import CaseFileError

#: The largest input text file read, in bytes (16 MiB).
MAX_BYTES = 16 << 20


def read_input_text(path, what: str, limit: int = MAX_BYTES) -> str:
    """The UTF-8 text of the input file ``path`` (``what``: e.g. "YAML case file", for the message).

    Raises
    ------
    CaseFileError
        A missing or non-regular file, a file over ``limit`` bytes, or text that is not UTF-8.
    """
    path = Path(path)
    try:
        mode = path.stat().st_mode
    except OSError:
        mode = None
    if mode is None or not stat.S_ISREG(mode):
        expected = (
            f"an existing {what}" if mode is None else f"a {what} (a regular file, not a device or pipe)"
        )
        raise CaseFileError(str(path), "<file>", None, expected)
    with open(path, "rb") as f:
        data = f.read(limit + 1)
    if len(data) > limit:
        size = os.path.getsize(path)
        raise CaseFileError(
            str(path), "<file>", None, f"a {what} of at most {limit >> 20} MiB (this one holds {size} bytes)"
        )
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise CaseFileError(
            str(path), "<file>", None, f"UTF-8 text (byte {exc.start} is {data[exc.start]:#04x})"
        ) from None
