"""Whole explicit steps of a case against its force kernel: ``peridyn bench --case CASE.yaml``.

The case is built as ``peridyn run`` builds it (``setup.build.build``, in one process), with
the solver ``setup.solver_choice.time_stepper`` makes and the observers ``peridyn run`` attaches: the
recorder of ``setup.recording.recorder_spec`` (series and snapshots, written to a temporary folder
deleted afterwards) and, with damage, the crack-length observer; no checkpoints. Then:

- the initial state and its first record, as a run makes them (not timed);
- one warm-up step with its observers (JIT compilation of the breaking test and the like);
- ``steps`` timed steps through ``ExplicitSolver.run``, the loop of ``peridyn run``: force,
  breaking test, contact, boundary conditions, actuators, damping (absorbing layers),
  integration, state checks and the observers. Their time is ``seconds``;
- the force evaluation alone, ``model.force(u, out)`` (the call of the solver's step), on the
  state after the timed steps: one warm-up call, then the best of ``repeat`` calls.

Rates are directed bond updates per second: ``bonds`` (all directed bonds, the kernel's loop)
per force evaluation, and ``bonds x steps / seconds`` for whole steps. ``step_share`` =
step rate / kernel rate, the kernel's share of a step (the target on
``cases/lamb_plate.yaml``: >= 0.85).

The breakdown of the timed steps (``parts``, s) comes from ``time.perf_counter`` around the
parts, with the solver's code unchanged: the model's ``force``, the damage's ``update`` and the
contact's ``add_force`` are wrapped on their instances, the observers by a timing observer;
``rest`` is what remains of the steps (integration, boundary conditions, actuators, damping,
checks, the loop).
"""

from __future__ import annotations

import os
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numba
import numpy as np

from peridyn.errors import InputError
from peridyn.io.case import Case
from peridyn.io.provenance import provenance
from peridyn.io.recorder import Recorder
from peridyn.io.results import Results
from peridyn.jobs.bench import best_seconds
from peridyn.jobs.bench_gpu import force_seconds
from peridyn.jobs.observers import crack_observer
from peridyn.parallel.observers import RootObservers
from peridyn.setup.build import build
from peridyn.setup.recording import RESULTS, check_output_fits, point_tensors, recorder_spec
from peridyn.setup.solver_choice import step_count, time_stepper
from peridyn.solvers.explicit_gpu import GPUExplicitSolver

#: Timed steps when ``--steps`` is not given: the case's own step count, at most this.
DEFAULT_MAX_STEPS = 200


class _Clock:
    """Seconds spent in wrapped callables, per part."""

    def __init__(self):
        self.seconds: dict[str, float] = {}

    def wrap(self, part: str, fn: Callable) -> Callable:
        """``fn`` with its time added to ``part``."""
        self.seconds.setdefault(part, 0.0)

        def timed(*args, **kwargs):
            t0 = time.perf_counter()
            try:
                return fn(*args, **kwargs)
            finally:
                self.seconds[part] += time.perf_counter() - t0

        return timed


class _TimedObserver:
    """An observer whose ``observe`` time goes to the clock's ``observers`` part; counts calls."""

    def __init__(self, observer, clock: _Clock):
        self.calls = 0
        self._observe = clock.wrap("observers", observer.observe)

    def observe(self, state, solver) -> None:
        self.calls += 1
        self._observe(state, solver)


