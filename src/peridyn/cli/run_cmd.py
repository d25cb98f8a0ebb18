"""``peridyn run CASE.yaml``: run a case with a progress bar and print its summary."""

from __future__ import annotations

import shlex
import sys
from pathlib import Path

from tqdm import tqdm

from peridyn.cli import add_json_flag
from peridyn.io.case import load_case
from peridyn.io.provenance import provenance


def add_case_arguments(parser) -> None:
    """The case path and the repeatable ``--set key.path=value`` override."""
    parser.add_argument("case", help="YAML case file")
    parser.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="override a case entry, e.g. discretization.spacing=0.001 (repeatable)",
    )


def register(sub) -> None:
    """Add the ``run`` subcommand."""
    p = sub.add_parser("run", help="run a case file", description=__doc__)
    add_case_arguments(p)
    p.add_argument(
        "--output",
        "-o",
        help="output folder (default: the case's output.directory or peridyn-out/<case name>)",
    )
    p.add_argument(
        "--checkpoint-every", type=int, default=None, metavar="N", help="write a checkpoint every N steps"
    )
    p.add_argument("--restart", action="store_true", help="continue from the output folder's checkpoint.h5")
    add_overwrite_flag(p)
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    add_json_flag(p)
    p.set_defaults(func=run)


def add_overwrite_flag(parser) -> None:
    """The ``--overwrite`` flag: replace an earlier run's results in the output folder."""
    parser.add_argument(
        "--overwrite",
        action="store_true",
        help="replace the results of an earlier run in the output folder (refused without it)",
    )


def command_line() -> str:
    """This process's ``peridyn ...`` command line (without --overwrite), for resume hints."""
    return shlex.join(["peridyn", *(a for a in sys.argv[1:] if a != "--overwrite")])


def run(args) -> dict:
    """Run the case; print a readable summary unless --json."""
    from peridyn.jobs.run import run_case

    case = load_case(args.case, args.overrides)
    info = provenance()
    print(
        f"peridyn {info['peridyn_version']} (commit {info['git_commit'][:12]}): case "
        f"{case.name!r} from {args.case}",
        file=sys.stderr,
    )
    progress = None
    if not args.no_progress:

        def progress(total):
            return tqdm(total=total, unit="step", file=sys.stderr, dynamic_ncols=True, desc=case.name)

    summary = run_case(
        case,
        args.output,
        case_path=args.case,
        checkpoint_every=args.checkpoint_every,
        restart=args.restart,
        progress=progress,
        base_dir=Path(args.case).parent,
        overwrite=args.overwrite,
        command=command_line(),
    )
    if not args.json:
        print_summary(summary)
    return summary


def print_summary(summary: dict) -> None:
    """Readable end-of-run report."""
    print(
        f"points {summary['points']}, bonds {summary['bonds']}, steps {summary['steps']}, "
        f"{summary['seconds']:.2f} s"
    )
    for key in ("dt_s", "stable_dt_s", "broken_bonds", "max_damage", "strain_energy_j"):
        if key in summary:
            print(f"  {key}: {summary[key]:.6g}")
    for path in summary.get("plots", []):
        print(f"  plot: {path}")
    print(f"results written to {summary['output_dir']}")
