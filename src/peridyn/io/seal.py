"""The seal of a whole HDF5 file (results files, checkpoints): every byte checked before HDF5
opens it.

HDF5 trusts its files: a damaged one (a flipped byte in its metadata, a cut or spliced copy)
may make it fail, return other values, or loop forever where no signal can stop it (HDF5 2.0
reading a damaged variable-length attribute from its global heap). The CRC-32 of each dataset
(``peridyn.io.integrity``) is read through HDF5, so it comes too late for that. Hence:

- When its writer has closed it, a file of peridyn's gets a seal: one line of text appended
  after HDF5's last byte (HDF5 reads a file longer than its data, and cuts a file it writes
  back to its data when it closes it), with the CRC-32 (``zlib.crc32``) and the number of every
  byte before it::

      peridyn seal 1 crc32 1a2b3c4d bytes 00000000000004784197

  Before a writer opens a file for writing (a restart's append and truncation, the end of a
  job) the seal is cut off: a file without a seal is one being written, one whose writer was
  killed, one written before seals were recorded or changed by another program. A checkpoint
  is written whole, so it is always sealed.
- Before HDF5 opens a file to read or continue it (:func:`check`), a sealed file whose bytes
  differ (another number of them before the seal, or another CRC-32) is refused naming the
  file, without HDF5 reading any of it. A file without a seal is read first by a probe in a
  child process with a time limit (``peridyn.io.hdf5_probe``), and refused when the probe
  fails or does not finish.
- Each version of a file (its path, inode, size and modification time) is checked once per
  process; sealing a file counts as checking it.

Cost: the CRC-32 of the whole file, once when a writer closes it and once in each process that
reads it: about 1.3 s for a 1.08 GB results file on a loaded 2-core machine, where checking its
datasets' checksums (which a matching seal makes unnecessary) takes 1.8 s and a probe 1.9 s
(``benchmarks/seal_cost.py``).

CRC-32 finds every burst error of up to 32 bits and any other change with probability
1 - 2^-32; it guards against corruption, not against deliberate tampering.
"""

from __future__ import annotations

import os
import re
import stat
import zlib

from peridyn.errors import InputError
from peridyn.io import hdf5_probe

#: The seal's text: its CRC-32 (8 hex digits) and the bytes it covers (20 digits).
FORMAT = "peridyn seal 1 crc32 {crc:08x} bytes {size:020d}\n"
#: Bytes of a seal.
LENGTH = len(FORMAT.format(crc=0, size=0))
_PATTERN = re.compile(rb"peridyn seal 1 crc32 ([0-9a-f]{8}) bytes ([0-9]{20})\n")
#: Bytes read at a time while computing a file's CRC-32 (small: a run seals its results file
#: while its own arrays are still held, so the piece adds to its peak memory).
READ_BYTES = 4 << 20

#: The versions of files checked in this process: (real path, inode, size, mtime in ns).
_checked: set = set()


def read_seal(path) -> tuple[int, int] | None:
    """The seal at the end of ``path``: the CRC-32 and number of the bytes it covers (those
    before it, unless bytes were added or removed); None when the file ends without one."""
    with open(path, "rb") as f:
        size = f.seek(0, os.SEEK_END)
        if size < LENGTH:
            return None
        f.seek(size - LENGTH)
        match = _PATTERN.fullmatch(f.read(LENGTH))
    return None if match is None else (int(match[1], 16), int(match[2]))


def seal(path) -> None:
    """Append the seal to ``path``, closed by its writer (replacing a seal it has)."""
    unseal(path)
    crc, size = crc_of(path, os.path.getsize(path))
    with open(path, "ab") as f:
        f.write(FORMAT.format(crc=crc, size=size).encode())
    _checked.add(_version(path))


def unseal(path) -> None:
    """Cut the seal off ``path`` (if it has one) before a writer opens it: until the writer
    has closed it, the file is not sealed."""
    found = read_seal(path)
    if found is not None and found[1] == os.path.getsize(path) - LENGTH:
        os.truncate(path, found[1])


def crc_of(path, size: int) -> tuple[int, int]:
    """CRC-32 of the first ``size`` bytes of ``path``, read in pieces, and how many it read
    (fewer when the file is shorter)."""
    crc, done = 0, 0
    with open(path, "rb") as f:
        while done < size and (piece := f.read(min(READ_BYTES, size - done))):
            crc = zlib.crc32(piece, crc)
            done += len(piece)
    return crc, done


def check(path) -> None:
    """Refuse a damaged HDF5 file before HDF5 opens it: a sealed file whose bytes differ from
    its seal, or a file without a seal that the probe cannot read in its time limit
    (``peridyn.io.hdf5_probe``). Each version of a file is checked once per process.

    Raises
    ------
    InputError
        Naming the file and what is wrong; the file is not used.
    """
    version = _version(path)
    if version in _checked:
        return
    if not stat.S_ISREG(os.stat(path).st_mode):
        raise InputError(
            f"{os.fspath(path)}: not a regular file (a pipe, a device or a folder): not an HDF5 file"
        )
    found = read_seal(path)
    if found is None:
        hdf5_probe.probe(path)
    elif found[1] != version[2] - LENGTH:
        raise InputError(
            f"{os.fspath(path)}: holds {version[2] - LENGTH} bytes before its seal, which covers "
            f"{found[1]}: bytes were added or removed; the file is damaged; it is not used"
        )
    elif crc_of(path, found[1])[0] != found[0]:
        raise InputError(
            f"{os.fspath(path)}: its bytes do not match its seal (CRC-32): the file is corrupted; "
            "it is not used"
        )
    if _version(path) == version:  # not changed while it was checked
        _checked.add(version)


def _version(path) -> tuple:
    st = os.stat(path)
    return (os.path.realpath(path), st.st_ino, st.st_size, st.st_mtime_ns)
