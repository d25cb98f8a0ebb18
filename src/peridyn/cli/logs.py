"""What the command line writes to stderr besides errors: the package's log records (Python
``logging``, logger ``peridyn``) as plain lines, a progress bar where someone watches it and a
heartbeat line at a steady interval where no one does (a redirected log, a batch job), and
warnings as one plain line each."""

from __future__ import annotations

import logging
import os
import sys
import time
import warnings
from contextlib import contextmanager

from peridyn.cli.errors import one_line

logger = logging.getLogger(__name__)

#: Seconds between two heartbeat lines of a long job not on a terminal (the environment variable
#: ``PERIDYN_HEARTBEAT_SECONDS`` changes it).
HEARTBEAT_SECONDS = 30.0


class _Stderr(logging.StreamHandler):
    """A handler that writes to whatever ``sys.stderr`` is when a record comes."""

    @property
    def stream(self):
        return sys.stderr

    @stream.setter
    def stream(self, value):
        pass


def configure_logging() -> None:
    """The ``peridyn`` loggers' INFO records on stderr (once per process), each line starting
    ``peridyn:`` as every line the command writes there does."""
    package = logging.getLogger("peridyn")
    if any(isinstance(h, _Stderr) for h in package.handlers):
        return
    handler = _Stderr()
    handler.setFormatter(logging.Formatter("peridyn: %(message)s"))
    package.addHandler(handler)
    package.setLevel(logging.INFO)


def progress_bar(choice: bool | None, desc: str):
    """A progress-bar factory ``total -> bar`` (with ``update(n)`` and ``close()``): a tqdm bar on
    stderr, or else a :class:`Heartbeat`.

    Parameters
    ----------
    choice : bool or None
        ``--progress`` (True), ``--no-progress`` (False) or neither (None: a bar only when stderr
        is a terminal, never carriage-return lines in a redirected log).
    desc : str
        The bar's label (the case name).
    """
    show = sys.stderr.isatty() if choice is None else choice
    if not show:
        seconds = float(os.environ.get("PERIDYN_HEARTBEAT_SECONDS", HEARTBEAT_SECONDS))
        return lambda total: Heartbeat(total, desc, seconds)
    from tqdm import tqdm

    def factory(total: int):
        return tqdm(total=total, unit="step", file=sys.stderr, dynamic_ncols=True, desc=desc)

    return factory


@contextmanager
def plain_warnings():
    """Within the block, a warning prints as ``peridyn: warning: <message>`` on one line, without
    the source file and line; the previous ``warnings.showwarning`` is restored after."""
    saved = warnings.showwarning

    def show(message, category, filename, lineno, file=None, line=None):
        print(f"peridyn: warning: {one_line(str(message))}", file=file or sys.stderr)

    warnings.showwarning = show
    try:
        yield
    finally:
        warnings.showwarning = saved


class Heartbeat:
    """A progress report for a log: every ``seconds`` of a job, one INFO line of logger
    ``peridyn.cli.logs``, e.g. ``bar_pulse: step 4000 of 8000 (50 %), 61 s, about 61 s left``.

    Parameters
    ----------
    total : int
        Steps of the job.
    desc : str
        What is counted (the case name).
    seconds : float
        Least time between two lines, s.
    """

    def __init__(self, total: int, desc: str, seconds: float, clock=time.monotonic):
        self.total, self.desc, self.seconds, self.clock = total, desc, seconds, clock
        self.done = 0
        self.start = self.last = clock()

    def update(self, n: int = 1) -> None:
        """Count ``n`` more steps; log a line when ``seconds`` have passed since the last."""
        self.done += n
        now = self.clock()
        if now - self.last < self.seconds:
            return
        self.last = now
        elapsed = now - self.start
        left = elapsed * (self.total - self.done) / self.done if self.done else float("nan")
        share = 100 * self.done / self.total if self.total else 100.0
        logger.info(
            f"{self.desc}: step {self.done} of {self.total} ({share:.0f} %), {elapsed:.0f} s, "
            f"about {left:.0f} s left"
        )

    def close(self) -> None:
        """Nothing to release (the tqdm bar's protocol)."""
