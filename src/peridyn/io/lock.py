"""The lock of an output folder: one job writes a folder at a time.

A job that writes a folder holds ``<folder>/.peridyn.lock`` while it runs: a JSON file with
the process id, the host and the start time (UTC) of its holder, created exclusively
(``O_CREAT | O_EXCL``, atomic on local file systems and on NFS v3 and later). A second job
asking for the folder is refused with an error naming the holder. A lock whose holder is a
process of this host that no longer exists (a job killed by SIGKILL or a power cut) is stale:
it is taken over, by renaming it away first so that of two jobs taking it over at once only one
succeeds. A lock held from another host cannot be checked and is never taken over: the message
says which file to remove once that job is known to be gone.
"""

from __future__ import annotations

import json
import os
import socket
import time
from datetime import UTC, datetime
from pathlib import Path

from peridyn.errors import InputError

#: The lock file in an output folder.
LOCK_FILE = ".peridyn.lock"

#: Seconds after which a lock file that is still empty or unreadable counts as stale (its
#: holder died between creating and writing it).
UNWRITTEN_S = 10.0


class OutputLock:
    """Hold the lock of the output folder ``out`` (created if missing) from construction to
    :meth:`release` (or the end of a ``with`` block).

    Raises
    ------
    InputError
        Another live job holds the folder (the message names its pid, host and start time).
    """

    def __init__(self, out):
        self.folder = Path(out)
        if self.folder.exists() and not self.folder.is_dir():
            raise InputError(f"output folder {str(out)!r} is a file, not a folder: choose another --output")
        self.folder.mkdir(parents=True, exist_ok=True)  # an OSError names the path and the reason
        self.path = self.folder / LOCK_FILE
        self.holder = {
            "pid": os.getpid(),
            "host": socket.gethostname(),
            "started": datetime.now(UTC).isoformat(timespec="seconds"),
        }
        for _ in range(3):  # a stale lock taken over by another job between our tries: try again
            if self._create():
                return
            held = read_holder(self.path)
            if held is None and not self.path.exists():
                continue
            if not _stale(self.path, held):
                raise InputError(_refusal(self.path, held))
            self._take_over()
        raise InputError(_refusal(self.path, read_holder(self.path)))

    def _create(self) -> bool:
        """Create the lock file with this process as holder; False when it exists."""
        try:
            fd = os.open(self.path, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
        except FileExistsError:
            return False
        with os.fdopen(fd, "w") as f:
            f.write(json.dumps(self.holder) + "\n")
        return True

    def _take_over(self) -> None:
        """Move a stale lock away (only one of several jobs doing so at once succeeds)."""
        away = self.path.with_name(f"{LOCK_FILE}.stale.{os.getpid()}")
        try:
            os.rename(self.path, away)
        except FileNotFoundError:
            return
        away.unlink(missing_ok=True)

    def release(self) -> None:
        """Remove the lock file if this process still holds it; calling it again does nothing."""
        if read_holder(self.path) == self.holder:
            self.path.unlink(missing_ok=True)

    def __enter__(self) -> OutputLock:
        return self

    def __exit__(self, *exc) -> None:
        self.release()


def read_holder(path) -> dict | None:
    """The holder recorded in a lock file; None when it is missing, empty or unreadable."""
    try:
        holder = json.loads(Path(path).read_text())
    except (OSError, ValueError):
        return None
    return holder if isinstance(holder, dict) else None


def _stale(path: Path, holder: dict | None) -> bool:
    """True when the lock's holder is gone: a process of this host that no longer runs, or an
    unreadable lock older than ``UNWRITTEN_S``."""
    if holder is None:
        try:
            return time.time() - path.stat().st_mtime > UNWRITTEN_S
        except FileNotFoundError:
            return True
    if holder.get("host") != socket.gethostname():
        return False
    return not process_alive(holder.get("pid"))


def process_alive(pid) -> bool:
    """True when a process with id ``pid`` runs on this host (a process of another user too)."""
    if not isinstance(pid, int) or pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _refusal(path: Path, holder: dict | None) -> str:
    folder = str(path.parent)
    if holder is None:
        return (
            f"output folder {folder!r} is locked by another job ({path} is being written): wait, "
            "or choose another --output"
        )
    who = f"process {holder.get('pid')} on {holder.get('host')}, started {holder.get('started')}"
    here = holder.get("host") == socket.gethostname()
    return (
        f"output folder {folder!r} is in use by another run ({who}): wait for it to end, or choose "
        "another --output" + ("" if here else f"; if that job is gone, remove {str(path)!r}")
    )
