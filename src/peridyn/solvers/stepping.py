"""The step loop shared by the time-stepping solvers (explicit, Newmark)."""

from __future__ import annotations

from peridyn.discretization.state import State


def advance(solver, state: State, n_steps: int, observers=(), progress=None) -> State:
    """Call ``solver.step(state)`` ``n_steps`` times, then ``observe(state, solver)`` of each
    observer and ``progress.update(1)`` (e.g. a tqdm bar) after every step."""
    for _ in range(int(n_steps)):
        solver.step(state)
        for obs in observers:
            obs.observe(state, solver)
        if progress is not None:
            progress.update(1)
    return state
