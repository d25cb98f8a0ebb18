"""Strong scaling of an explicit run over MPI ranks and numba threads (issue 20 item 6).

Runs ``peridyn run CASE --json`` one configuration after the other (ranks x numba threads:
1 x 1, 2 x 1, 3 x 1 and 1 x 2 by default; ``mpiexec -n R`` for R > 1) and records, per run,
the wall time of the whole command, the summary's ``seconds`` (total) and ``step_seconds``
(the time loop), the bond rate of the loop (directed bonds x steps / step_seconds), and under
MPI each rank's points, ghosts, halo messages and bytes per step, seconds in the halo exchange
(and waiting in it), in collectives, and peak memory; with the 1-minute load average before
and after each run (a shared machine: say what the load was).

    PYTHONPATH=src python benchmarks/bench_mpi.py                    # the seed Lamb case
    PYTHONPATH=src python benchmarks/bench_mpi.py --quick            # bar_pulse, a short check
    PYTHONPATH=src python benchmarks/bench_mpi.py --repeat 2 -o benchmarks/bench_mpi.json

Beside the runs it records what the scaling model (``docs/figures/mpi_scaling.py``) reads: the
serial step's parts on one thread (``peridyn bench --case CASE --steps 100``: force, observers,
rest, ms per step) and the point-to-point latency and bandwidth of two ranks
(``benchmarks/mpi_pingpong.py``), and the number of probe points a series record gathers (the
recorder's ``Probes``). A short serial run first fills numba's cache, so that no run
compiles. Plots are off
(``output.plots=false``): figures are drawn by rank 0 alone after the loop and are no part of
the scaling; ``--set`` passes more overrides to every run.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CASES = {
    "lamb": (ROOT / "cases" / "lamb_plate.yaml", []),
    "quick": (ROOT / "cases" / "bar_pulse.yaml", ["solver.time=10e-6"]),
}
#: (ranks, numba threads per rank)
CONFIGURATIONS = ((1, 1), (2, 1), (3, 1), (1, 2))


def run_once(case: Path, sets: list[str], ranks: int, threads: int, out: Path) -> dict:
    """One ``peridyn run`` of ``case`` on ``ranks`` x ``threads``: its measured numbers."""
    command = [sys.executable, "-m", "peridyn", "run", str(case), "-o", str(out), "--no-progress", "--json"]
    for s in ["output.plots=false", *sets]:
        command += ["--set", s]
    if ranks > 1:
        command = ["mpiexec", "-n", str(ranks), *command]
    env = _env(threads)
    load_before = os.getloadavg()[0]
    start = time.perf_counter()
    done = subprocess.run(command, capture_output=True, text=True, env=env, check=False)
    wall = time.perf_counter() - start
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(command)} failed:\n{done.stderr[-3000:]}")
    summary = json.loads(done.stdout)
    row = {
        "ranks": ranks,
        "threads": threads,
        "points": summary["points"],
        "bonds": summary["bonds"],
        "steps": summary["steps"],
        "wall_seconds": wall,
        "seconds": summary["seconds"],
        "step_seconds": summary["step_seconds"],
        "ms_per_step": 1e3 * summary["step_seconds"] / summary["steps"],
        "bond_rate_per_s": summary["bonds"] * summary["steps"] / summary["step_seconds"],
        "load_before": load_before,
        "load_after": os.getloadavg()[0],
    }
    if "mpi" in summary:
        per_rank = summary["mpi"]["per_rank"]
        row["per_rank"] = per_rank
        row["halo_share"] = max(r["halo_share"] for r in per_rank)
        row["halo_bytes_per_step"] = [r["bytes_per_step"] for r in per_rank]
        row["peak_memory_bytes"] = [r["peak_memory_bytes"] for r in per_rank]
    else:
        row["peak_memory_bytes"] = [summary["peak_memory_bytes"]]
    return row


def _env(threads: int) -> dict:
    return dict(
        os.environ,
        PYTHONPATH=os.pathsep.join(filter(None, [str(ROOT / "src"), os.environ.get("PYTHONPATH")])),
        NUMBA_NUM_THREADS=str(threads),
        OMP_NUM_THREADS="1",
        OPENBLAS_NUM_THREADS="1",
    )


def serial_parts(case: Path, sets: list[str], steps: int = 100) -> dict:
    """``peridyn bench --case`` on one thread: the step's parts, s per step, and the load."""
    command = [sys.executable, "-m", "peridyn", "bench", "--case", str(case), "--steps", str(steps)]
    command += ["--repeat", "3", "--json"]
    for s in ["output.plots=false", *sets]:
        command += ["--set", s]
    done = subprocess.run(command, capture_output=True, text=True, env=_env(1), check=True)
    bench = json.loads(done.stdout)
    per_step = {name: seconds / bench["steps"] for name, seconds in bench["parts"].items()}
    return {"steps": bench["steps"], "seconds_per_step": per_step, "load_average": bench["load_average"]}


