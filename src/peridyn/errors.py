"""Exceptions that speak to the user: each names what is wrong and what was expected."""

from __future__ import annotations

import difflib


class PeridynError(Exception):
    """Base class of every error peridyn raises on purpose."""


class InputError(PeridynError, ValueError):
    """A value given by the user (argument, array, case-file entry) is invalid."""


class CaseFileError(InputError):
    """A case file is invalid.

    Parameters
    ----------
    path : str
        The case file.
    key : str
        Dotted key path inside the file, e.g. ``"material.E"``.
    value : object
        The offending value (``None`` when missing).
    expected : str
        What was expected instead.
    has_value : bool
        False where no one value is at fault (a check across keys): the message leaves out
        ``= value``.

    The message shows at most ``SHOWN_CHARACTERS`` of the value's repr (a 10 000-character
    ``--set`` value is cut, with its length); ``value`` keeps it whole.

    >>> error = CaseFileError("case.yaml", "name", "x" * 500, "a short name")
    >>> str(error).endswith("x... (502 characters): a short name"), len(error.value)
    (True, 500)
    """

    #: Characters of the value's repr that the message shows.
    SHOWN_CHARACTERS = 80

    def __init__(self, path: str, key: str, value, expected: str, *, has_value: bool = True):
        self.path, self.key, self.value, self.expected = path, key, value, expected
        shown = f" = {_cut(repr(value), self.SHOWN_CHARACTERS)}" if has_value else ""
        super().__init__(f"{path}: {key}{shown}: {expected}")


def _cut(text: str, limit: int) -> str:
    """``text``, or its first ``limit`` characters and its length when it is longer."""
    return text if len(text) <= limit else f"{text[:limit]}... ({len(text)} characters)"


class InstabilityError(PeridynError, RuntimeError):
    """The explicit integration blew up (NaN/inf or runaway displacement)."""

    def __init__(self, step: int, time: float, point: int, detail: str = ""):
        self.step, self.time, self.point, self.detail = step, time, point, detail
        msg = f"solution became unstable at step {step} (t = {time:.6g} s), point {point}"
        super().__init__(msg + (f": {detail}" if detail else ""))


class Interrupted(PeridynError):
    """A job stopped by a signal (SIGINT, SIGTERM, SIGHUP) at a safe point, its files closed.

    Parameters
    ----------
    signal_name : str
        "SIGINT", "SIGTERM" or "SIGHUP".
    step : int or None
        The last completed time step of a time-stepping job, else None.
    resume : str
        How to continue (e.g. the command line with ``--restart``), or "" when it cannot be.
    where : str
        What a job without time steps was doing (e.g. "building the model"), or "".
    """

    #: exit status of the command line: 128 + the signal number
    EXIT_CODES = {"SIGHUP": 129, "SIGINT": 130, "SIGTERM": 143}

    def __init__(self, signal_name: str, step: int | None = None, resume: str = "", where: str = ""):
        self.signal_name, self.step, self.resume, self.where = signal_name, step, resume, where
        self.exit_code = self.EXIT_CODES.get(signal_name, 130)
        msg = f"interrupted ({signal_name}) {self.progress}".rstrip()
        super().__init__(msg + (f"; resume with: {resume}" if resume else ""))

    @property
    def progress(self) -> str:
        """ "at step N", "while <where>" or ""."""
        if self.step is not None:
            return f"at step {self.step}"
        return f"while {self.where}" if self.where else ""


def did_you_mean(word: str, choices) -> str:
    """A ``" (did you mean 'x'?)"`` suffix for a misspelt ``word``, or ``""``.

    >>> did_you_mean("lsp", ["pmb", "lps"])
    " (did you mean 'lps'?)"
    >>> did_you_mean("elastic", ["pmb", "lps"])
    ''

    Only names are compared: a ``word`` that is not text (a number where a name belongs) has
    no suggestion, and choices that are not text are skipped.

    >>> did_you_mean(float("nan"), ["pmb", "lps"]), did_you_mean("lsp", [1, "lps"])
    ('', " (did you mean 'lps'?)")
    """
    if not isinstance(word, str):
        return ""
    close = difflib.get_close_matches(word, [c for c in choices if isinstance(c, str)], n=1)
    return f" (did you mean {close[0]!r}?)" if close else ""
