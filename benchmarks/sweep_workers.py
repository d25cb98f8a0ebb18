"""Runs per hour of a dask sweep with 1 and 2 workers of 1 thread each (issue 21 acceptance).

The runs are those of ``sweeps/demo.yaml`` (the steel bar of ``cases/bar_pulse.yaml`` at
2.5 mm, 1280 points, a few hundred steps), with ``--runs`` values of Young's modulus instead
of its 2 x 2 product, so that the sweep's fixed start (the local cluster, each worker's
imports and numba cache loads) can be told apart from its rate.

Rate: each run's record holds the moment it ended (the dataset's ``finished``, Unix time,
s). With W workers, sort the N end times t_1 <= ... <= t_N; the rate is
(N - W) / (t_N - t_W), the runs that ended after the first W per second between the W-th end
and the last: each worker's first run (its imports, the kernels' cache load) is left out, and
so are the cluster's start and the sweep's ends (dataset, shutdown). Runs per hour = 3600 x
rate. The sweep's whole wall time is printed too.

The two sides run interleaved, 1, 2, 1, 2, ... (``--repeats`` pairs), on a shared machine:
each line gives the load average (1 min) before that sweep.

    PYTHONPATH=src python benchmarks/sweep_workers.py [--runs 48] [--repeats 2] [--json]
"""

from __future__ import annotations

import argparse
import json
import os
import tempfile
from pathlib import Path

import numpy as np
import yaml

from peridyn.io.dataset import load_sweep
from peridyn.jobs.sweep import run_sweep

ROOT = Path(__file__).resolve().parents[1]
DEMO = ROOT / "sweeps" / "demo.yaml"


def sweep_file(folder: Path, runs: int) -> Path:
    """``sweeps/demo.yaml`` with ``runs`` moduli (150-200 GPa) at one density, no figures."""
    spec = yaml.safe_load(DEMO.read_text())
    spec["name"] = f"demo{runs}"
    spec["base"] = str((DEMO.parent / spec["base"]).resolve())
    spec["vary"] = {"product": {"material.E": [float(e) for e in np.linspace(150e9, 200e9, runs)]}}
    spec["outputs"]["figures"] = False
    path = folder / f"demo{runs}.yaml"
    path.write_text(yaml.safe_dump(spec))
    return path


def runs_per_hour(finished: np.ndarray, workers: int) -> float:
    """3600 (N - W) / (t_N - t_W) of the runs' end times ``finished`` (s), W = ``workers``."""
    t = np.sort(finished)
    if t.size <= workers:
        raise ValueError(f"{t.size} runs: need more than {workers} to measure a rate")
    return 3600.0 * (t.size - workers) / (t[-1] - t[workers - 1])


def measure(path: Path, out: Path, workers: int) -> dict:
    """One dask sweep of ``path`` with ``workers`` workers of 1 thread into ``out``."""
    load = os.getloadavg()[0]
    summary = run_sweep(path, out, executor="dask", workers=workers, threads=1, overwrite=True)
    ds = load_sweep(summary["dataset"])
    if summary["completed"] != summary["runs"]:
        raise RuntimeError(f"{summary['runs'] - summary['completed']} runs did not complete: {out}")
    return {
        "workers": workers,
        "load_1min": load,
        "runs": summary["runs"],
        "sweep_seconds": summary["seconds"],
        "run_seconds_mean": float(ds["seconds"].mean()),
        "runs_per_hour": runs_per_hour(ds["finished"].values, workers),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=48, help="runs per sweep (default 48)")
    parser.add_argument(
        "--repeats", type=int, default=2, help="pairs of sweeps, 1 then 2 workers (default 2)"
    )
    parser.add_argument("--json", action="store_true", help="print the results as one JSON object")
    args = parser.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        path = sweep_file(Path(tmp), args.runs)
        for _ in range(args.repeats):
            for workers in (1, 2):
                rows.append(measure(path, Path(tmp) / f"w{workers}", workers))
                if not args.json:
                    r = rows[-1]
                    print(
                        f"{workers} worker(s) x 1 thread: {r['runs_per_hour']:8.0f} runs/h "
                        f"(run {r['run_seconds_mean']:.3f} s, sweep {r['sweep_seconds']:.1f} s for "
                        f"{r['runs']} runs, load {r['load_1min']:.2f})",
                        flush=True,
                    )
    rate = {w: float(np.mean([r["runs_per_hour"] for r in rows if r["workers"] == w])) for w in (1, 2)}
    ratio = rate[2] / rate[1]
    if args.json:
        print(json.dumps({"rows": rows, "runs_per_hour": rate, "ratio": ratio}, indent=1))
    else:
        print(f"mean: 1 worker {rate[1]:.0f} runs/h, 2 workers {rate[2]:.0f} runs/h: {ratio:.2f}x")


if __name__ == "__main__":
    main()
