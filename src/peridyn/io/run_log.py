"""The plain-text log of a job in its output folder, ``run.log``.

While :func:`run_log` is active every record of the ``peridyn`` loggers at INFO and above (the
modules' ``logging.getLogger(__name__)``: the job's start and end, a restart, the heartbeat of a
long run, warnings) is appended to ``<folder>/run.log``, one line each, stamped with the UTC time::

    2026-11-29T09:15:02Z INFO peridyn.jobs.run: case 'bar_pulse': 1280 points, 127 steps of 1.58e-07 s
"""

from __future__ import annotations

import logging
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

#: The log file's name in a job's output folder.
RUN_LOG = "run.log"

#: The package's top logger: every module's logger is below it.
PACKAGE_LOGGER = "peridyn"


class _UTCFormatter(logging.Formatter):
    converter = time.gmtime


@contextmanager
def run_log(folder, enabled: bool = True) -> Iterator[Path | None]:
    """Append the ``peridyn`` log records to ``folder/run.log`` within the block (an existing log,
    e.g. of the run a restart continues, is kept); ``enabled`` False (an MPI rank other than 0)
    does nothing. Yields the log's path, or None."""
    if not enabled:
        yield None
        return
    path = Path(folder) / RUN_LOG
    handler = logging.FileHandler(path, mode="a", encoding="utf-8")
    line = "%(asctime)s %(levelname)s %(name)s: %(message)s"
    handler.setFormatter(_UTCFormatter(line, "%Y-%m-%dT%H:%M:%SZ"))
    handler.setLevel(logging.INFO)
    logger = logging.getLogger(PACKAGE_LOGGER)
    level = logger.level
    if logger.getEffectiveLevel() > logging.INFO:
        logger.setLevel(logging.INFO)
    logger.addHandler(handler)
    try:
        yield path
    finally:
        logger.removeHandler(handler)
        logger.setLevel(level)
        handler.close()
