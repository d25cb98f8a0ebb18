"""A job's output folder: checked before anything is written to it, and the job's status.

An earlier job's results are never replaced unless asked: ``prepare_output`` refuses a folder
that holds one (its ``results.h5``, or the JSON summary of a fatigue job) unless the
caller passes ``overwrite`` (start again) or ``restart`` (continue from its checkpoint).

A job's status is one of ``running``, ``complete``, ``failed: <reason>``, ``interrupted at
step N`` and (for a job without time steps) ``interrupted while <what it was doing>``. Every job
keeps it in ``status.json`` (``{"status": ...}``), written and read here, beside its provenance
and summary (``peridyn.io.job_files``, the output contract); a run and a modal job also keep it
in the ``status`` root attribute of ``results.h5`` (``HDF5Writer.set_status``, read with
``Results.status``).
"""

from __future__ import annotations

import json
import os
import shutil
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from peridyn.errors import InputError, InstabilityError, Interrupted, PeridynError
from peridyn.io.reserve import disk_errno

#: Name of the status file of the jobs that write JSON rather than results.h5.
STATUS_FILE = "status.json"


def prepare_output(
    out, marker: str, overwrite: bool = False, restart: bool = False, earlier: tuple = (), restartable=True
) -> Path:
    """Check the output folder ``out`` and create it; returns it as a Path. With ``overwrite``,
    the earlier job's files (``earlier``: names and glob patterns of what such a job writes,
    e.g. ``RUN_OUTPUTS``) are removed first, so that none is left beside the new job's.

    Parameters
    ----------
    out : path
    marker : str
        The file whose presence means an earlier job's results (e.g. ``"results.h5"``).
    overwrite, restart : bool
        Replace the earlier results, or continue them (mutually exclusive).
    earlier : tuple of str
        What ``overwrite`` removes.
    restartable : bool
        Whether the command can continue earlier results (the refusal suggests ``--restart``).

    Raises
    ------
    InputError
        ``out`` is not a folder or cannot be created, or it holds earlier results and
        neither ``overwrite`` nor ``restart`` is given.
    """
    out = Path(out)
    if overwrite and restart:
        raise InputError("--overwrite and --restart exclude each other: restart continues the results")
    if out.exists() and not out.is_dir():
        raise InputError(f"output folder {str(out)!r} is a file, not a folder: choose another --output")
    if (out / marker).exists() and not (overwrite or restart):
        restart_hint = ", --restart to continue it" if restartable else ""
        raise InputError(
            f"output folder {str(out)!r} holds an earlier run's {marker}: pass --overwrite to replace "
            f"it{restart_hint}, or choose another --output"
        )
    out.mkdir(parents=True, exist_ok=True)  # an OSError names the path and the reason (the CLI prints it)
    if overwrite:
        remove_outputs(out, earlier)
    return out


#: What a run, static or modal job writes in its output folder (names and glob patterns):
#: removed by ``--overwrite`` before the new job writes (not ``run.log``: each job appends to it).
RUN_OUTPUTS = (
    "results.h5",
    "checkpoint.h5",
    "checkpoint.h5.tmp",
    "snapshots.pvd",
    "snapshots",
    "modes",
    "figures",
    "*.png",
    "*.e",
    "*.exo",
    "crack_length.csv",
    "modes.csv",
    "modes.json",
    "modal.json",
    "damage.vtu",
    "mode_*.vtu",
    ".peridyn.reserve",
    "status.json",
    "provenance.json",
    "summary.json",
)


def remove_outputs(out: Path, patterns) -> None:
    """Remove the files and folders of ``out`` that match ``patterns`` (top level only)."""
    for pattern in patterns:
        for path in sorted(out.glob(pattern)):
            if path.is_dir() and not path.is_symlink():
                shutil.rmtree(path)
            else:
                path.unlink(missing_ok=True)


def write_status(out, status: str) -> None:
    """Write ``status`` to ``<out>/status.json`` (replacing it atomically)."""
    path = Path(out) / STATUS_FILE
    tmp = path.with_suffix(".json.tmp")
    tmp.write_text(json.dumps({"status": status}) + "\n")
    tmp.replace(path)


def read_status(out) -> str:
    """The status in ``<out>/status.json``.

    Raises
    ------
    InputError
        The file is missing or not a status file.
    """
    path = Path(out) / STATUS_FILE
    try:
        return str(json.loads(path.read_text())["status"])
    except FileNotFoundError:
        raise InputError(f"{str(path)!r} does not exist: no job status in that folder") from None
    except (ValueError, KeyError, TypeError) as exc:
        raise InputError(f"{str(path)!r} is not a status file ({exc})") from None


def end_status(exc: BaseException) -> str:
    """The status of a job ended by ``exc``: ``interrupted ...`` for a signal, else
    ``failed: <reason>``."""
    if isinstance(exc, Interrupted):
        return f"interrupted {exc.progress}".rstrip()
    if isinstance(exc, InstabilityError):
        return f"failed: unstable at step {exc.step} (t = {exc.time:.6g} s, point {exc.point}): {exc}"
    number = disk_errno(exc)
    if number is not None:  # a full or failing disk: what and where, not the HDF5 report
        where = getattr(exc, "filename", None)
        return f"failed: {os.strerror(number)}" + (f" ({where})" if where else "")
    reason = str(exc) if isinstance(exc, PeridynError) else f"{type(exc).__name__}: {exc}"
    return f"failed: {reason}"


@contextmanager
def json_job_status(out) -> Iterator[None]:
    """``status.json`` of a job that writes JSON: ``running`` within the block, then
    ``complete``, or the :func:`end_status` of what the block raised (which goes on)."""
    write_status(out, "running")
    try:
        yield
    except Exception as exc:
        write_status(out, end_status(exc))
        raise
    write_status(out, "complete")
