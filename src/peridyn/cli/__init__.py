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
        return getattr(exc, "exit_code", 1)
    if getattr(args, "json", False):
        json.dump(summary, sys.stdout, default=_to_builtin)
        sys.stdout.write("\n")
    return 0


def _to_builtin(obj):
    """JSON fallback for numpy scalars and arrays."""
    if hasattr(obj, "tolist"):
        return obj.tolist()
    raise TypeError(f"not JSON serialisable: {type(obj).__name__}")
