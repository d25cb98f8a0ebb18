"""How the command line reports a failure: one line on stderr, with ``--json`` also one JSON object
on stdout, and an exit status; the traceback only with ``--debug``.

Exit statuses: 1 for an error in the input or the run (a ``PeridynError``, an I/O failure, no
memory left), 2 for a command line that argparse refuses and for an internal error (a bug),
129 (SIGHUP), 130 (SIGINT) or 143 (SIGTERM) for an interrupted run.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
import traceback
from contextlib import contextmanager

from peridyn.errors import InputError, Interrupted, PeridynError, did_you_mean

#: Exit status of an internal error (an exception no check anticipated).
INTERNAL_ERROR_STATUS = 2
#: Exit status of Ctrl-C outside a run's step loop (128 + SIGINT).
KEYBOARD_INTERRUPT_STATUS = 130
#: Exit statuses of an interrupted command: reported as such, not as an error.
INTERRUPTED_STATUSES = (KEYBOARD_INTERRUPT_STATUS, *Interrupted.EXIT_CODES.values())
#: Attributes of an exception copied into the ``--json`` error object, when it has them.
JSON_FIELDS = ("key", "value", "expected", "path", "step", "time", "point", "resume")


class UsageError(InputError):
    """A command line that argparse refuses: unknown option, missing or malformed argument.

    Parameters
    ----------
    prog : str
        The (sub)command, e.g. ``"peridyn run"``.
    message : str
        argparse's message, e.g. ``"argument --checkpoint-every: invalid int value: 'x'"``.
    choices : sequence of str
        The options and subcommands the parser knows: the nearest to the value is suggested.
    """

    exit_code = 2

    def __init__(self, prog: str, message: str, choices=()):
        self.prog = prog
        self.key, self.value, self.expected = _parse_argparse_message(message)
        hint = did_you_mean(self.value, choices) if self.value and choices else ""
        super().__init__(f"{message}{hint} (see '{prog} --help')")


class ArgumentParser(argparse.ArgumentParser):
    """An argparse parser that raises :class:`UsageError` instead of printing the usage and exiting
    (its subcommand parsers are of this class too)."""

    def error(self, message):
        choices = list(self._option_string_actions)  # an unknown option: suggest the nearest
        if self._subparsers is not None:  # an unknown subcommand: suggest the nearest
            choices += [c for a in self._subparsers._group_actions for c in (a.choices or ())]
        raise UsageError(self.prog, message, choices)

    def subcommand(self, name: str) -> ArgumentParser:
        """The parser of subcommand ``name``."""
        return self.subcommands()[name]

    def subcommands(self) -> dict[str, ArgumentParser]:
        """The parsers of the subcommands by name, in the order ``--help`` lists them."""
        if self._subparsers is None:
            return {}
        return {name: p for a in self._subparsers._group_actions for name, p in (a.choices or {}).items()}


_ARGUMENT = re.compile(r"argument (?P<key>[^:]+): (?P<detail>.*)")
_INVALID_VALUE = re.compile(r"invalid (?P<type>\w+) value: '(?P<value>.*)'")
_INVALID_CHOICE = re.compile(r"invalid choice: '(?P<value>.*?)' \(choose from (?P<choices>.*)\)")
#: the message of peridyn's own argparse types (``cli.options.positive_int``, ``memory_bytes``)
_EXPECTED_GOT = re.compile(r"expected (?P<expected>.*), got '?(?P<value>.*?)'?")
_EXPECTED_TYPE = {"int": "an integer", "float": "a number"}


def _parse_argparse_message(message: str) -> tuple:
    """(key, value, expected) of an argparse error message, each None where it does not say."""
    if message.startswith("the following arguments are required: "):
        return message.split(": ", 1)[1], None, "required"
    if message.startswith("unrecognized arguments: "):
        return None, message.split(": ", 1)[1], "no such option or argument"
    match = _ARGUMENT.fullmatch(message)
    if match is None:
        return None, None, None
    key, detail = match["key"].split("/")[0], match["detail"]
    if m := _INVALID_VALUE.fullmatch(detail):
        return key, m["value"], _EXPECTED_TYPE.get(m["type"], f"a {m['type']} value")
    if m := _INVALID_CHOICE.fullmatch(detail):
        return key, m["value"], f"one of {m['choices']}"
    if m := _EXPECTED_GOT.fullmatch(detail):
        return key, m["value"], m["expected"]
    return key, None, detail


def report(exc: BaseException, prog: str, as_json: bool, debug: bool) -> int:
    """Report ``exc`` as one line on stderr (``prog: error: ...``), with ``as_json`` also as one
    JSON object on stdout, with ``debug`` after its traceback; returns the exit status."""
    if debug:
        traceback.print_exception(exc, file=sys.stderr)
    message, status = describe(exc, prog)
    line = one_line(message)
    label = "" if status in INTERRUPTED_STATUSES else "error: "
    print(f"{prog}: {label}{line}", file=sys.stderr)
    if as_json:
        fields = {**getattr(exc, "summary", {}), "error": line}  # a job's summary, when it has one
        fields.update(
            {k: _jsonable(getattr(exc, k)) for k in JSON_FIELDS if getattr(exc, k, None) is not None}
        )
        if isinstance(exc, OSError) and exc.filename is not None:
            fields["path"] = str(exc.filename)
        try:
            print(json.dumps(fields))
        except OSError:  # stdout itself failed (a full disk, a closed pipe): stderr has the line
            pass
    return status


def _jsonable(value):
    """``value`` where it is strict JSON (numpy values as numbers or lists), else its repr (NaN and
    infinity too, which strict JSON has no numbers for)."""
    value = value.tolist() if hasattr(value, "tolist") else value
    try:
        json.dumps(value, allow_nan=False)
    except (TypeError, ValueError):
        return repr(value)
    return value


#: The commands that discretize a body: an out-of-memory error there suggests a coarser spacing.
SPACING_COMMANDS = ("run", "demo", "modal", "fatigue", "study", "sweep", "validate", "bench")


def describe(exc: BaseException, prog: str = "") -> tuple[str, int]:
    """The message of ``exc`` for the user and the exit status (``prog``: the command, e.g.
    ``"peridyn lamb"``, whose advice an out-of-memory error gives)."""
    if isinstance(exc, PeridynError):
        return str(exc), getattr(exc, "exit_code", 1)
    cause = _underlying(exc)
    if isinstance(cause, KeyboardInterrupt):  # numba wraps it in a SystemError
        return "interrupted", KEYBOARD_INTERRUPT_STATUS
    if isinstance(cause, MemoryError):
        detail = f" ({cause})" if str(cause) else ""
        command = prog.split()[1] if len(prog.split()) > 1 else ""
        advice = (
            "try a coarser discretization.spacing or a smaller body"
            if command in SPACING_COMMANDS
            else "ask for less (fewer or lower frequencies, fewer points)"
        )
        return f"out of memory{detail}: {advice}", 1
    if isinstance(exc, OSError):
        return os_error_message(exc), 1
    return (
        f"internal error: {type(exc).__name__}: {exc} (run with --debug for the traceback)",
        INTERNAL_ERROR_STATUS,
    )


#: HDF5's report of a failed system call (h5py raises it as an OSError without a filename).
_HDF5_IO_FAILURE = re.compile(r"(?:file)?name = '(?P<path>[^']*)'.*error message = '(?P<reason>[^']*)'")


def os_error_message(exc: OSError) -> str:
    """``PATH: reason`` of an I/O failure (``[Errno 28] No space left on device: 'x'`` ->
    ``x: No space left on device``, also from HDF5's long report), or the message as it is when
    it names no path."""
    if isinstance(exc, BrokenPipeError) and exc.filename is None:  # the only pipe written: stdout
        return f"<stdout>: {exc.strerror}"
    if exc.filename is None or not exc.strerror:
        if m := _HDF5_IO_FAILURE.search(str(exc)):
            return f"{m['path']}: {m['reason']} ({(exc.strerror or str(exc)).split(' (')[0]})"
        return exc.strerror or str(exc)
    paths = str(exc.filename) + (f" -> {exc.filename2}" if exc.filename2 is not None else "")
    return f"{paths}: {exc.strerror}"


def _underlying(exc: BaseException) -> BaseException:
    """The KeyboardInterrupt or MemoryError behind ``exc`` (itself, or in its chain of causes), or
    ``exc``."""
    seen = set()
    node = exc
    while node is not None and id(node) not in seen:
        if isinstance(node, (KeyboardInterrupt, MemoryError)):
            return node
        seen.add(id(node))
        node = node.__cause__ or node.__context__
    return exc


def one_line(message: str) -> str:
    """``message`` on one line: its lines stripped and joined by "; "."""
    return "; ".join(part.strip() for part in str(message).splitlines() if part.strip())


@contextmanager
def writing(path):
    """Within the block, an OSError that names no file (a full disk found when a file is flushed
    or closed) is raised again naming ``path``."""
    try:
        yield
    except OSError as exc:
        if exc.filename is not None or exc.errno is None:
            raise
        raise OSError(exc.errno, exc.strerror, str(path)) from exc
