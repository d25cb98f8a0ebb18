"""peridyn monitor CASE.yaml: a fatigue life with guided-wave interrogations by a PZT network at
the points of a schedule, damage indices, images and one dataset (docs/monitoring.md). A second
run into the same folder resumes it: finished fatigue and interrogation runs are kept."""

from __future__ import annotations

from peridyn.cli.options import (
    add_case_arguments,
    add_common_flags,
    add_executor_flags,
    add_output_flag,
    add_rerun_flag,
)


def register(sub) -> None:
    """Add the ``monitor`` subcommand."""
    p = sub.add_parser(
        "monitor", help="fatigue life monitored by guided-wave interrogations", description=__doc__
    )
    add_case_arguments(p)
    add_executor_flags(p, "interrogation runs")
    add_output_flag(p, "output folder (default: the case's output.directory or peridyn-out/<case name>)")
    add_rerun_flag(p, "fatigue and interrogation runs")
    add_common_flags(p)
    p.set_defaults(func=run)


def run(args) -> dict:
    """Run the monitoring case; print its figures of merit unless --json."""
    from peridyn.jobs.monitor import run_monitor
    from peridyn.parallel.comm import world

    summary = run_monitor(
        args.case,
        args.output,
        overrides=args.overrides,
        executor=args.executor,
        workers=args.workers,
        scheduler=args.scheduler,
        threads=args.threads,
        overwrite=args.overwrite,
        comm=world(),
    )
    if not args.json:
        m = summary["monitoring"]
        print(
            f"{m['interrogations']} interrogations, final crack {1e3 * m['final_crack_length_m']:.2f} mm, "
            f"crossed paths {m['crossed_paths']}: Spearman min {m['crossed_spearman_min']}, above the "
            f"uncrossed {m['crossed_above_uncrossed']}, image peak error max "
            f"{m['image_peak_error_max_m']} m, "
            f"{summary['seconds']:.1f} s"
        )
        print(f"results written to {summary['output_dir']}")
    return summary
