"""SIGINT (Ctrl-C), SIGTERM and SIGHUP (the terminal closed), acted on at safe points.

Python's own SIGINT handler raises ``KeyboardInterrupt`` wherever the interpreter happens to
be; when that is the launch of a parallel numba kernel the process can die of SIGSEGV
(measured: tests/unit/cli/test_cli_signals.py). Within :func:`deferred` the two signals are
only noted, and the code acts on them where stopping is safe by calling :func:`check` (after
a time step, between the phases of a build, in the iterations of the static, modal and
fatigue solvers), which raises :class:`peridyn.errors.Interrupted`. SIGHUP, sent when the
terminal or the ssh session of a run goes away, ends it as SIGTERM does: its checkpoint and
status are written (its messages to the lost terminal are dropped, ``peridyn.cli.streams``).
A second signal while the
first is still pending raises ``KeyboardInterrupt`` at once: the user insists.

Outside :func:`deferred`, and outside the main thread (where handlers cannot be set), the
signals keep their usual effect and :func:`check` never raises.
"""

from __future__ import annotations

import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager

from peridyn.errors import Interrupted

#: The signals that end a job at its next safe point.
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)

#: Signals noted and not yet acted on (at most one: a second one raises KeyboardInterrupt).
_pending: list[int] = []
#: How many :func:`deferred` blocks are open (the handlers are set by the outermost one).
_depth = 0


@contextmanager
def deferred() -> Iterator[None]:
    """Within the block, the ``STOP_SIGNALS`` are noted for :func:`check` instead of acting.

    Re-entrant: the handlers are set by the outermost block and the previous ones come back
    when it ends, with any signal still pending dropped.
    """
    global _depth
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {}
    if _depth == 0:
        _pending.clear()
        previous = {sig: signal.signal(sig, _note) for sig in STOP_SIGNALS}
    _depth += 1
    try:
        yield
    finally:
        _depth -= 1
        if _depth == 0:
            for sig, handler in previous.items():
                signal.signal(sig, signal.SIG_DFL if handler is None else handler)
            _pending.clear()


@contextmanager
def raised_outside_jobs() -> Iterator[None]:
    """Within the block, SIGTERM and SIGHUP left at their default action (the process dies with
    no word) raise :class:`~peridyn.errors.Interrupted` instead, as SIGINT raises
    ``KeyboardInterrupt``: a signal while a command starts (imports, reading the case) ends it
    with one line and 128 + the signal. A job's :func:`deferred` block notes them as usual."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {
        sig: signal.signal(sig, _raise)
        for sig in (signal.SIGTERM, signal.SIGHUP)
        if signal.getsignal(sig) is signal.SIG_DFL
    }
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def _raise(signum, frame) -> None:
    raise Interrupted(signal.Signals(signum).name, where="starting")


def check(step: int | None = None, where: str = "", agree=None) -> None:
    """Raise :class:`~peridyn.errors.Interrupted` if a stop signal arrived since the block began.

    Parameters
    ----------
    step : int or None
        The last completed time step, for a time-stepping job.
    where : str
        What the job was doing (e.g. "building the model"), for the other jobs.
    agree : callable(int) -> int, optional
        Combines the signal number noted here (0 for none) with those of the other processes
        of a parallel run (e.g. the maximum over the MPI ranks), so that all stop together.
        A collective: every process must call ``check`` at the same point.
    """
    signum = _pending[0] if _pending else 0
    if agree is not None:
        signum = agree(signum)
    if signum:
        raise Interrupted(signal.Signals(signum).name, step, where=where)


def _note(signum, frame) -> None:
    if _pending:
        raise KeyboardInterrupt
    _pending.append(signum)