def probe_points(case: Path, sets: list[str]) -> int:
    """The points whose displacement a series record gathers on rank 0 under MPI (the recorder's
    ``Probes``: sensors, lines, planes and PZT sensor points, with repeats), for the model's
    gather term."""
    from peridyn.io.case import load_case
    from peridyn.io.recorder import Probes
    from peridyn.setup.build import build_body
    from peridyn.setup.recording import recorder_spec

    loaded = load_case(case, sets)
    body = build_body(loaded, case.parent)
    return len(Probes.of(body, recorder_spec(loaded, body, 1.0)).u_points)


def pingpong() -> dict:
    """Latency (s) and bandwidth (bytes/s) of two ranks (``benchmarks/mpi_pingpong.py``)."""
    command = ["mpiexec", "-n", "2", sys.executable, str(ROOT / "benchmarks" / "mpi_pingpong.py")]
    done = subprocess.run(command, capture_output=True, text=True, env=_env(1), check=True)
    return {**json.loads(done.stdout), "load_before": os.getloadavg()[0]}


def table(rows: list[dict]) -> str:
    """The runs as a Markdown table."""
    lines = [
        "| ranks x threads | steps | wall, s | seconds | step_seconds | ms/step | M bond/s | halo share "
        "| halo KiB/step/rank | peak MiB/rank | load |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        halo = f"{r['halo_share']:.3f}" if "halo_share" in r else "-"
        kib = "/".join(f"{b / 1024:.0f}" for b in r.get("halo_bytes_per_step", [])) or "-"
        mem = "/".join(f"{b / 2**20:.0f}" for b in r["peak_memory_bytes"])
        lines.append(
            f"| {r['ranks']} x {r['threads']} | {r['steps']} | {r['wall_seconds']:.1f} | {r['seconds']:.1f} "
            f"| {r['step_seconds']:.1f} | {r['ms_per_step']:.1f} | {r['bond_rate_per_s'] / 1e6:.0f} | {halo} "
            f"| {kib} | {mem} | {r['load_before']:.1f}-{r['load_after']:.1f} |"
        )
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="bar_pulse (20 000 points, 153 steps)")
    parser.add_argument("--repeat", type=int, default=1, help="rounds over the configurations")
    parser.add_argument("--set", action="append", default=[], help="an override for every run")
    parser.add_argument(
        "--configurations",
        default=",".join(f"{r}x{t}" for r, t in CONFIGURATIONS),
        help="ranks x threads, comma-separated (default %(default)s)",
    )
    parser.add_argument("--no-model-inputs", action="store_true", help="skip the parts and the ping-pong")
    parser.add_argument("-o", "--output", type=Path, help="write the runs as JSON here")
    args = parser.parse_args(argv)
    case, sets = CASES["quick" if args.quick else "lamb"]
    sets = [*sets, *args.set]
    configurations = [tuple(int(v) for v in c.split("x")) for c in args.configurations.split(",")]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        run_once(case, [*sets, "solver.time=2e-7"], 1, 1, Path(tmp) / "warm-up")
        for round_ in range(args.repeat):
            for ranks, threads in configurations:
                row = run_once(case, sets, ranks, threads, Path(tmp) / f"{ranks}x{threads}-{round_}")
                row["round"] = round_
                rows.append(row)
                print(table([row]).splitlines()[-1], file=sys.stderr, flush=True)
    print(table(rows))
    record = {"case": str(case.relative_to(ROOT)), "sets": sets, "cpus": os.cpu_count(), "runs": rows}
    record["probe_points"] = probe_points(case, sets)
    if not args.no_model_inputs:
        record["serial_parts"] = serial_parts(case, sets)
        record["pingpong"] = pingpong()
        print(json.dumps({k: record[k] for k in ("serial_parts", "pingpong")}, indent=1))
    if args.output is not None:
        args.output.write_text(json.dumps(record, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
