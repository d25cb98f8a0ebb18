"""peridyn bench: force-kernel throughput (directed bond updates per second).

Times one explicit-step force evaluation of the baseline PMB loop and of the PMB and
LPS models (float64 and float32, through model.force) on a cube of about 100k
points (1 mm spacing, horizon 3.015 spacings, no partial volumes unless
--partial-volumes), next to the machine's triad memory bandwidth. Best of
--repeat interleaved rounds after a warm-up. See peridyn.jobs.bench for what
is counted.
"""

from __future__ import annotations

import sys

from peridyn.cli.options import add_common_flags
from peridyn.jobs.bench import DEFAULT_POINTS, format_table, run_benchmark


def register(sub) -> None:
    """Add the ``bench`` subcommand."""
    p = sub.add_parser("bench", help="measure force-kernel throughput", description=__doc__)
    p.add_argument(
        "--points",
        type=int,
        default=DEFAULT_POINTS,
        metavar="N",
        help=f"approximate number of grid points, rounded to a cube (default {DEFAULT_POINTS} = 46^3)",
    )
    p.add_argument(
        "--repeat",
        type=int,
        default=10,
        metavar="N",
        help="timed rounds after the warm-up; each row keeps its best (default 10)",
    )
    p.add_argument(
        "--partial-volumes",
        action="store_true",
        help="build the bonds with partial volumes (default: full-volume bonds)",
    )
    add_common_flags(p)
    p.set_defaults(func=run)


def run(args) -> dict:
    """Run the benchmark; print the table unless --json (progress goes to stderr)."""
    result = run_benchmark(
        points=args.points,
        repeat=args.repeat,
        partial_volumes=args.partial_volumes,
        log=lambda msg: print(f"peridyn bench: {msg}", file=sys.stderr),
    )
    if not args.json:
        print(format_table(result))
    return result
