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
    parser.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="override a case entry, e.g. discretization.spacing=0.001 (repeatable)",
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


class DeprecatedAlias(argparse.Action):
    """An old spelling of an option, hidden from the help: stores like the new one and warns."""

    def __init__(self, option_strings, dest, new: str, **kwargs):
        self.new = new
        super().__init__(option_strings, dest, help=argparse.SUPPRESS, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None):
        warnings.warn(f"{option_string} is deprecated: use {self.new}", FutureWarning, stacklevel=2)
        setattr(namespace, self.dest, values)
