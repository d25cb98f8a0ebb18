"""The files every job leaves in its output folder, whatever its kind (run, modal, fatigue,
study, sweep): one output contract.

- ``status.json``: ``{"status": ...}``, one of ``running``, ``complete``, ``failed: <reason>``,
  ``interrupted ...`` (``peridyn.io.outdir``);
- ``provenance.json``: what made the results (package version and commit, command line, case
  file and case: ``peridyn.io.provenance``);
- ``summary.json``: the job's summary once it is complete (its ``kind`` says which job; keys in
  docs/user-guide.md, "Summaries and results files").

A run and a modal job also keep their status, provenance and summary inside ``results.h5``, a
fatigue job its summary in ``fatigue.json`` and a study in ``study.json``; ``read_job`` reads the
three files of any job's folder.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from peridyn.errors import InputError
from peridyn.io.hdf5 import to_json
from peridyn.io.outdir import STATUS_FILE, json_job_status, read_status

#: The provenance of a job's results in its output folder.
PROVENANCE_FILE = "provenance.json"
#: The summary of a complete job in its output folder.
SUMMARY_FILE = "summary.json"
#: The files of the output contract, in every job's output folder.
JOB_FILES = (STATUS_FILE, PROVENANCE_FILE, SUMMARY_FILE)


def write_json_file(path: Path, value, what: str) -> None:
    """Write ``value`` as JSON to ``path``, replacing it atomically (``what`` names it in an error)."""
    path = Path(path)
    text = to_json(value, f"{path}: {what}") + "\n"
    tmp = path.with_name(path.name + ".tmp")
    try:
        tmp.write_text(text)
        tmp.replace(path)
    except BaseException:
        tmp.unlink(missing_ok=True)  # e.g. a full disk: no partial file left beside the results
        raise


def write_provenance(out, info: dict) -> None:
    """``<out>/provenance.json``: the provenance ``info`` of the job's results."""
    write_json_file(Path(out) / PROVENANCE_FILE, info, "provenance")


def write_summary(out, summary: dict) -> None:
    """``<out>/summary.json``: the summary of the complete job."""
    write_json_file(Path(out) / SUMMARY_FILE, summary, "summary")


@contextmanager
def job_files(out, info: dict) -> Iterator[None]:
    """The provenance ``info`` written, then the job's status: ``running`` within the block,
    ``complete`` after it, or the status of what the block raised (which goes on). The job
    writes its summary (``write_summary``) within the block."""
    write_provenance(out, info)
    with json_job_status(out):
        yield


def read_job(out) -> dict:
    """``{"status", "provenance", "summary"}`` of a job's output folder ``out`` (``summary``
    None until the job is complete).

    Raises
    ------
    InputError
        A file of the contract is missing or not JSON, naming it.
    """
    out = Path(out)
    found = {"status": read_status(out)}
    for key, name in (("provenance", PROVENANCE_FILE), ("summary", SUMMARY_FILE)):
        path = out / name
        if key == "summary" and not path.exists() and found["status"] != "complete":
            found[key] = None
            continue
        try:
            found[key] = json.loads(path.read_text())
        except FileNotFoundError:
            raise InputError(
                f"{str(path)!r} does not exist: not the folder of a finished peridyn job"
            ) from None
        except ValueError as exc:
            raise InputError(f"{str(path)!r} is not JSON ({exc})") from None
    return found
