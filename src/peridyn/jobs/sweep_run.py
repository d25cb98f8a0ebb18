"""Running a sweep's runs: one run in its folder (:func:`execute`), and the executors that run
many (``serial``, ``processes``, ``dask``), each reporting every finished run as it comes.

A run's record (``run.json`` in its folder, written atomically when the run ends) holds its
id, index, parameters, case hash, status (``complete``, ``failed: <reason>`` or
``interrupted ...``), error text, numba threads, wall time, the moment it ended (Unix time, s)
and the job's summary. A run that raises is
recorded as failed and never stops the sweep; a worker process that dies is replaced and its
runs are submitted again (at most :data:`MAX_ATTEMPTS` times each).
"""

from __future__ import annotations

import json
import os
import time
from collections.abc import Callable, Iterable
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from peridyn.errors import InputError, Interrupted
from peridyn.io.outdir import end_status

#: Executors of ``peridyn sweep --executor``.
EXECUTORS = ("serial", "processes", "dask")
#: A run's record in its folder.
RECORD = "run.json"
#: Times a run is submitted before a worker's death is taken for the run's fault.
MAX_ATTEMPTS = 3
#: Test hook: when this variable names a file that does not exist, the next run to start creates
#: it and kills its worker process (``os._exit``), to exercise the retry of a dead worker.
CRASH_ONCE_ENV = "PERIDYN_SWEEP_CRASH_ONCE"
#: Environment variables that size a worker's thread pools (numba, OpenMP, BLAS).
THREAD_ENV = ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


@dataclass(frozen=True)
class RunTask:
    """What a worker needs to do one run (picklable).

    Attributes
    ----------
    run_id, index, parameters, case, case_hash
        As in :class:`peridyn.jobs.sweep_spec.SweepRun`.
    command : "run", "modal" or "fatigue"
    run_dir : str
        The run's output folder.
    base_dir : str
        Folder of the base case (relative paths of the case are read from it).
    threads : int or None
        numba threads for the run, set before it starts (None: leave the worker's setting;
        a worker process started by the sweep also has its BLAS and OpenMP pools sized to it,
        :func:`worker_environment`).
    reference_dir : str or None
        A modal run's folder to compare this modal run's modes with (``comparison`` in the
        summary: frequency change and MAC of each reference mode).
    bloch : tuple of float
        Frequencies (Hz) of the Bloch prediction added to the summary (``bloch``).
    """

    run_id: str
    index: int
    parameters: dict
    case: object
    case_hash: str
    command: str
    run_dir: str
    base_dir: str
    threads: int | None
    reference_dir: str | None = None
    bloch: tuple = ()


def execute(task: RunTask) -> dict:
    """Do one run in ``task.run_dir`` (replacing an earlier attempt there), write its record
    and return it. Every exception of the job is caught and recorded."""
    _crash_hook()
    if task.threads is not None:
        set_threads(task.threads)
    start = time.perf_counter()
    record = {**_identity(task), "threads": _numba_threads()}
    try:
        summary = _job(task)
        record.update(status="complete", error="", summary=summary)
    except Interrupted as exc:
        record.update(status=f"interrupted ({exc.signal_name})", error=str(exc), summary=None)
    except Exception as exc:  # noqa: BLE001 - a failed run is recorded and the sweep goes on
        record.update(status=end_status(exc), error=f"{type(exc).__name__}: {exc}", summary=None)
    record["seconds"] = time.perf_counter() - start
    record["finished"] = time.time()
    write_record(task.run_dir, record)
    return record


def _job(task: RunTask) -> dict:
    """The job's summary (run, modal, fatigue: ``jobs.dispatch.run_job``; bloch: none), with
    the comparison with the reference and the Bloch prediction when asked."""
    Path(task.run_dir).mkdir(parents=True, exist_ok=True)
    summary = {}
    if task.command != "bloch":
        from peridyn.jobs.dispatch import run_job

        summary = run_job(task.command, task.case, task.run_dir, base_dir=task.base_dir, overwrite=True)
    if task.reference_dir is not None and task.command == "modal":
        from peridyn.jobs.modal import compare_with_run

        summary["comparison"] = compare_with_run(Path(task.run_dir), Path(task.reference_dir))
    if task.bloch:
        summary["bloch"] = bloch_prediction(task.case, task.bloch)
    return summary


