"""Command-line interface: ``peridyn <command> ...``.

Each subcommand lives in its own module in this package and exposes
``register(subparsers)``, which adds its parser and sets ``func`` to a
function ``func(args) -> dict``. The returned dict is the machine-readable
summary: printed as one JSON object on stdout with ``--json``; otherwise the
command prints its own human-readable report (to stdout) and logs go to stderr.
"""

from __future__ import annotations

import argparse
import importlib
import json
import sys

from peridyn.errors import PeridynError

#: Subcommand modules, in the order ``peridyn --help`` lists them.
COMMAND_MODULES = (
    "peridyn.cli.run_cmd",
    "peridyn.cli.validate_cmd",
    "peridyn.cli.demo_cmd",
    "peridyn.cli.bench_cmd",
    "peridyn.cli.lamb_cmd",
    "peridyn.cli.dispersion_cmd",
    "peridyn.cli.modal_cmd",
    "peridyn.cli.plot_cmd",
    "peridyn.cli.fatigue_cmd",
    "peridyn.cli.study_cmd",
)


def build_parser() -> argparse.ArgumentParser:
    """The top-level parser with every available subcommand registered."""
    parser = argparse.ArgumentParser(
        prog="peridyn", description="Peridynamics for waves, vibration and damage in solids."
    )
    parser.add_argument("--version", action="store_true", help="print the version and exit")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in COMMAND_MODULES:
        try:
            module = importlib.import_module(name)
        except ModuleNotFoundError as exc:  # a subcommand not yet shipped in this build
            if exc.name != name:
                raise
            continue
        module.register(sub)
    return parser


def add_json_flag(parser: argparse.ArgumentParser) -> None:
    """Give a subcommand the common ``--json`` flag."""
    parser.add_argument(
        "--json", action="store_true", help="print one machine-readable JSON object on stdout"
    )


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
    from peridyn.jobs.estimate import parse_bytes

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


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``peridyn`` console script; returns the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.version:
        from peridyn import __version__

        print(__version__)
        return 0
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    try:
        summary = args.func(args)
    except PeridynError as exc:
        print(f"peridyn {args.command}: error: {exc}", file=sys.stderr)
        return 1
    if getattr(args, "json", False):
        json.dump(summary, sys.stdout, default=_to_builtin)
        sys.stdout.write("\n")
    return 0


def _to_builtin(obj):
    """JSON fallback for numpy scalars and arrays."""
    if hasattr(obj, "tolist"):
        return obj.tolist()
    raise TypeError(f"not JSON serialisable: {type(obj).__name__}")
