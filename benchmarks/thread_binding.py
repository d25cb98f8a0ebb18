"""Does binding numba's threads steady the kernels' rate? One fresh process after another.

Each process builds the ``peridyn bench`` grid (49^3 points, horizon 3.015 spacings), calls
the PMB float64 force (``model.force``) once to warm up, then ``--calls`` times, and prints
its best rate in directed bond updates per second. The processes alternate between the
environment as it is and ``OMP_PROC_BIND=spread`` (numba's OpenMP threading layer binds its
threads to cores). A process whose threads the operating system keeps badly placed runs slow
for its whole life, so it takes many processes, not many calls, to see it::

    PYTHONPATH=src python benchmarks/thread_binding.py --processes 10

Results in ``benchmarks/HISTORY.md`` ("Chunks of 32, slow processes, ...", 2026-11-28); the user
guide's "Threads" says when to bind.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time

import numpy as np

SIDE = 49


def one_process(calls: int) -> float:
    """Best PMB float64 force rate (bond updates/s) of ``calls`` calls in this process."""
    from peridyn.jobs.bench import SPACING, benchmark_grid
    from peridyn.physics.materials import make_model

    body, bonds = benchmark_grid(SIDE)
    model = make_model("pmb", body, bonds, E=200e9, nu=0.25, density=7850.0)
    u = 1e-4 * SPACING * np.random.default_rng(0).standard_normal(body.points.shape)
    out = np.empty_like(u)
    model.force(u, out)
    best = np.inf
    for _ in range(calls):
        t0 = time.perf_counter()
        model.force(u, out)
        best = min(best, time.perf_counter() - t0)
    return bonds.n_bonds / best


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--processes", type=int, default=10, help="processes of each kind")
    parser.add_argument("--calls", type=int, default=15, help="timed force calls per process")
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        print(one_process(args.calls))
        return
    unbound = {k: v for k, v in os.environ.items() if k != "OMP_PROC_BIND"}
    envs = {"unbound": unbound, "OMP_PROC_BIND=spread": dict(unbound, OMP_PROC_BIND="spread")}
    rates: dict[str, list[float]] = {kind: [] for kind in envs}
    for k in range(args.processes):
        for kind, env in envs.items():
            cmd = [sys.executable, __file__, "--child", "--calls", str(args.calls)]
            done = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True)
            rates[kind].append(float(done.stdout.split()[-1]))
            print(f"process {k + 1} {kind}: {rates[kind][-1] / 1e6:.0f} M/s", flush=True)
    for kind, values in rates.items():
        print(f"{kind}: M bond/s of each process, sorted: {sorted(round(v / 1e6) for v in values)}")


if __name__ == "__main__":
    main()
