"""The step loop shared by the time-stepping solvers (explicit, Newmark).

SIGINT (Ctrl-C) and SIGTERM do not stop the loop inside a step (nor inside a numba kernel):
while it runs, their handlers only note the signal, and the loop raises
``peridyn.errors.Interrupted`` after the step that was under way and its observers. The
previous handlers are restored when the loop ends.
"""

from __future__ import annotations

import signal
import threading
from contextlib import contextmanager

from peridyn.discretization.state import State
from peridyn.errors import Interrupted

#: The signals that end a run at the end of a step.
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)


def advance(solver, state: State, n_steps: int, observers=(), progress=None) -> State:
    """Call ``solver.step(state)`` ``n_steps`` times, then ``observe(state, solver)`` of each
    observer and ``progress.update(1)`` (e.g. a tqdm bar) after every step.

    Raises
    ------
    Interrupted
        SIGINT or SIGTERM arrived: raised after the current step and its observers, with
        ``step`` the last completed step (``resume`` is left to the caller). A solver with an
        MPI ``domain`` (``peridyn.parallel``) raises it on every rank after the same step.
    """
    domain = getattr(solver, "domain", None)
    several = domain is not None and domain.size > 1
    with _deferred_signals() as received:
        for _ in range(int(n_steps)):
            solver.step(state)
            for obs in observers:
                obs.observe(state, solver)
            if progress is not None:
                progress.update(1)
            signum = received[0] if received else 0
            if several:  # the ranks stop together: a signal seen by any rank ends this step on all
                signum = domain.max(signum)
            if signum:
                raise Interrupted(signal.Signals(signum).name, state.step)
    return state


@contextmanager
def _deferred_signals():
    """Within the block, SIGINT and SIGTERM are appended to the yielded list instead of
    acting; the previous handlers come back after it. Outside the main thread (where
    handlers cannot be set) the signals keep their usual effect and the list stays empty."""
    received: list[int] = []
    if threading.current_thread() is not threading.main_thread():
        yield received
        return

    def note(signum, frame):
        received.append(signum)

    previous = {sig: signal.signal(sig, note) for sig in STOP_SIGNALS}
    try:
        yield received
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, signal.SIG_DFL if handler is None else handler)
