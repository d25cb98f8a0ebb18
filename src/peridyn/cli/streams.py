"""stdout and stderr that the caller closed (``>&-``, ``2>&-``) or whose reader went away (a
closed pipe, a terminal hung up): a command runs all the same and never ends in a traceback.

A stream closed before the command starts is pointed at ``/dev/null`` (what nobody can read is
dropped). Messages on stderr (progress, warnings, the error line) that cannot be written are
dropped from then on: a run is never stopped by its log. stdout keeps failing loudly, since it
carries the results a caller reads (``--json``): its failure is reported on stderr, exit 1
(``peridyn.cli.errors.writing``).
"""

from __future__ import annotations

import io
import os
import sys
from collections.abc import Iterator
from contextlib import contextmanager


class Forgiving(io.TextIOBase):
    """A text stream that writes to ``inner`` until that fails, then drops what it is given."""

    def __init__(self, inner):
        self.inner = inner
        self.broken = False

    def write(self, text: str) -> int:
        if not self.broken:
            try:
                self.inner.write(text)
            except (OSError, ValueError):  # EPIPE, EIO of a hung-up terminal, a closed file
                self.broken = True
        return len(text)

    def flush(self) -> None:
        if not self.broken:
            try:
                self.inner.flush()
            except (OSError, ValueError):
                self.broken = True

    def isatty(self) -> bool:
        try:
            return not self.broken and self.inner.isatty()
        except (OSError, ValueError):
            return False

    def fileno(self) -> int:
        return self.inner.fileno()

    def writable(self) -> bool:
        return True

    @property
    def encoding(self):
        return getattr(self.inner, "encoding", "utf-8")


def reopen_closed() -> None:
    """Point file descriptors 1 and 2, when closed, at /dev/null, and give Python a stream on
    each (``sys.stdout`` or ``sys.stderr`` is None when the process started without it)."""
    for fd, name in ((1, "stdout"), (2, "stderr")):
        try:
            os.fstat(fd)
        except OSError:
            null = os.open(os.devnull, os.O_WRONLY)  # may be ``fd`` itself: the lowest free number
            if null != fd:
                os.dup2(null, fd)
                os.close(null)
            setattr(sys, name, open(fd, "w", closefd=False))  # noqa: SIM115 - for the process's lifetime
        else:
            if getattr(sys, name) is None:
                setattr(sys, name, open(fd, "w", closefd=False))  # noqa: SIM115


@contextmanager
def usable_streams() -> Iterator[None]:
    """Within the block, closed streams are reopened on /dev/null and stderr forgives failures;
    the previous ``sys.stderr`` comes back after."""
    reopen_closed()
    saved = sys.stderr
    sys.stderr = Forgiving(saved)
    try:
        yield
    finally:
        sys.stderr.flush()
        sys.stderr = saved