def run_case_benchmark(
    case: Case,
    base_dir=".",
    case_path=None,
    steps: int | None = None,
    repeat: int = 10,
    log: Callable[[str], None] | None = None,
) -> dict:
    """Time a case's whole explicit steps and its force kernel; the ``peridyn bench --case`` dict.

    Parameters
    ----------
    case : Case
        An explicit case (``solver.type: explicit``), overrides applied.
    base_dir : path
        Folder that the case's relative paths (meshes) start from.
    case_path : path or None
        The case file, for the recorder's provenance.
    steps : int or None
        Timed steps; None: the case's own step count, at most ``DEFAULT_MAX_STEPS``.
    repeat : int
        Timed force evaluations after the warm-up; the best counts.
    log : callable or None
        Receives progress messages (the CLI sends them to stderr).

    Returns
    -------
    dict
        ``case``, ``backend`` (``solver.backend``: cpu or gpu, whose force kernel is timed),
        ``points``, ``bonds`` (directed), ``steps``, ``dt`` (s), ``seconds`` (the timed
        steps), ``kernel_seconds`` (best force evaluation), ``kernel_bond_updates_per_s``,
        ``step_bond_updates_per_s``, ``step_share``, ``parts`` (s: force, damage, contact,
        observers, rest; damage and contact only when the case has them), ``observer_calls``,
        ``records`` (series name -> records in the temporary results file, the initial
        and warm-up records included), ``threads``, ``cpus``, ``load_average`` (1, 5, 15 min).
    """
    if case.solver.type != "explicit":
        raise InputError(
            f"peridyn bench --case: only explicit cases are benchmarked, {case.name!r} is a "
            f"{case.solver.type} case"
        )
    if steps is not None and steps < 1:
        raise InputError(f"--steps must be at least 1, got {steps}")
    if repeat < 1:
        raise InputError(f"repeat must be at least 1, got {repeat}")
    say = log or (lambda msg: None)
    say(f"building case {case.name!r}")
    setup = build(case, base_dir)
    solver = time_stepper(case, setup)
    case_steps = step_count(case, solver)
    n_steps = steps if steps is not None else max(1, min(case_steps, DEFAULT_MAX_STEPS))
    bonds = int(setup.bonds.n_bonds)
    spec = recorder_spec(case, setup.whole_body, solver.dt)
    clock = _Clock()
    with tempfile.TemporaryDirectory(prefix="peridyn-bench-") as tmp:
        out = Path(tmp)
        check_output_fits(spec, setup.whole_body, n_steps + 1, solver.dt, out)
        gathered = RootObservers(setup.domain, setup.model)
        cracks = crack_observer(case, setup, case_steps, gathered.damage)
        recorder = Recorder(
            setup.whole_body,
            out,
            spec,
            provenance(case_path, case=case),
            gathered.damage,
            None,
            point_tensors(setup, spec),
        )
        try:
            gathered.attach(
                [recorder, *([cracks] if cracks is not None else [])],
                [spec.due, *([cracks.due] if cracks is not None else [])],
            )
            state = solver.initial_state()
            gathered.call(state, lambda whole: (recorder.record_series(whole), recorder.snapshot(whole)))
            say(f"{setup.body.n_points} points, {bonds} directed bonds, dt {solver.dt:.4g} s; warm-up step")
            solver.run(state, 1, [gathered])
            # the GPU solver calls no host force, breaking test or contact: only its observers are timed
            wrapped = [] if isinstance(solver, GPUExplicitSolver) else _wrap_parts(setup, clock)
            observer = _TimedObserver(gathered, clock)
            say(f"{n_steps} timed steps")
            t0 = time.perf_counter()
            try:
                solver.run(state, n_steps, [observer])
            finally:
                seconds = time.perf_counter() - t0
                for obj, name in wrapped:
                    delattr(obj, name)  # back to the class's method
        finally:
            gathered.detach()
            recorder.close()
        records = _record_counts(out / RESULTS)
    say("force kernel alone")
    if isinstance(solver, GPUExplicitSolver):  # the device's kernel, at the state on the device
        kernel_seconds = force_seconds(solver.force_on_device, solver.device_array("u"), repeat)
    else:
        kernel_seconds = _best_force(setup.model, state.u, repeat)
    parts = dict(clock.seconds)
    parts["rest"] = seconds - sum(parts.values())
    kernel_rate = bonds / kernel_seconds
    step_rate = bonds * n_steps / seconds
    return {
        "case": case.name,
        "backend": case.solver.backend,
        "points": int(setup.body.n_points),
        "bonds": bonds,
        "steps": int(n_steps),
        "dt": float(solver.dt),
        "seconds": float(seconds),
        "kernel_seconds": float(kernel_seconds),
        "kernel_bond_updates_per_s": float(kernel_rate),
        "step_bond_updates_per_s": float(step_rate),
        "step_share": float(step_rate / kernel_rate),
        "parts": {k: float(v) for k, v in parts.items()},
        "observer_calls": observer.calls,
        "records": records,
        "threads": int(numba.get_num_threads()),
        "cpus": os.cpu_count(),
        "load_average": list(os.getloadavg()),
    }


def _wrap_parts(setup, clock: _Clock) -> list[tuple[object, str]]:
    """Time the model's force, the damage's breaking test and the contact force through timing
    wrappers set on their instances (the solver calls them through these attributes); returns
    the (instance, attribute) pairs wrapped, for ``delattr`` afterwards."""
    parts = (
        ("force", setup.model, "force"),
        ("damage", setup.damage, "update"),
        ("contact", setup.contact, "add_force"),
    )
    wrapped = []
    for part, obj, name in parts:
        if obj is not None:
            setattr(obj, name, clock.wrap(part, getattr(obj, name)))
            wrapped.append((obj, name))
    return wrapped


def _best_force(model, u: np.ndarray, repeat: int) -> float:
    """Best time, s, of ``repeat`` evaluations of ``model.force(u, out=...)`` (the solver's call;
    ``u`` (n_points, 3), m) after one warm-up call."""
    out = np.empty_like(u, dtype=model.dtype)
    model.force(u, out=out)
    return best_seconds(lambda: model.force(u, out=out), repeat)


def _record_counts(path: Path) -> dict[str, int]:
    """Records of every series of a results file."""
    results = Results(path)
    return {name: results.n_records(name) for name in results.series_names()}


def format_case_result(result: dict) -> str:
    """Readable report of a :func:`run_case_benchmark` result."""
    seconds = result["seconds"]
    lines = [
        f"case {result['case']}: {result['points']} points, {result['bonds']} directed bonds, "
        f"{result['steps']} steps of {result['dt']:.4g} s, {result['threads']} numba threads, "
        f"load {result['load_average'][0]:.2f}",
        f"kernel alone  {result['kernel_bond_updates_per_s'] / 1e6:9.1f} M bond/s "
        f"({result['kernel_seconds'] * 1e3:.2f} ms per force evaluation)",
        f"whole step    {result['step_bond_updates_per_s'] / 1e6:9.1f} M bond/s "
        f"({seconds / result['steps'] * 1e3:.2f} ms per step, {seconds:.2f} s in all)",
        f"step share    {result['step_share']:9.2f} (kernel rate share reached by whole steps)",
        "",
        f"{'part':<10} {'s':>8} {'ms/step':>8} {'share':>6}",
    ]
    for part, s in result["parts"].items():
        lines.append(f"{part:<10} {s:>8.3f} {s / result['steps'] * 1e3:>8.3f} {s / seconds:>6.1%}")
    return "\n".join(lines)
