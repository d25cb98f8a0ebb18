"""peridyn modal CASE.yaml: free-vibration modes of a case, classified by type."""

from __future__ import annotations

from pathlib import Path

from peridyn.cli.options import (
    add_case_arguments,
    add_common_flags,
    add_max_memory,
    add_output_flag,
    add_overwrite_flag,
)
from peridyn.io.case import load_case


def register(sub) -> None:
    """Add the ``modal`` subcommand."""
    p = sub.add_parser("modal", help="modal analysis of a case", description=__doc__)
    add_case_arguments(p)
    p.add_argument("--modes", type=int, default=None, help="number of modes (rigid included)")
    add_output_flag(p, "output folder (default: the case's output.directory or peridyn-out/<case name>)")
    add_overwrite_flag(p)
    p.add_argument(
        "--compare",
        metavar="RUN_DIR",
        help="a modal run of the same grid (e.g. the healthy body): frequency-shift "
        "table of this run's modes against it, matched by MAC",
    )
    add_common_flags(p)
    add_max_memory(p)
    p.set_defaults(func=run)


def run(args) -> dict:
    """Solve and print the frequency table unless --json."""
    from peridyn.jobs.dispatch import job_function, run_job
    from peridyn.parallel.comm import world

    job_function("modal")  # its modules loaded before the case is read, as before the dispatch
    overrides = [*args.overrides, "solver.type=modal"]
    if args.modes is not None:
        overrides.append(f"solver.modes={args.modes}")
    case = load_case(args.case, overrides)
    comm = world()  # under mpiexec -n N: the distributed LOBPCG, rank 0 writes
    summary = run_job(
        "modal",
        case,
        args.output,
        case_path=args.case,
        base_dir=Path(args.case).parent,
        overwrite=args.overwrite,
        comm=comm,
        max_memory=args.max_memory,
    )
    if args.compare and comm.rank == 0:
        from peridyn.jobs.modal import compare_with_run

        summary["comparison"] = compare_with_run(Path(summary["output_dir"]), Path(args.compare))
    if not args.json:
        print_modes(summary)
    return summary


def print_modes(summary: dict) -> None:
    """Readable report of a modal run: its frequency table (and the comparison, if any)."""
    print(f"{summary['points']} points, {summary['rigid_modes']} rigid modes, {summary['seconds']:.1f} s")
    for m in summary["modes"]:
        print(f"  {m['index']:3d}  {m['frequency_hz']:12.2f} Hz  {m['label']}")
    for row in summary.get("comparison", []):
        print(
            f"  {row['reference_label']:>28s} {row['reference_frequency_hz']:10.2f} Hz -> "
            f"{row['frequency_hz']:10.2f} Hz ({100 * row['frequency_change']:+.2f} %, "
            f"MAC {row['mac']:.2f}, now {row['label']})"
        )
    print(f"results written to {summary['output_dir']}")
