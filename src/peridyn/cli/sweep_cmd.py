"""peridyn sweep SWEEP.yaml: run a parameter sweep (docs/sweeps.md) and collect its dataset."""

from __future__ import annotations

from peridyn.cli.logs import progress_bar
from peridyn.cli.options import (
    add_common_flags,
    add_executor_flags,
    add_output_flag,
    add_progress_flags,
    add_rerun_flag,
    add_set_flag,
    positive_int,
)
from peridyn.cli.run_cmd import command_line
from peridyn.errors import PeridynError


def register(sub) -> None:
    """Add the ``sweep`` subcommand."""
    p = sub.add_parser("sweep", help="run a parameter sweep and collect its dataset", description=__doc__)
    p.add_argument("sweep", help="YAML sweep file")
    add_executor_flags(p)
    add_set_flag(p, "override a case entry of every run, e.g. discretization.spacing=0.002 (repeatable)")
    p.add_argument("--first", type=positive_int, default=None, metavar="N", help="run only the first N runs")
    add_output_flag(p, "output folder (default: peridyn-out/<sweep name>); a second run resumes it")
    add_rerun_flag(p)
    add_progress_flags(p)
    add_common_flags(p)
    p.set_defaults(func=run)


def run(args) -> dict:
    """Run the sweep; print a one-paragraph report unless --json."""
    from peridyn.jobs.sweep import run_sweep

    bar = progress_bar(args.progress, "sweep")
    summary = run_sweep(
        args.sweep,
        args.output,
        executor=args.executor,
        workers=args.workers,
        threads=args.threads,
        scheduler=args.scheduler,
        overwrite=args.overwrite,
        progress=None if bar is None else _runs(bar),
        command=command_line(),
        overrides=args.overrides,
        first=args.first,
    )
    if not args.json:
        print(
            f"sweep {summary['sweep']}: {summary['runs']} runs, {summary['completed']} complete, "
            f"{summary['failed']} failed, {summary['skipped']} skipped (already complete), "
            f"{summary['seconds']:.1f} s"
        )
        print(f"dataset: {summary['dataset']}")
        for path in summary["figures"]:
            print(f"  plot: {path}")
    if summary["failed_runs"]:
        raise RunsFailed(summary)
    return summary


class RunsFailed(PeridynError):
    """A sweep that finished with failed runs: exit status 1, one line listing each failed run
    and why; with ``--json`` the sweep's summary is still the JSON object on stdout (``summary``,
    with the ``error``)."""

    def __init__(self, summary: dict):
        self.summary = summary
        runs = summary["failed_runs"]
        listed = "; ".join(f"{r['run_id']}: {r['status']}" for r in runs)
        super().__init__(f"{len(runs)} of {summary['runs']} runs failed ({listed})")


def _runs(factory):
    """The progress-bar factory counting runs, not steps."""

    def make(total: int):
        bar = factory(total)
        bar.unit = "run"
        return bar

    return make
