"""Force-kernel throughput benchmark; writes ``bench_kernels.json`` next to this script.

Same measurement as ``peridyn bench`` (``peridyn.jobs.bench``), plus the machine, the
command line and the UTC date in the JSON, for ``RESULTS.md`` and ``HISTORY.md``::

    python benchmarks/bench_kernels.py                      # 46^3 grid, no partial volumes
    python benchmarks/bench_kernels.py --partial-volumes -o benchmarks/bench_kernels_pv.json
    NUMBA_NUM_THREADS=1 python benchmarks/bench_kernels.py -o benchmarks/bench_kernels_1t.json
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import shlex
import subprocess
import sys
from pathlib import Path

from peridyn.jobs.bench import DEFAULT_POINTS, format_table, run_benchmark

HERE = Path(__file__).resolve().parent


def machine() -> dict:
    """CPU model and core count (from ``lscpu`` where available)."""
    info = {"cpu": platform.processor() or platform.machine(), "logical_cpus": os.cpu_count()}
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True, check=True).stdout
    except (OSError, subprocess.CalledProcessError):
        return info
    fields = dict(line.split(":", 1) for line in out.splitlines() if ":" in line)
    fields = {k.strip(): v.strip() for k, v in fields.items()}
    info["cpu"] = fields.get("Model name", info["cpu"])
    for key, name in (
        ("Core(s) per socket", "cores_per_socket"),
        ("Socket(s)", "sockets"),
        ("Thread(s) per core", "threads_per_core"),
        ("L3 cache", "l3_cache"),
    ):
        if key in fields:
            info[name] = fields[key]
    return info


def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=DEFAULT_POINTS)
    parser.add_argument("--repeat", type=int, default=10)
    parser.add_argument("--partial-volumes", action="store_true")
    parser.add_argument("--output", "-o", type=Path, default=HERE / "bench_kernels.json")
    args = parser.parse_args(argv)
    load_before = os.getloadavg()[0]
    result = run_benchmark(
        points=args.points,
        repeat=args.repeat,
        partial_volumes=args.partial_volumes,
        log=lambda msg: print(msg, file=sys.stderr),
    )
    print(format_table(result))
    record = {
        "command": " ".join(
            [
                *(f"{k}={os.environ[k]}" for k in ("NUMBA_NUM_THREADS",) if k in os.environ),
                "python",
                *(shlex.quote(a) for a in sys.argv),
            ]
        ),
        "date_utc": datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "machine": machine(),
        "numba_num_threads_env": os.environ.get("NUMBA_NUM_THREADS"),
        "partial_volumes": args.partial_volumes,
        # 1-minute load average: the timings are only as clean as the machine was idle
        "load_average_1min": {"before": round(load_before, 2), "after": round(os.getloadavg()[0], 2)},
        **result,
    }
    args.output.write_text(json.dumps(record, indent=2) + "\n")
    print(f"wrote {args.output}", file=sys.stderr)
    return record


if __name__ == "__main__":
    main()
