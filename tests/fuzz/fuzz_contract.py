"""The contract every fuzz example is held to (docs/user-guide.md, "Errors"), checked in-process
for the reading and validating functions and counted over a campaign.

An example either succeeds or is refused with an error the command line reports as one line
(``peridyn.cli.errors.describe``: a ``PeridynError`` or an I/O error naming its file, exit status
1), never an exception no check anticipated (a traceback, "internal error"), never a hang
(``HANG_S``) and never a change to the files it reads or to an earlier run's folder.
"""

from __future__ import annotations

import hashlib
import os
import pickle
import select
import signal
import time
from collections import Counter
from contextlib import contextmanager
from pathlib import Path

from peridyn.cli.errors import describe
from peridyn.errors import PeridynError

#: Seconds after which an in-process example counts as a hang (the slowest example takes < 2 s).
HANG_S = 20.0

#: What each campaign counted, by campaign: examples, outcomes and the failures of the contract.
TALLIES: dict[str, Counter] = {}

#: The failures of the contract that a campaign counts (each must stay 0).
FAILURES = ("tracebacks", "hangs", "crashes", "orphans", "modified bytes", "corrupted and used")


class Hang(Exception):
    """An example ran past ``HANG_S``."""


@contextmanager
def time_limit(seconds: float = HANG_S):
    """Raise :class:`Hang` in the block after ``seconds`` (SIGALRM: the main thread only)."""

    def alarm(signum, frame):
        raise Hang(f"no answer after {seconds} s")

    previous = signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def tally(campaign: str) -> Counter:
    """The counter of ``campaign`` (made with every failure at 0)."""
    return TALLIES.setdefault(campaign, Counter(dict.fromkeys(FAILURES, 0)))


def outcome(campaign: str, call, what: str, names: str | None = None):
    """Run ``call()`` under the contract; returns ("ok", its value) or ("refused", the message).

    A refusal must be one the command line reports as one line with exit status 1 (naming
    ``names``, e.g. the file, when given). Anything else is counted in ``campaign``'s tally
    (traceback, hang) and fails with ``what`` (how the example was made, to reproduce it).
    """
    counts = tally(campaign)
    counts["examples"] += 1
    try:
        with time_limit():
            value = call()
    except Hang as exc:
        counts["hangs"] += 1
        raise AssertionError(f"{what}: {exc}") from exc
    except Exception as exc:  # the contract: every exception is one the command line anticipates
        failure = _verdict(exc, names)
        if failure is not None:
            counts["tracebacks"] += 1
            raise AssertionError(f"{what}: {failure}") from exc
        counts["refused"] += 1
        return "refused", str(exc)
    counts["ok"] += 1
    return "ok", value


def _verdict(exc: Exception, names: str | None) -> str | None:
    """None when ``exc`` is a refusal the contract allows (see :func:`outcome`), else why not."""
    message, status = describe(exc, "peridyn run")
    expected = isinstance(exc, PeridynError) or (isinstance(exc, OSError) and exc.filename is not None)
    if not expected or status != 1 or (names is not None and names not in message):
        return f"{type(exc).__name__}: {exc}"
    return None


def outcome_in_a_fork(campaign: str, call, what: str, names: str | None = None) -> str:
    """:func:`outcome` for a ``call`` that may hang where a signal cannot stop it (in a C
    library: HDF5): run in a forked process, killed after ``HANG_S``. ``call`` returns the
    list of the values it read that differ from the file's true ones (empty: none); returns
    "ok" or "refused"."""
    counts = tally(campaign)
    counts["examples"] += 1
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: one pickled answer, then out without cleanup
        os.close(read)
        try:
            answer = ("ok", call())
        except Exception as exc:
            answer = ("raised", _verdict(exc, names))
        os.write(write, pickle.dumps(answer))
        os._exit(0)
    os.close(write)
    deadline, data = time.monotonic() + HANG_S, b""
    while (left := deadline - time.monotonic()) > 0 and select.select([read], [], [], left)[0]:
        chunk = os.read(read, 1 << 16)
        if not chunk:
            break
        data += chunk
    os.close(read)
    if not data:
        os.kill(pid, signal.SIGKILL)
    _, status = os.waitpid(pid, 0)
    if not data:
        counts[
            "hangs" if os.WIFSIGNALED(status) and os.WTERMSIG(status) == signal.SIGKILL else "crashes"
        ] += 1
        raise AssertionError(f"{what}: no answer in {HANG_S} s or a crash (wait status {status})")
    kind, detail = pickle.loads(data)
    if kind == "raised" and detail is not None:
        counts["tracebacks"] += 1
        raise AssertionError(f"{what}: {detail}")
    if kind == "ok" and detail:
        counts["corrupted and used"] += 1
        raise AssertionError(f"{what}: a corrupted file was read with other values ({detail})")
    counts["ok" if kind == "ok" else "refused"] += 1
    return "ok" if kind == "ok" else "refused"


def fingerprint(folder: Path) -> dict[str, str]:
    """sha256 of every file under ``folder`` by path, but ``run.log`` (the folder's journal, to
    which every job appends by design, docs/user-guide.md)."""
    return {
        str(f): hashlib.sha256(f.read_bytes()).hexdigest()
        for f in sorted(Path(folder).rglob("*"))
        if f.is_file() and f.name != "run.log"
    }


def check_unchanged(campaign: str, before: dict, folder: Path, what: str) -> None:
    """Count and fail when a file under ``folder`` differs from ``before`` (its fingerprint)."""
    after = fingerprint(folder)
    if after != before:
        tally(campaign)["modified bytes"] += 1
        changed = sorted(k for k in set(before) | set(after) if before.get(k) != after.get(k))
        raise AssertionError(f"{what}: an earlier run's files changed: {changed}")


def report(campaign: str) -> str:
    """One line of ``campaign``'s counts (printed by each test; ``pytest -s`` shows them)."""
    counts = tally(campaign)
    return f"fuzz {campaign}: " + ", ".join(f"{k} {v}" for k, v in sorted(counts.items()))
