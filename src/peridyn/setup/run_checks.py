"""What a time-stepping run would do that its case surely did not mean, found before it runs
(docs/user-guide.md, "Warnings and errors before a run").

Errors (``CaseFileError``): an excitation whose frequency is above the Nyquist frequency of the
time step, 1 / (2 dt) (it would be sampled as another, lower frequency: aliasing).

Warnings (the run goes on): a run shorter than one step (it makes one whole step), snapshot
times after the run's end (never written), and a recording interval (``output.every``) longer
than the run (the series hold the first state only).
"""

from __future__ import annotations

import warnings

from peridyn.errors import CaseFileError
from peridyn.io.case import Case


def check_run_plan(case: Case, dt: float, n_steps: int) -> None:
    """Check a time-stepping run of ``n_steps`` steps of ``dt`` (s) of ``case``: raise for an
    excitation above the step's Nyquist frequency, warn of what would be lost (module docstring).

    Raises
    ------
    CaseFileError
        Naming the excitation's key, its frequency and the Nyquist frequency.
    """
    nyquist = 0.5 / dt
    for key, frequency in excitation_frequencies(case):
        if frequency > nyquist:
            raise CaseFileError(
                case.name,
                key,
                frequency,
                f"a frequency below the Nyquist frequency 1/(2 dt) = {nyquist:.4g} Hz of the time step "
                f"dt = {dt:.4g} s (above it the excitation is aliased): a smaller solver.dt or a "
                "lower frequency",
            )
    end = n_steps * dt
    s, out = case.solver, case.output
    if s.time is not None and s.time < dt * (1 - 1e-9):
        warnings.warn(
            f"{case.name}: solver.time = {s.time:.4g} s is shorter than one time step (dt = {dt:.4g} s): "
            f"the run makes one step, to t = {end:.4g} s",
            stacklevel=2,
        )
    late = [t for t in out.snapshot_times if t > end * (1 + 1e-9)]
    if late:
        warnings.warn(
            f"{case.name}: output.snapshot_times {late} come after the run's end t = {end:.4g} s: "
            "they are never written",
            stacklevel=2,
        )
    if out.every > n_steps:
        warnings.warn(
            f"{case.name}: output.every = {out.every} steps is longer than the run's {n_steps} steps: "
            "the probe series hold the initial state only (the final state is in final/u)",
            stacklevel=2,
        )


def excitation_frequencies(case: Case) -> list[tuple[str, float]]:
    """(key, Hz) of every time function with a ``frequency`` that drives an actuator or a
    boundary condition."""
    found = []
    for name, actuator in case.actuators.items():
        found += _frequencies(actuator.signal, f"actuators.{name}.signal")
    for i, bc in enumerate(case.boundary_conditions):
        found += _frequencies(getattr(bc, "value", None), f"boundary_conditions[{i}].value")
    return found


def _frequencies(value, key: str) -> list[tuple[str, float]]:
    """The ``frequency`` entries of a time function given as a mapping (nested ones too)."""
    if isinstance(value, dict):
        found = []
        for k, v in value.items():
            if k == "frequency" and isinstance(v, int | float) and not isinstance(v, bool):
                found.append((f"{key}.frequency", float(v)))
            else:
                found += _frequencies(v, f"{key}.{k}")
        return found
    if isinstance(value, list):
        return [item for i, v in enumerate(value) for item in _frequencies(v, f"{key}[{i}]")]
    return []
