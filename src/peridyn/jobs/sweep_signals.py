"""SIGINT and SIGTERM while a sweep runs its runs (``Signals``): noted, and acted on where the
sweep can stop without losing a finished run."""

from __future__ import annotations

import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager


class Signals:
    """SIGINT and SIGTERM while a sweep runs (in the main thread): each raises KeyboardInterrupt
    where it arrives (``name`` says which), except within ``deferred()`` (the dataset being
    written), where it is raised when the block ends. A run's time stepping installs its own
    handlers (``peridyn.solvers.stepping``) and ends the run with ``Interrupted`` instead."""

    def __init__(self):
        self.name = None
        self._depth = 0
        self._pending = False
        self._previous = {}

    def __enter__(self):
        if threading.current_thread() is threading.main_thread():
            self._previous = {sig: signal.signal(sig, self._note) for sig in (signal.SIGINT, signal.SIGTERM)}
        return self

    def __exit__(self, *exc):
        for sig, handler in self._previous.items():
            signal.signal(sig, signal.SIG_DFL if handler is None else handler)
        return False

    def _note(self, signum, frame):
        self.name = signal.Signals(signum).name
        if self._depth:
            self._pending = True
        else:
            raise KeyboardInterrupt

    @contextmanager
    def deferred(self) -> Iterator[None]:
        """A block that a signal does not cut short."""
        self._depth += 1
        try:
            yield
        finally:
            self._depth -= 1
        if self._pending and not self._depth:
            self._pending = False
            raise KeyboardInterrupt
