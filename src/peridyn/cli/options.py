"""Options that several subcommands share, spelt the same everywhere."""

from __future__ import annotations

import argparse
import warnings


def add_common_flags(parser: argparse.ArgumentParser) -> None:
    """Every subcommand's ``--json`` and ``--debug``."""
    parser.add_argument(
        "--json", action="store_true", help="print one machine-readable JSON object on stdout"
    )
    parser.add_argument(
        "--debug",
        action="store_true",
        default=argparse.SUPPRESS,  # keeps a `peridyn --debug COMMAND` given before the command
        help="on an error, also print the Python traceback",
    )


def add_case_arguments(parser: argparse.ArgumentParser) -> None:
    """The case path and the repeatable ``--set key.path=value`` override."""
    parser.add_argument("case", help="YAML case file")
    add_set_flag(parser, "override a case entry, e.g. discretization.spacing=0.001 (repeatable)")


def add_set_flag(parser: argparse.ArgumentParser, text: str) -> None:
    """The repeatable ``--set key.path=value`` override of case entries (``args.overrides``)."""
    parser.add_argument(
        "--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE", help=text
    )


def add_output_flag(parser: argparse.ArgumentParser, text: str, default=None) -> None:
    """``--output``/``-o``: the folder a command writes to."""
    parser.add_argument("--output", "-o", default=default, metavar="DIR", help=text)


def add_progress_flags(parser: argparse.ArgumentParser) -> None:
    """``--progress`` / ``--no-progress`` (``args.progress``: True, False, or None for a bar only
    when stderr is a terminal)."""
    group = parser.add_mutually_exclusive_group()
    group.add_argument(
        "--progress",
        action="store_true",
        default=None,
        help="show a progress bar (default: only when stderr is a terminal)",
    )
    group.add_argument("--no-progress", dest="progress", action="store_false", help="no progress bar")


def add_executor_flags(parser: argparse.ArgumentParser, what: str = "runs") -> None:
    """``--executor``, ``--workers``, ``--threads`` and ``--scheduler``: where the runs of a sweep run
    (``peridyn.jobs.sweep_run``); ``what`` names them in the help."""
    from peridyn.jobs.sweep_run import EXECUTORS

    parser.add_argument(
        "--executor",
        choices=EXECUTORS,
        default="serial",
        help=f"where the {what} run: this process, a pool of processes, or dask (default: serial)",
    )
    parser.add_argument(
        "--workers",
        type=positive_int,
        default=1,
        metavar="N",
        help="worker processes (processes, local dask cluster)",
    )
    parser.add_argument(
        "--threads",
        type=positive_int,
        default=None,
        metavar="N",
        help=f"threads per run (numba; BLAS and OpenMP in the workers started here), set before "
        f"each of the {what} starts (default: cores // workers with processes and a local dask "
        "cluster, else the process's or the cluster workers' own)",
    )
    parser.add_argument(
        "--scheduler",
        default=None,
        metavar="ADDRESS",
        help="address of a running dask scheduler (with --executor dask)",
    )


def add_rerun_flag(parser: argparse.ArgumentParser, what: str = "runs") -> None:
    """``--overwrite`` of a command that resumes its folder (sweep, study): run again the
    ``what`` already complete there."""
    parser.add_argument(
        "--overwrite", action="store_true", help=f"run again the {what} already complete (default: skip them)"
    )


class DeprecatedAlias(argparse.Action):
    """An old spelling of an option, hidden from the help: stores like the new one and warns."""

    def __init__(self, option_strings, dest, new: str, **kwargs):
        self.new = new
        super().__init__(option_strings, dest, help=argparse.SUPPRESS, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None):
        warnings.warn(f"{option_string} is deprecated: use {self.new}", FutureWarning, stacklevel=2)
        setattr(namespace, self.dest, values)


def positive_int(text: str) -> int:
    """argparse type: an integer >= 1 (a count of steps, modes...)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 1, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 1, got {value}")
    return value


def memory_bytes(text: str) -> int:
    """argparse type: a memory size in bytes, as a number ("4e9") or with a unit ("4GB", "512MiB")."""
    from peridyn.errors import InputError
    from peridyn.setup.estimate import parse_bytes

    try:
        return parse_bytes(text)
    except InputError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def add_max_memory(parser: argparse.ArgumentParser) -> None:
    """Give a subcommand the common ``--max-memory BYTES`` option (default: the machine's memory)."""
    parser.add_argument(
        "--max-memory",
        type=memory_bytes,
        default=None,
        metavar="BYTES",
        help="refuse a job whose estimated peak memory exceeds BYTES (e.g. 4GB; default: physical memory)",
    )


def add_overwrite_flag(parser) -> None:
    """The ``--overwrite`` flag: replace an earlier run's results in the output folder."""
    parser.add_argument(
        "--overwrite",
        action="store_true",
        help="replace the results of an earlier run in the output folder (refused without it)",
    )
