"""peridyn run CASE.yaml: run a case (a progress bar on a terminal) and print its summary.
A Peridigm input deck (DECK.xml or DECK.yaml) runs as its translation (peridyn convert;
docs/peridigm.md)."""

from __future__ import annotations

import logging
import shlex
import sys
from pathlib import Path

from peridyn.cli.logs import progress_bar
from peridyn.cli.modal_cmd import print_modes
from peridyn.cli.options import (
    add_case_arguments,
    add_common_flags,
    add_max_memory,
    add_output_flag,
    add_overwrite_flag,
    add_progress_flags,
    positive_int,
)
from peridyn.io.peridigm_case import load_case_or_deck
from peridyn.io.provenance import provenance
from peridyn.parallel.comm import world

logger = logging.getLogger(__name__)


def register(sub) -> None:
    """Add the ``run`` subcommand."""
    p = sub.add_parser("run", help="run a case file or a Peridigm deck", description=__doc__)
    add_case_arguments(p)
    add_output_flag(p, "output folder (default: the case's output.directory or peridyn-out/<case name>)")
    p.add_argument(
        "--checkpoint-every",
        type=positive_int,
        default=None,
        metavar="N",
        help="write a checkpoint every N steps",
    )
    p.add_argument("--restart", action="store_true", help="continue from the output folder's checkpoint.h5")
    p.add_argument(
        "--backend",
        choices=("cpu", "gpu"),
        default=None,
        help="where an explicit run's time loop runs (default: the case's solver.backend, cpu): "
        "gpu needs a CUDA device and pip install peridyn[gpu] (docs/gpu.md)",
    )
    add_progress_flags(p)
    add_common_flags(p)
    add_max_memory(p)
    add_overwrite_flag(p)
    p.set_defaults(func=run)


def command_line(argv=None) -> str:
    """This process's ``peridyn ...`` command line (without --overwrite), for resume hints;
    under ``mpiexec -n N`` (N > 1) with its launcher, ``mpiexec -n N peridyn ...``, so that the
    hint resumes on as many ranks."""
    args = sys.argv[1:] if argv is None else argv
    launcher = ["mpiexec", "-n", str(world().size)] if world().size > 1 else []
    return shlex.join([*launcher, "peridyn", *(a for a in args if a != "--overwrite")])


def run(args) -> dict:
    """Run the case; print a readable summary unless --json. Under ``mpiexec -n N`` every rank
    runs its part (``peridyn.parallel``); only rank 0 prints (``peridyn.cli.main``)."""
    from peridyn.jobs.dispatch import job_function, run_job

    job_function("run")  # its modules loaded before the banner: a signal after it finds the job running

    backend = getattr(args, "backend", None)  # demo: no flag
    overrides = [*args.overrides, *([f"solver.backend={backend}"] if backend else [])]
    case = load_case_or_deck(args.case, overrides)
    info = provenance()
    logger.info(
        f"peridyn {info['peridyn_version']} (commit {info['git_commit'][:12]}): case "
        f"{case.name!r} from {args.case}"
    )
    summary = run_job(
        "run",
        case,
        args.output,
        case_path=args.case,
        checkpoint_every=args.checkpoint_every,
        restart=args.restart,
        progress=progress_bar(args.progress, case.name),
        base_dir=Path(args.case).parent,
        overwrite=args.overwrite,
        command=args.command_line if hasattr(args, "command_line") else command_line(),  # demo: ""
        comm=world(),
        figure_worker=True,
        max_memory=getattr(args, "max_memory", None),  # demo: no flag
    )
    if not args.json:
        print_summary(summary)
    return summary


def print_summary(summary: dict) -> None:
    """Readable end-of-run report (a modal run's: its modes)."""
    if summary["kind"] == "modal":
        print_modes(summary)
        return
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
