"""peridyn bench: force-kernel throughput (directed bond updates per second).

Without --case: times one explicit-step force evaluation of the baseline PMB loop and
of the PMB and LPS models (float64 and float32, through model.force) on a cube of
about 100k points (1 mm spacing, horizon 3.015 spacings, no partial volumes unless
--partial-volumes), next to the machine's triad memory bandwidth and square-root and
division throughput: each row's share of the memory roof and of the compute roof. Best
of --repeat interleaved rounds after a warm-up. See peridyn.jobs.bench for what is counted.

With --case CASE.yaml (an explicit case, --set overrides applied): builds the case
as `peridyn run` does and times --steps whole steps (force, breaking test, contact,
boundary conditions, actuators, damping, integration, and the run's recorder and
snapshots, written to a temporary folder deleted afterwards) against the force
evaluation alone on the same bonds (best of --repeat): the whole-step and kernel
rates, the step's share of the kernel rate and where the step time goes. See
peridyn.jobs.bench_case.

With --backend gpu: the same on the GPU backend (a CUDA device through NVIDIA Warp, or
Warp's CPU device with PERIDYN_GPU_ON_CPU=1): the PMB and LPS rows in float64 and float32
against the device's memory roof from a measured copy (peridyn.jobs.bench_gpu), or with
--case the case's whole steps on the device against its device force kernel.
"""

from __future__ import annotations

import sys
from pathlib import Path

from peridyn.cli.options import add_common_flags, add_set_flag, positive_int
from peridyn.errors import InputError
from peridyn.jobs.bench import DEFAULT_POINTS, format_table, run_benchmark


def register(sub) -> None:
    """Add the ``bench`` subcommand."""
    p = sub.add_parser(
        "bench", help="measure force-kernel (or a case's whole-step) throughput", description=__doc__
    )
    p.add_argument(
        "--points",
        type=int,
        default=None,
        metavar="N",
        help=f"approximate number of grid points, rounded to a cube (default {DEFAULT_POINTS} = 46^3)",
    )
    p.add_argument(
        "--repeat",
        type=int,
        default=10,
        metavar="N",
        help="timed rounds (force evaluations with --case) after the warm-up; the best counts (default 10)",
    )
    p.add_argument(
        "--partial-volumes",
        action="store_true",
        help="build the bonds with partial volumes (default: full-volume bonds)",
    )
    p.add_argument(
        "--storage",
        choices=("bonds", "lattice"),
        default="bonds",
        help="lattice: also time the models on lattice storage, in the same rounds (default: bonds)",
    )
    p.add_argument(
        "--case",
        metavar="CASE.yaml",
        help="time an explicit case's whole steps against its force kernel instead of the grid",
    )
    add_set_flag(p, "with --case: override a case entry, e.g. discretization.spacing=0.001 (repeatable)")
    p.add_argument(
        "--steps",
        type=positive_int,
        default=None,
        metavar="N",
        help="with --case: timed steps (default: the case's step count, at most 200)",
    )
    p.add_argument(
        "--backend",
        choices=("cpu", "gpu"),
        default="cpu",
        help="the numba CPU kernels (default) or the GPU backend (docs/gpu.md)",
    )
    add_common_flags(p)
    p.set_defaults(func=run)


def run(args) -> dict:
    """Run the benchmark; print the table unless --json (progress goes to stderr)."""

    def log(msg):
        print(f"peridyn bench: {msg}", file=sys.stderr)

    if args.case is not None:
        return _run_case(args, log)
    if args.steps is not None or args.overrides:
        raise InputError("--steps and --set apply to a case: give --case CASE.yaml")
    if args.backend == "gpu":
        from peridyn.jobs.bench_gpu import format_gpu_table, run_gpu_benchmark

        points = args.points if args.points is not None else DEFAULT_POINTS
        result = run_gpu_benchmark(points, args.repeat, args.partial_volumes, log=log)
        if not args.json:
            print(format_gpu_table(result))
        return result
    result = run_benchmark(
        points=args.points if args.points is not None else DEFAULT_POINTS,
        repeat=args.repeat,
        partial_volumes=args.partial_volumes,
        log=log,
        lattice=args.storage == "lattice",
    )
    if not args.json:
        print(format_table(result))
    return result


def _run_case(args, log) -> dict:
    """``peridyn bench --case``: whole steps of the case against its force kernel."""
    from peridyn.io.case import load_case
    from peridyn.jobs.bench_case import format_case_result, run_case_benchmark

    if args.points is not None or args.partial_volumes:
        raise InputError("--points and --partial-volumes set the benchmark grid, not a --case run")
    if args.storage != "bonds":
        raise InputError(
            "--storage sets the benchmark grid's rows; a case takes --set discretization.storage=lattice"
        )
    backend = [f"solver.backend={args.backend}"] if args.backend == "gpu" else []
    case = load_case(args.case, [*args.overrides, *backend])
    result = run_case_benchmark(
        case, Path(args.case).parent, args.case, steps=args.steps, repeat=args.repeat, log=log
    )
    if not args.json:
        print(format_case_result(result))
    return result
