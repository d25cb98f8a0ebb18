"""peridyn's force kernels against LAMMPS PERI, side by side in one sitting.

Same grid for both: simple cubic, spacing 1 mm, 49^3 = 117,649 points, horizon 3.015
spacings, full-volume bonds (13,366,362 directed bonds), random displacement 1e-4 spacing.
Each round runs LAMMPS ``peri/pmb`` and ``peri/lps`` (``benchmarks/lammps/in.peri``, MPI
ranks ``--ranks``, one OpenMP thread each) and then ``peridyn bench`` (``run_benchmark``,
``--repeat`` interleaved rounds, numba's default threads), so that a load drifting on a
shared machine hits both alike. Rates are directed bond updates per second, best round:

- LAMMPS "pair": bonds x steps / the ``Pair`` time of LAMMPS's timing breakdown (the
  force computation alone, its neighbour exchange excluded; the rate that favours LAMMPS);
- LAMMPS "loop": bonds x steps / the whole loop time (adds the ghost exchange and NVE);
- peridyn: the ``peridyn bench`` rows (one force evaluation, best of its rounds).

Threads are bound on both sides, like for like: Open MPI's ``mpirun`` binds each LAMMPS rank to
a core (``--report-bindings`` shows it for 2 ranks), and the script sets ``OMP_PROC_BIND``
(``--thread-binding``, default ``spread``) before peridyn's first kernel, which binds numba's
threads to cores. On the 2-core VM of ``HISTORY.md`` ("Chunks of 32, slow processes, ...") binding
did not change peridyn's rate; about one process in ten, bound or not, ran at 0.8 of the others'
(``thread_binding.py``), so a round whose peridyn rates are low is worth repeating. LAMMPS is
started with the CPU set the script started with, not the core its bound main thread then holds.

Writes ``benchmarks/lammps_vs_peridyn.json`` (command, machine, date, load averages)::

    PYTHONPATH=src python benchmarks/lammps_vs_peridyn.py --rounds 3
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

from bench_kernels import machine

from peridyn.jobs.bench import run_benchmark

HERE = Path(__file__).resolve().parent
START_CPUS = os.sched_getaffinity(0)  # before numba binds this process's main thread
LAMMPS_DIR = HERE / "lammps"
SIDE = 49


def lammps_command(style: str, steps: int, ranks: int) -> list[str]:
    """The ``mpirun ... lmp`` command line of one LAMMPS run (Debian's lmp is built on Open MPI)."""
    mpirun = shutil.which("mpirun.openmpi") or shutil.which("mpirun")
    lmp = shutil.which("lmp")
    if mpirun is None or lmp is None:
        raise SystemExit("needs LAMMPS (`lmp`, Debian package lammps) and mpirun on PATH")
    return [mpirun, "-np", str(ranks), lmp, "-in", "in.peri", "-var", "style", style] + [
        "-var",
        "steps",
        str(steps),
        "-log",
        "none",
        "-nocite",
    ]


def parse_lammps(out: str) -> dict:
    """Bonds, steps, loop and Pair times (s) from LAMMPS's screen output (the timed run's)."""
    bonds = int(re.search(r"total # of bonds = (\d+)", out).group(1))
    loops = re.findall(r"Loop time of ([\d.eE+-]+) on \d+ procs for (\d+) steps", out)
    pairs = re.findall(r"^Pair\s*\|\s*\S+\s*\|\s*([\d.eE+-]+)", out, re.MULTILINE)
    loop, steps = float(loops[-1][0]), int(loops[-1][1])
    return {"bonds": bonds, "steps": steps, "loop_s": loop, "pair_s": float(pairs[-1])}


def run_lammps(style: str, steps: int, ranks: int) -> dict:
    """One LAMMPS run; rates in directed bond updates per second."""
    env = dict(os.environ, OMP_NUM_THREADS="1")
    if os.geteuid() == 0:  # Open MPI refuses root without these
        env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    cmd = lammps_command(style, steps, ranks)
    bound = os.sched_getaffinity(0)
    os.sched_setaffinity(0, START_CPUS)  # the child inherits the CPU set of this thread
    try:
        proc = subprocess.run(cmd, cwd=LAMMPS_DIR, env=env, capture_output=True, text=True, check=True)
    finally:
        os.sched_setaffinity(0, bound)
    r = parse_lammps(proc.stdout)
    work = r["bonds"] * r["steps"]
    return {**r, "pair_rate": work / r["pair_s"], "loop_rate": work / r["loop_s"]}


def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--steps", type=int, default=20, help="LAMMPS timed steps per run")
    parser.add_argument("--ranks", type=int, default=2, help="LAMMPS MPI ranks")
    parser.add_argument("--repeat", type=int, default=5, help="peridyn bench rounds per round")
    parser.add_argument("--output", "-o", type=Path, default=HERE / "lammps_vs_peridyn.json")
    parser.add_argument(
        "--thread-binding",
        default="spread",
        help="OMP_PROC_BIND for peridyn's numba threads unless already set; 'none' leaves them unbound",
    )
    args = parser.parse_args(argv)
    if args.thread_binding != "none":
        os.environ.setdefault("OMP_PROC_BIND", args.thread_binding)
    load_before = os.getloadavg()[0]
    lammps = {"pmb": [], "lps": []}
    peridyn = []
    for k in range(args.rounds):
        for style in lammps:
            lammps[style].append(run_lammps(style, args.steps, args.ranks))
            print(f"round {k + 1} LAMMPS {style}: {lammps[style][-1]['pair_rate'] / 1e6:.0f} M/s (pair)")
        peridyn.append(run_benchmark(points=SIDE**3, repeat=args.repeat))
        print(
            f"round {k + 1} peridyn: {[round(r['bond_updates_per_s'] / 1e6) for r in peridyn[-1]['results']]}"
        )
    best_l = {
        s: {m: max(r[m] for r in runs) for m in ("pair_rate", "loop_rate")} for s, runs in lammps.items()
    }
    rows = []
    for i, row in enumerate(peridyn[0]["results"]):
        rate = max(run["results"][i]["bond_updates_per_s"] for run in peridyn)
        ref = best_l.get(row["model"], best_l["pmb"] if row["model"] == "pmb-baseline" else None)
        rows.append(
            {
                "model": row["model"],
                "dtype": row["dtype"],
                "bonds": row["bonds"],
                "bond_updates_per_s": rate,
                "x_lammps_pair": rate / ref["pair_rate"],
                "x_lammps_loop": rate / ref["loop_rate"],
            }
        )
    print(
        f"\nLAMMPS ({args.ranks} ranks), best of {args.rounds}: "
        + ", ".join(
            f"{s} {v['pair_rate'] / 1e6:.0f} M/s pair, {v['loop_rate'] / 1e6:.0f} M/s loop"
            for s, v in best_l.items()
        )
    )
    print(f"{'peridyn row':<22} {'M bond/s':>9} {'x LAMMPS pair':>14} {'x LAMMPS loop':>14}")
    for r in rows:
        print(
            f"{r['model'] + ' ' + r['dtype']:<22} {r['bond_updates_per_s'] / 1e6:>9.0f} "
            f"{r['x_lammps_pair']:>14.2f} {r['x_lammps_loop']:>14.2f}"
        )
    record = {
        "command": "python " + " ".join(sys.argv),
        "lammps_command": " ".join(lammps_command("STYLE", args.steps, args.ranks)),
        "date_utc": datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "machine": machine(),
        "load_average_1min": {"before": round(load_before, 2), "after": round(os.getloadavg()[0], 2)},
        "lammps_runs": lammps,
        "lammps_best": best_l,
        "peridyn_threads": peridyn[0]["threads"],
        "peridyn_omp_proc_bind": peridyn[0]["omp_proc_bind"],
        "peridyn_runs": peridyn,  # every round's full ``peridyn bench`` result (roofs included)
        "rows": rows,
    }
    args.output.write_text(json.dumps(record, indent=2) + "\n")
    return record


if __name__ == "__main__":
    main()
