"""SIGINT and SIGTERM within ``peridyn.interrupts.deferred``: noted, acted on at ``check``
(issue 17, item 4: a signal ends a job at a safe point, never inside a numba kernel)."""

from __future__ import annotations

import os
import signal

import pytest

from peridyn import interrupts
from peridyn.errors import Interrupted


def _send(sig: int) -> None:
    """Deliver ``sig`` to this process; Python runs the handler before the next bytecode."""
    os.kill(os.getpid(), sig)


@pytest.mark.parametrize(
    "sig, name, code", [(signal.SIGINT, "SIGINT", 130), (signal.SIGTERM, "SIGTERM", 143)]
)
def test_a_signal_is_noted_and_raised_at_the_next_check(sig, name, code):
    with interrupts.deferred():
        interrupts.check(where="building the model")  # nothing pending: no effect
        _send(sig)
        with pytest.raises(Interrupted) as caught:
            interrupts.check(where="building the model")
    assert caught.value.signal_name == name and caught.value.exit_code == code
    assert str(caught.value) == f"interrupted ({name}) while building the model"


def test_a_time_step_is_named_in_the_message():
    with interrupts.deferred():
        _send(signal.SIGINT)
        with pytest.raises(Interrupted, match=r"^interrupted \(SIGINT\) at step 12$"):
            interrupts.check(12)


def test_a_second_signal_raises_at_once():
    """The user insists: the second Ctrl-C does not wait for a safe point."""
    with interrupts.deferred():
        _send(signal.SIGINT)
        with pytest.raises(KeyboardInterrupt):
            _send(signal.SIGINT)


def test_handlers_come_back_and_nothing_stays_pending():
    before = {sig: signal.getsignal(sig) for sig in interrupts.STOP_SIGNALS}
    with interrupts.deferred():
        with interrupts.deferred():  # nested: the outer block owns the handlers
            assert signal.getsignal(signal.SIGINT) is not before[signal.SIGINT]
        _send(signal.SIGTERM)
        assert signal.getsignal(signal.SIGTERM) is not before[signal.SIGTERM]
    assert {sig: signal.getsignal(sig) for sig in interrupts.STOP_SIGNALS} == before
    interrupts.check()  # the pending SIGTERM of the closed block is dropped
    with interrupts.deferred():
        interrupts.check()


def test_check_outside_a_block_never_raises():
    interrupts.check(3, "anything")


def test_usable_as_a_decorator():
    @interrupts.deferred()
    def job():
        _send(signal.SIGINT)
        interrupts.check(where="working")

    with pytest.raises(Interrupted, match="while working"):
        job()
