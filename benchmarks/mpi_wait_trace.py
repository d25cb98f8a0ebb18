"""Where the ranks of an MPI run wait: every collective and halo wait of each rank, timed.

Run a ``peridyn`` command through this script under ``mpiexec``; it wraps
``peridyn.parallel.comm.MPIComm._timed`` (every collective) and ``peridyn.parallel.halo.Halo.finish``
(the wait for the ghosts) to log each call's duration, and at exit each rank writes
``DIR/rank<R>.json`` (a list of [kind, name, start s, seconds]); ``report DIR`` then prints, per
rank and kind of call, the count, total, median and 90th percentile (``peridyn`` silences the
other ranks' output, so they are not printed at exit)::

    OMPI_ALLOW_RUN_AS_ROOT=1 NUMBA_NUM_THREADS=1 PYTHONPATH=src mpiexec -n 2 \\
        python benchmarks/mpi_wait_trace.py --trace-dir /tmp/waits \\
        run cases/lamb_plate.yaml -o /tmp/lamb2 --overwrite --no-progress --json \\
        --set output.plots=false
    python benchmarks/mpi_wait_trace.py report /tmp/waits
"""

from __future__ import annotations

import atexit
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

import peridyn.parallel.comm as comm_module
import peridyn.parallel.halo as halo_module

LOG: list = []


def _wrap() -> None:
    timed, finish = comm_module.MPIComm._timed, halo_module.Halo.finish

    def logged_timed(self, call, *args, **kwargs):
        start = time.perf_counter()
        try:
            return timed(self, call, *args, **kwargs)
        finally:
            LOG.append(("collective", getattr(call, "__name__", "?"), start, time.perf_counter() - start))

    def logged_finish(self):
        start = time.perf_counter()
        try:
            return finish(self)
        finally:
            LOG.append(("halo", "finish", start, time.perf_counter() - start))

    comm_module.MPIComm._timed = logged_timed
    halo_module.Halo.finish = logged_finish


def summary(log: list) -> dict:
    """{name: (calls, total s, median ms, 90th percentile ms)} of a rank's log."""
    by_name: dict = {}
    for _, name, _, seconds in log:
        by_name.setdefault(name, []).append(seconds)
    return {
        name: (len(v), float(np.sum(v)), 1e3 * float(np.median(v)), 1e3 * float(np.percentile(v, 90)))
        for name, v in sorted(by_name.items(), key=lambda item: -sum(item[1]))
    }


def report(directory: Path) -> None:
    """Print the summary of every rank's log in ``directory``."""
    for path in sorted(directory.glob("rank*.json")):
        for name, (calls, total, median, p90) in summary(json.loads(path.read_text())).items():
            print(
                f"{path.stem} {name:10s} calls {calls:5d} total {total:7.3f} s "
                f"median {median:7.3f} ms p90 {p90:7.3f} ms"
            )


def main(argv: list[str]) -> None:
    if len(argv) == 2 and argv[0] == "report":
        report(Path(argv[1]))
        return
    if len(argv) < 2 or argv[0] != "--trace-dir":
        raise SystemExit("usage: mpi_wait_trace.py --trace-dir DIR PERIDYN-ARGS... | report DIR")
    out, rank = Path(argv[1]), os.environ.get("PMI_RANK", "0")
    out.mkdir(parents=True, exist_ok=True)
    atexit.register(lambda: (out / f"rank{rank}.json").write_text(json.dumps(LOG)))
    _wrap()
    from peridyn.cli import main as peridyn_main

    sys.argv = ["peridyn", *argv[2:]]
    peridyn_main()


if __name__ == "__main__":
    main(sys.argv[1:])