def bloch_prediction(case, frequencies) -> dict:
    """``{mode: {"<f>": {"wavenumber_rad_m", "theory_rad_m", "error"}}}`` of the Bloch analysis
    of the case's discretisation at ``frequencies`` (Hz) (None where a branch stays below f)."""
    from peridyn.analysis.bloch import BlochLattice
    from peridyn.analysis.bloch_study import predict

    out: dict = {}
    for row in predict(BlochLattice.from_case(case), list(frequencies)):
        out.setdefault(row["mode"], {})[f"{row['frequency_hz']:g}"] = {
            "wavenumber_rad_m": row["wavenumber_rad_m"],
            "theory_rad_m": row["theory_wavenumber_rad_m"],
            "error": row["error"],
        }
    return out


def _crash_hook() -> None:
    marker = os.environ.get(CRASH_ONCE_ENV)
    if marker and not os.path.exists(marker):
        Path(marker).write_text("crashed\n")
        os._exit(70)


def set_threads(n: int) -> None:
    """Use ``n`` numba threads in this process (at most numba's pool size)."""
    import numba

    numba.set_num_threads(max(1, min(n, numba.config.NUMBA_NUM_THREADS)))


def _numba_threads() -> int:
    """The numba threads this process's kernels run with."""
    import numba

    return numba.get_num_threads()


def write_record(run_dir, record: dict) -> None:
    """Write ``<run_dir>/run.json`` atomically."""
    path = Path(run_dir) / RECORD
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(record, indent=1, default=_builtin) + "\n")
    os.replace(tmp, path)


def read_record(run_dir) -> dict | None:
    """The record in ``<run_dir>/run.json``, or None when there is none (or it is unreadable)."""
    try:
        return json.loads((Path(run_dir) / RECORD).read_text())
    except (OSError, ValueError):
        return None


def _builtin(obj):
    if hasattr(obj, "tolist"):
        return obj.tolist()
    raise TypeError(f"not JSON serialisable: {type(obj).__name__}")


