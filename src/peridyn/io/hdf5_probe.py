"""The probe of an HDF5 file without a seal (``peridyn.io.seal``): read whole in a child process
with a time limit, before the process that wants the file lets HDF5 open it.

A damaged HDF5 file can make HDF5 loop forever inside the library, where Python cannot
interrupt it. The probe (``python -c`` running :func:`main`) opens the file and reads what a
reader of it may touch: every attribute of every group and dataset, the dimension scales of
each dataset, and every dataset's values, checked against their checksums when the file
declares them (``peridyn.io.integrity.verify_file``). A probe that fails is refused with its
one-line error; one that does not finish in :func:`time_limit` is killed and the file refused
as damaged. HDF5 is deterministic, so what the probe read without trouble the parent reads the
same way. A file without HDF5's signature, or shorter than its superblock's end-of-file address
(a copy cut short), which HDF5 refuses, is refused without a probe (:func:`has_signature`,
:func:`stored_end`).

The probe also ends itself at its time limit (the default action of SIGALRM, which a loop in
HDF5 cannot block), so it never outlives a parent killed while waiting for it by more than that.
"""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
from pathlib import Path

import h5py

from peridyn.errors import InputError
from peridyn.io import integrity

#: Seconds a probe may take, beyond :data:`BYTES_PER_S`; the environment variable
#: ``PERIDYN_PROBE_SECONDS`` sets another (a slow file system, a loaded machine).
TIME_LIMIT_S = 20.0
#: Bytes per second of the file allowed on top of :data:`TIME_LIMIT_S`.
BYTES_PER_S = 50e6
#: HDF5's signature, at the start of its superblock.
HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"
#: The folder holding the ``peridyn`` package the probe runs (this one).
_PACKAGE_ROOT = str(Path(__file__).resolve().parents[2])


def time_limit(size: int) -> float:
    """Seconds allowed to probe a file of ``size`` bytes."""
    base = os.environ.get("PERIDYN_PROBE_SECONDS")
    try:
        base = float(base) if base is not None else TIME_LIMIT_S
    except ValueError:
        raise InputError(f"PERIDYN_PROBE_SECONDS must be a number of seconds, got {base!r}") from None
    if not base > 0:
        raise InputError(f"PERIDYN_PROBE_SECONDS must be positive, got {base!r}")
    return base + size / BYTES_PER_S


def probe(path) -> None:
    """Read ``path`` whole in a child process, killed after :func:`time_limit`.

    Raises
    ------
    InputError
        Naming the file: HDF5 did not finish reading it in time, crashed on it, or it is not
        an HDF5 file or does not match its checksums (the probe's own message).
    """
    path = os.fspath(path)
    size = os.path.getsize(path)
    if not has_signature(path, size):
        raise InputError(
            f"{path}: not a readable HDF5 file (no HDF5 signature): damaged or not HDF5; it is not used"
        )
    stored = stored_end(path)
    if stored is not None and size < stored:
        raise InputError(
            f"{path}: holds {size} bytes, its HDF5 superblock says {stored}: the file is truncated; "
            "it is not used"
        )
    limit = time_limit(size)
    code = f"import sys; sys.path.insert(0, {_PACKAGE_ROOT!r}); from {__name__} import main; main()"
    try:
        done = subprocess.run(
            [sys.executable, "-c", code, path, repr(limit)],
            stdin=subprocess.DEVNULL,
            capture_output=True,
            text=True,
            errors="replace",
            timeout=limit,
        )
    except subprocess.TimeoutExpired:  # the child is killed
        raise InputError(
            f"{path}: HDF5 did not finish reading it in {limit:.0f} s: the file is damaged; it is not used"
        ) from None
    if done.returncode == 0:
        return
    lines = done.stderr.strip().splitlines()
    if done.returncode > 0 and lines:
        raise InputError(lines[-1])
    ended = signal.Signals(-done.returncode).name if done.returncode < 0 else f"exit {done.returncode}"
    raise InputError(f"{path}: HDF5 ended reading it ({ended}): the file is damaged; it is not used")


def has_signature(path, size: int) -> bool:
    """Whether HDF5's signature is where HDF5 looks for its superblock: at byte 0, 512, 1024,
    2048 ... of the file (after a user block of that size)."""
    with open(path, "rb") as f:
        at = 0
        while at + len(HDF5_SIGNATURE) <= size:
            f.seek(at)
            if f.read(len(HDF5_SIGNATURE)) == HDF5_SIGNATURE:
                return True
            at = max(512, 2 * at)
    return False


def stored_end(path) -> int | None:
    """The end-of-file address in the superblock at the start of the HDF5 file ``path`` (HDF5
    File Format Specification, "Superblock": versions 0 and 1 after 24 or 28 bytes and the base
    and free-space addresses, versions 2 and 3 after 12 bytes and the base and extension
    addresses); None when the file does not start with a superblock of base address 0 that
    these bytes can be read from (a user block, a damaged superblock: left to the probe).
    HDF5 refuses a file shorter than that ("truncated file"): checked here, no probe needed."""
    with open(path, "rb") as f:
        head = f.read(64)
    if not head.startswith(HDF5_SIGNATURE) or len(head) < 16:
        return None
    version = head[8]
    if version in (0, 1):
        width, base_at = head[13], 24 + 4 * version
    elif version in (2, 3):
        width, base_at = head[9], 12
    else:
        return None
    end_at = base_at + 2 * width
    if width not in (2, 4, 8) or len(head) < end_at + width:
        return None
    if int.from_bytes(head[base_at : base_at + width], "little") != 0:
        return None
    return int.from_bytes(head[end_at : end_at + width], "little")


def read_whole(path: str) -> None:
    """Read every attribute, dimension scale and dataset of the HDF5 file ``path`` (datasets in
    pieces, against their checksums when the file declares them)."""
    with h5py.File(path, "r") as f:
        found = [f]
        f.visititems(lambda _, obj: found.append(obj))
        for obj in found:
            for key in obj.attrs:
                obj.attrs[key]
            if isinstance(obj, h5py.Dataset):
                for dim in obj.dims:
                    [scale.name for scale in dim.values()]
        if integrity.is_marked(f):
            integrity.verify_file(f, path)
            return
        for obj in found:
            if isinstance(obj, h5py.Dataset):
                integrity.prefix_crcs(obj, [integrity.rows_of(obj)])


def main() -> None:
    """The child: ``<path> <time limit in s>``; exit 0 when the file reads, else 1 with the
    reason on stderr."""
    path, limit = sys.argv[1], float(sys.argv[2])
    if hasattr(signal, "alarm"):  # POSIX: the kernel ends the probe at its limit
        signal.signal(signal.SIGALRM, signal.SIG_DFL)
        signal.alarm(math.ceil(limit) + 1)
    try:
        read_whole(path)
    except InputError as exc:
        print(" ".join(str(exc).split()), file=sys.stderr)
        sys.exit(1)
    except Exception as exc:  # HDF5 finds a damaged structure: any error means the same
        reason = " ".join(str(exc).split())
        print(
            f"{path}: not a readable HDF5 file ({reason}): damaged or not HDF5; it is not used",
            file=sys.stderr,
        )
        sys.exit(1)
