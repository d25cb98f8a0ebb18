"""What the command line writes to stderr besides errors: a progress bar only where someone
watches it, and warnings as one plain line each."""

from __future__ import annotations

import sys
import warnings
from contextlib import contextmanager

from peridyn.cli.errors import one_line


def progress_bar(choice: bool | None, desc: str):
    """A progress-bar factory ``total -> tqdm bar`` on stderr, or None for no bar.

    Parameters
    ----------
    choice : bool or None
        ``--progress`` (True), ``--no-progress`` (False) or neither (None: a bar only when stderr
        is a terminal, never carriage-return lines in a redirected log).
    desc : str
        The bar's label (the case name).
    """
    show = sys.stderr.isatty() if choice is None else choice
    if not show:
        return None
    from tqdm import tqdm

    def factory(total: int):
        return tqdm(total=total, unit="step", file=sys.stderr, dynamic_ncols=True, desc=desc)

    return factory


@contextmanager
def plain_warnings():
    """Within the block, a warning prints as ``peridyn: warning: <message>`` on one line, without
    the source file and line; the previous ``warnings.showwarning`` is restored after."""
    saved = warnings.showwarning

    def show(message, category, filename, lineno, file=None, line=None):
        print(f"peridyn: warning: {one_line(str(message))}", file=file or sys.stderr)

    warnings.showwarning = show
    try:
        yield
    finally:
        warnings.showwarning = saved