def threads_per_worker(workers: int) -> int:
    """numba threads for each of ``workers`` workers so that together they use the cores once."""
    return max(1, available_cores() // max(1, workers))


def run_threads(threads: int | None, executor: str, workers: int, scheduler: str | None) -> int | None:
    """Threads per run (``--threads``): ``threads`` when given, else ``cores // workers`` for the
    workers a sweep starts itself (processes, a local dask cluster) and None (the process's or
    the cluster workers' own setting) for the serial executor and a ``--scheduler`` cluster.

    Raises
    ------
    InputError
        ``threads`` is not a whole number >= 1.
    """
    if threads is not None:
        if isinstance(threads, bool) or not isinstance(threads, int) or threads < 1:
            raise InputError(f"threads must be a whole number >= 1, got {threads!r}")
        return threads
    if executor == "serial" or scheduler is not None:
        return None
    return threads_per_worker(workers)


def available_cores() -> int:
    """Cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


def run_tasks(
    tasks: list[RunTask],
    on_done: Callable[[dict], bool],
    executor: str = "serial",
    workers: int = 1,
    scheduler: str | None = None,
) -> None:
    """Run ``tasks``, calling ``on_done(record)`` in this process as each run finishes; it
    returns False to stop (no more runs are started; those running finish).

    Raises
    ------
    InputError
        An unknown executor, or ``dask`` without dask installed.
    KeyboardInterrupt
        Ctrl-C: no more runs are started (the records of finished runs are all reported).
    """
    if executor not in EXECUTORS:
        raise InputError(f"executor must be one of {EXECUTORS}, got {executor!r}")
    if not tasks and executor != "dask":
        return
    if executor == "serial":
        with numba_threads_kept():
            for task in tasks:
                if not on_done(execute(task)):
                    return
    elif executor == "processes":
        _run_processes(tasks, on_done, workers)
    else:
        _run_dask(tasks, on_done, workers, scheduler)


def _run_processes(tasks, on_done, workers: int) -> None:
    """A ProcessPoolExecutor of ``workers`` spawned processes, given one run per free worker
    (so that stopping starts no more runs); a broken pool (a worker died) is replaced and its
    unfinished runs are submitted again."""
    import multiprocessing
    from collections import deque
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
    from concurrent.futures.process import BrokenProcessPool

    attempts = {t.run_id: 0 for t in tasks}
    todo = deque(tasks)
    with worker_environment(tasks[0].threads):
        while todo:
            pool = ProcessPoolExecutor(
                workers,
                mp_context=multiprocessing.get_context("spawn"),
                initializer=_quiet_worker,
                initargs=(os.getpid(),),
            )
            pending, broken = {}, []
            try:
                while todo or pending:
                    while todo and not broken and len(pending) < workers:
                        task = todo.popleft()
                        attempts[task.run_id] += 1
                        pending[pool.submit(execute, task)] = task
                    if not pending:
                        break
                    done, _ = wait(pending, return_when=FIRST_COMPLETED)
                    for future in done:
                        task = pending.pop(future)
                        try:
                            record = future.result()
                        except BrokenProcessPool:
                            broken.append(task)
                            continue
                        if not on_done(record):
                            return
            finally:
                pool.shutdown(wait=True, cancel_futures=True)
            for task in reversed(broken):
                if attempts[task.run_id] < MAX_ATTEMPTS:
                    todo.appendleft(task)
                elif not on_done(_lost(task, f"its worker process died {MAX_ATTEMPTS} times")):
                    return


def _quiet_worker(parent: int) -> None:
    """A pool worker ends with the sweep's process ``parent`` (``peridyn.jobs.children``) and
    ignores Ctrl-C (the sweep's process stops the sweep), except within a run's time stepping,
    whose own handlers end the run at the end of a step."""
    import signal

    from peridyn.jobs.children import end_with_parent

    end_with_parent(parent)
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _identity(task: RunTask) -> dict:
    """The keys of a run's record that say which run it is."""
    return {
        "run_id": task.run_id,
        "index": task.index,
        "parameters": task.parameters,
        "case_hash": task.case_hash,
        "command": task.command,
    }


def _lost(task: RunTask, reason: str) -> dict:
    """The record of a run that no worker could finish (also written to its folder)."""
    record = {
        **_identity(task),
        "status": f"failed: {reason}",
        "error": reason,
        "summary": None,
        "seconds": 0.0,
        "finished": time.time(),
    }
    write_record(task.run_dir, record)
    return record


def _run_dask(tasks, on_done, workers: int, scheduler: str | None) -> None:
    """Dask distributed: a LocalCluster of ``workers`` single-threaded processes, or the cluster
    at ``scheduler``. The scheduler resubmits the runs of a worker that dies."""
    try:
        from dask.distributed import Client, LocalCluster, as_completed
    except ImportError:
        raise InputError(
            "--executor dask needs dask.distributed: install the sweep extra (pip install 'peridyn[sweep]')"
        ) from None
    import logging

    if not tasks:  # nothing to run (dask's presence is checked all the same)
        return
    cluster = None
    if scheduler is None:
        threads = tasks[0].threads if tasks else 1
        cluster = LocalCluster(
            n_workers=workers,
            threads_per_worker=1,
            processes=True,
            env={name: str(threads) for name in THREAD_ENV},
            dashboard_address=None,
            silence_logs=logging.ERROR,
        )
    client = Client(cluster if cluster is not None else scheduler)
    try:
        futures = [client.submit(execute, t, key=f"peridyn-run-{t.run_id}", pure=False) for t in tasks]
        finished = as_completed(futures)
        for future in finished:
            if not on_done(future.result()):
                break
        for future in futures:
            future.cancel()
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


@contextmanager
def numba_threads_kept() -> Iterable[None]:
    """Within the block, runs may set this process's numba threads; they are restored after."""
    import numba

    before = numba.get_num_threads()
    try:
        yield
    finally:
        numba.set_num_threads(before)


@contextmanager
def worker_environment(threads: int | None) -> Iterable[None]:
    """Within the block, processes started by this one size their thread pools to ``threads``
    (the variables of :data:`THREAD_ENV`; this process's own pools are already sized)."""
    if threads is None:
        yield
        return
    saved = {name: os.environ.get(name) for name in THREAD_ENV}
    os.environ.update({name: str(threads) for name in THREAD_ENV})
    try:
        yield
    finally:
        for name, value in saved.items():
            if value is None:
                os.environ.pop(name, None)
            else:
                os.environ[name] = value
