"""What one core keeps of its speed when the other works too (issue 20, the 2-rank ratio's roof).

Two MPI ranks of one thread each can be at most ``2 e`` times faster than one, where ``e`` is
the fraction of its one-core speed a core keeps while the other core runs the same work (shared
memory bandwidth, shared L3 cache, and on a virtual machine whatever the host shares). This
measures ``e`` with no MPI and no synchronisation at all: a case's model is built in each of
one or two independent processes (``NUMBA_NUM_THREADS=1``), they start together, and each times
``--calls`` calls of the model's force (the time loop's dominant part). Solo, pair and solo
again, ``--rounds`` times; ``e`` is each pair process's calls per second over the solo ones'.

    PYTHONPATH=src python benchmarks/core_sharing.py --case cases/lamb_plate.yaml --rounds 3
"""

from __future__ import annotations

import argparse
import json
import multiprocessing as mp
import os
import time
from pathlib import Path


def _worker(case: str, calls: int, ready, start, results) -> None:
    """Build the case's model, say ready, wait for the start, time ``calls`` force calls."""
    os.environ["NUMBA_NUM_THREADS"] = "1"
    import numpy as np

    from peridyn.io.case import load_case
    from peridyn.setup.build import build

    case_path = Path(case)
    setup = build(load_case(case_path), case_path.parent)
    model = setup.model
    u = np.random.default_rng(0).normal(scale=1e-9, size=model.x.shape)
    out = np.empty_like(model.x)
    model.force(u, out)  # compiled or loaded from numba's cache before the clock starts
    ready.release()
    start.wait()
    begin = time.perf_counter()
    for _ in range(calls):
        model.force(u, out)
    results.put(calls / (time.perf_counter() - begin))


def concurrent_rates(case: str, calls: int, copies: int) -> list[float]:
    """Force calls per second of each of ``copies`` processes started together."""
    ctx = mp.get_context("spawn")
    ready, start, results = ctx.Semaphore(0), ctx.Event(), ctx.Queue()
    procs = [ctx.Process(target=_worker, args=(case, calls, ready, start, results)) for _ in range(copies)]
    for p in procs:
        p.start()
    for _ in procs:
        ready.acquire()
    start.set()
    rates = [results.get() for _ in procs]
    for p in procs:
        p.join()
    return rates


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--case", default="cases/lamb_plate.yaml")
    parser.add_argument("--calls", type=int, default=150, help="force calls timed per process")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("-o", "--output", type=Path, help="write the rates as JSON here")
    args = parser.parse_args(argv)
    rows = []
    for r in range(args.rounds):
        for copies in (1, 2, 1):
            load = os.getloadavg()[0]
            rates = concurrent_rates(args.case, args.calls, copies)
            rows.append({"round": r, "copies": copies, "calls_per_s": rates, "load_before": load})
            shown = ", ".join(f"{x:.2f}" for x in rates)
            print(f"round {r}, {copies} process(es): {shown} calls/s (load {load:.2f})")
    solo = [x for row in rows if row["copies"] == 1 for x in row["calls_per_s"]]
    pair = [x for row in rows if row["copies"] == 2 for x in row["calls_per_s"]]
    kept = sorted(p / max(solo) for p in pair)
    median_kept = kept[len(kept) // 2]
    print(
        f"each core keeps {median_kept:.3f} of the best solo rate (median of {len(kept)}; "
        f"range {kept[0]:.3f}-{kept[-1]:.3f}): two one-thread ranks are at most "
        f"{2 * median_kept:.2f}x one"
    )
    if args.output:
        summary = {"case": args.case, "calls": args.calls, "rows": rows, "kept_median": median_kept}
        args.output.write_text(json.dumps(summary, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
