"""A second process that draws a run's figures while the run's own process analyses its records.

After the time loop a run's own work is single-threaded: the f-k and kx-ky analyses and their
maps in one half, the sensor, B-scan, field and wavefield figures in the other (2-3 s each for
the Lamb plate case). A worker started before the build, when the run may use a second core,
imports matplotlib and peridyn's plotting while the run builds its model (mostly one core's
work), waits through the time loop, then draws the run figures while the run analyses. The
figures are the same files; only the wall time changes.

The worker is started by ``spawn``, which imports the main module of a script anew: a script
that asks ``run_case`` for it must guard its run with ``if __name__ == "__main__":``.

The worker ends with the run, whatever ended the run (a SIGKILL or an out-of-memory kill too,
which leave the run no chance to shut it down; ``peridyn.jobs.children``)."""

from __future__ import annotations

import multiprocessing
import os
import signal
from collections.abc import Iterator
from concurrent.futures import Future, ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from contextlib import contextmanager

import numba
import numpy as np

from peridyn.errors import InputError
from peridyn.io.case import Case
from peridyn.jobs.children import end_with_parent
from peridyn.setup.estimate import grid_shape

#: Grids with fewer points draw their figures in the run's own process: the worker's start (about
#: 1.5 s of imports) would not be hidden by a short run.
MIN_POINTS = 20_000

#: Scheduling priority added to the worker (``os.nice``): its imports yield to the time loop.
NICENESS = 10


@contextmanager
def figure_worker_for(case: Case, base_dir=".", wanted: bool = True) -> Iterator[ProcessPoolExecutor | None]:
    """A one-process pool for the figures of a run of ``case``, started now (before the build,
    which leaves the second core free for its imports) and shut down on leaving; None when not
    ``wanted`` (an MPI run: the other ranks hold the cores) or when the run draws its own: a
    mesh geometry or a grid under ``MIN_POINTS`` points, or one numba thread (``--threads 1``,
    a sweep's workers: one core asked)."""
    if not wanted or case.geometry.is_mesh or _threads() < 2:
        yield None
        return
    try:
        points = np.prod(grid_shape(case, base_dir)[0])
    except InputError:  # a bad grid: the build reports it
        points = 0
    if points < MIN_POINTS:
        yield None
        return
    pool = ProcessPoolExecutor(
        1, mp_context=multiprocessing.get_context("spawn"), initializer=_initialise, initargs=(os.getpid(),)
    )
    pool.submit(int)  # the pool starts its process at the first task
    try:
        yield pool
    finally:
        pool.shutdown(wait=False, cancel_futures=True)


def _threads() -> int:
    """The numba threads this process runs its kernels on (the cores a run was given)."""
    return numba.get_num_threads()


def submit(pool: ProcessPoolExecutor | None, draw, *args) -> Future | None:
    """``draw(*args)`` sent to the worker ``pool``; None without a worker or when it has died
    (killed, out of memory): ``figures_of`` then draws here."""
    if pool is None:
        return None
    try:
        return pool.submit(draw, *args)
    except BrokenProcessPool:
        return None


def figures_of(pending: Future | None, draw, *args) -> list:
    """The worker's result of ``draw(*args)`` (``pending``, from ``submit``), or ``draw(*args)``
    here when there is no worker or it died: a finished run keeps its figures either way. An
    error of ``draw`` itself is raised as it would be here."""
    if pending is not None:
        try:
            return pending.result()
        except BrokenProcessPool:
            pass
    return draw(*args)


def _initialise(parent: int) -> None:
    """The worker's start: it ends when its ``parent`` (the run's process id) does; Ctrl-C,
    SIGTERM and SIGHUP are the run's to handle (it stops at a safe point, closes its files and
    shuts the worker down); a lower priority, and the plotting imports done now rather than at
    the first figure."""
    end_with_parent(parent)
    for sig in (signal.SIGINT, signal.SIGHUP):
        signal.signal(sig, signal.SIG_IGN)
    os.nice(NICENESS)
    import peridyn.jobs.figures  # noqa: F401
    import peridyn.plotting.fields  # noqa: F401
    import peridyn.plotting.lamb_wavefield  # noqa: F401
