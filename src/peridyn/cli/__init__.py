"""Command-line interface: ``peridyn <command> ...``.

Each subcommand lives in its own module in this package and exposes
``register(subparsers)``, which adds its parser and sets ``func`` to a
function ``func(args) -> dict``. The returned dict is the machine-readable
summary: printed as one JSON object on stdout with ``--json``; otherwise the
command prints its own human-readable report (to stdout) and logs go to stderr.
A failure is one line on stderr (and one JSON object on stdout with ``--json``):
see :mod:`peridyn.cli.errors`. A closed or broken stdout or stderr never ends a command in a
traceback (:mod:`peridyn.cli.streams`).
"""

from __future__ import annotations

import importlib
import json
import os
import signal
import sys
import threading
import time

from peridyn.cli.errors import ArgumentParser, report, writing
from peridyn.cli.logs import configure_logging, plain_warnings
from peridyn.cli.streams import usable_streams
from peridyn.errors import InputError
from peridyn.interrupts import STOP_SIGNALS, raised_outside_jobs

#: Subcommand modules, in the order ``peridyn --help`` lists them.
COMMAND_MODULES = (
    "peridyn.cli.run_cmd",
    "peridyn.cli.validate_cmd",
    "peridyn.cli.convert_cmd",
    "peridyn.cli.demo_cmd",
    "peridyn.cli.examples_cmd",
    "peridyn.cli.schema_cmd",
    "peridyn.cli.bench_cmd",
    "peridyn.cli.lamb_cmd",
    "peridyn.cli.dispersion_cmd",
    "peridyn.cli.modal_cmd",
    "peridyn.cli.plot_cmd",
    "peridyn.cli.fatigue_cmd",
    "peridyn.cli.study_cmd",
    "peridyn.cli.sweep_cmd",
    "peridyn.cli.monitor_cmd",
)


def build_parser() -> ArgumentParser:
    """The top-level parser with every available subcommand registered."""
    parser = ArgumentParser(
        prog="peridyn", description="Peridynamics for waves, vibration and damage in solids."
    )
    parser.add_argument("--version", action="store_true", help="print the version and exit")
    parser.add_argument("--debug", action="store_true", help="on an error, also print the Python traceback")
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


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``peridyn`` console script; returns the exit status.

    Never raises (but ``--help``'s SystemExit): every failure is reported by
    :func:`peridyn.cli.errors.report`.
    """
    the_process = argv is None  # the console script: the process ends with this command
    argv = sys.argv[1:] if argv is None else list(argv)
    _quiet_unless_first_rank()
    configure_logging()
    args = None
    with plain_warnings(), usable_streams(), raised_outside_jobs():
        try:
            parser = build_parser()
            args = _parse(parser, argv)
            status = _dispatch(parser, args)
            with writing("<stdout>"):  # a full disk or a closed pipe on stdout is reported here
                sys.stdout.flush()
        except (Exception, KeyboardInterrupt) as exc:
            prog = getattr(exc, "prog", None) or " ".join(
                filter(None, ["peridyn", getattr(args, "command", None)])
            )
            as_json = getattr(args, "json", "--json" in argv)
            if getattr(exc, "failed_rank", None) is not None:
                _speak()  # this rank alone knows of the error
            status = report(exc, prog, as_json, getattr(args, "debug", "--debug" in argv))
            _drop_unwritable_stdout()
            if getattr(exc, "failed_rank", None) is not None:
                _abort_every_rank(status)
    if the_process:
        _exit_uninterrupted()
    return status


def _exit_uninterrupted() -> None:
    """Ignore stop signals from here on: the command's outcome and exit status are decided, and
    the interpreter's exit that follows (a second or so of closing libraries) is not cut short
    into a death by the signal (exit -1 after a complete run)."""
    if threading.current_thread() is threading.main_thread():
        for sig in STOP_SIGNALS:
            signal.signal(sig, signal.SIG_IGN)


def _parse(parser: ArgumentParser, argv: list[str]):
    """``parser.parse_args(argv)``, but an unknown argument is refused by the subcommand's parser
    (which names the subcommand and the nearest option)."""
    args, extra = parser.parse_known_args(argv)
    if extra:
        command = parser.subcommand(args.command) if args.command else parser
        command.error(f"unrecognized arguments: {' '.join(extra)}")
    return args


def _dispatch(parser: ArgumentParser, args) -> int:
    """Run the parsed command; print its summary with ``--json``; the exit status."""
    if args.version:
        from peridyn import __version__

        print(__version__)
        return 0
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    _refuse_under_mpi(args.command)
    summary = args.func(args)
    if args.json:
        with writing("<stdout>"):
            json.dump(summary, sys.stdout, default=_to_builtin)
            sys.stdout.write("\n")
    return 0


#: Seconds a rank waits between printing its own error and ``MPI_Abort`` (``_abort_every_rank``).
ABORT_GRACE_SECONDS = 1.0

#: The commands that run over MPI ranks (``mpiexec -n N peridyn ...``, N > 1).
MPI_COMMANDS = ("run", "modal", "fatigue", "monitor")


def _refuse_under_mpi(command: str) -> None:
    """Refuse, on every rank, a command that would run N times over under ``mpiexec -n N``."""
    from peridyn.parallel.comm import launched_by_mpi, world

    if command not in MPI_COMMANDS and launched_by_mpi() and world().size > 1:
        raise InputError(
            f"'peridyn {command}' does not run over MPI ranks (only {', '.join(MPI_COMMANDS)} do): "
            "run it without mpiexec"
        )


def _quiet_unless_first_rank() -> None:
    """Under ``mpiexec -n N`` only rank 0 speaks: the other ranks' stdout and stderr go to
    /dev/null (every rank raises the same error at the same point, ``peridyn.parallel.domain``,
    and rank 0 reports it once)."""
    from peridyn.parallel.comm import launched_by_mpi, world

    if launched_by_mpi() and world().rank > 0:
        sys.stdout = sys.stderr = open(os.devnull, "w")  # noqa: SIM115 - for the process's lifetime


def _speak() -> None:
    """Give this rank back its stdout and stderr (``_quiet_unless_first_rank``)."""
    sys.stdout, sys.stderr = sys.__stdout__, sys.__stderr__


def _abort_every_rank(status: int) -> None:
    """End every MPI rank after an error of this rank alone (``failed_rank``, raised inside a time
    step). The last resort, and the only one: the other ranks may be blocked in a halo exchange or
    a collective that this rank will never join, and MPI cancels neither but by ``MPI_Abort``
    (results.h5 keeps the status ``running``, as after a kill)."""
    from peridyn.parallel.comm import world

    sys.stdout.flush()
    sys.stderr.flush()
    # mpiexec forwards a rank's output through a pipe to its proxy, which MPI_Abort may tear
    # down before it has passed the error line on (seen once in 50 MPI tests at load 6)
    time.sleep(ABORT_GRACE_SECONDS)
    world().abort(status)


def _drop_unwritable_stdout() -> None:
    """Point stdout at /dev/null when what it holds cannot be written (a full disk, a closed pipe),
    so that the interpreter's flush at exit prints no traceback."""
    try:
        sys.stdout.flush()
    except OSError:
        try:
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        except (OSError, ValueError):  # not a real file (captured by a test)
            pass


def _to_builtin(obj):
    """JSON fallback for numpy scalars and arrays."""
    if hasattr(obj, "tolist"):
        return obj.tolist()
    raise TypeError(f"not JSON serialisable: {type(obj).__name__}")
