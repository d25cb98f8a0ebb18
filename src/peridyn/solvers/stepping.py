"""The step loop shared by the time-stepping solvers (explicit, Newmark).

SIGINT (Ctrl-C) and SIGTERM do not stop the loop inside a step (nor inside a numba kernel):
while it runs they are only noted (``peridyn.interrupts``), and the loop raises
``peridyn.errors.Interrupted`` after the step that was under way and its observers.
"""

from __future__ import annotations

from peridyn import interrupts
from peridyn.discretization.state import State
from peridyn.parallel.domain import failed_alone


def advance(solver, state: State, n_steps: int, observers=(), progress=None) -> State:
    """Call ``solver.step(state)`` ``n_steps`` times, then ``observe(state, solver)`` of each
    observer and ``progress.update(1)`` (e.g. a tqdm bar) after every step.

    Raises
    ------
    Interrupted
        SIGINT or SIGTERM arrived: raised after the current step and its observers, with
        ``step`` the last completed step (``resume`` is left to the caller). A solver with an
        MPI ``domain`` (``peridyn.parallel``) raises it on every rank after the same step.
    Exception
        Under MPI, an error raised by one rank alone in a step or its observers is marked with
        ``failed_rank`` (``peridyn.parallel.domain.failed_alone``).
    """
    domain = getattr(solver, "domain", None)
    parallel = domain is not None and domain.size > 1
    agree = domain.max if parallel else None
    with interrupts.deferred():
        for _ in range(int(n_steps)):
            try:
                solver.step(state)
                for obs in observers:
                    obs.observe(state, solver)
            except Exception as exc:
                if parallel:  # an error of this rank alone ends every rank (peridyn.cli)
                    failed_alone(exc, domain.comm)
                raise
            if progress is not None:
                progress.update(1)
            interrupts.check(state.step, agree=agree)  # with several ranks, all stop after this step
    return state
