"""The quasi-static runs of a case: dynamic relaxation or modified Newton (``static``) and
Newton-Raphson (``newton``), each recorded as one state (``run_static``, ``run_newton``,
called by ``run_case``)."""

from __future__ import annotations

import numpy as np

from peridyn.discretization.state import State
from peridyn.errors import InputError
from peridyn.io.recorder import Recorder
from peridyn.io.vtu_pieces import VtuPieces
from peridyn.jobs.context import RunContext
from peridyn.jobs.summary import base_summary
from peridyn.parallel.observers import RootObservers
from peridyn.physics.damage import damage_field
from peridyn.setup.build import Setup
from peridyn.setup.recording import exodus_values, point_tensors, recorder_spec
from peridyn.setup.solver_choice import static_solver
from peridyn.solvers import ExplicitSolver


def run_static(ctx: RunContext, setup: Setup) -> dict:
    """Equilibrium of a ``static`` case in ``solver.load_steps`` load steps, recorded as one
    state at t = 1 s; the run's summary."""
    case = ctx.case
    s = case.solver
    u = None
    iterations = 0
    solve = static_solver(setup)
    for k in range(1, s.load_steps + 1):
        result = solve(
            setup.model,
            setup.loading,
            time=k / s.load_steps,
            u0=u,
            tolerance=s.tolerance,
            max_iterations=s.max_iterations,
            damage=setup.damage,
            contact=setup.contact,
        )
        u, iterations = result.u, iterations + result.iterations
        if not result.converged:
            raise InputError(
                f"static load step {k}/{s.load_steps} did not converge in {s.max_iterations} "
                f"iterations (residual {result.residual:.3g} > {s.tolerance:g}): raise "
                "solver.max_iterations or solver.load_steps"
            )
    results = {"steps": s.load_steps, "iterations": iterations, "residual": result.residual}
    if setup.contact is not None:
        results["contact_rebuilds"] = setup.contact.rebuilds
    return _record_equilibrium(ctx, setup, u, results)


def _equilibrium_recorder(ctx: RunContext, setup: Setup) -> Recorder:
    """The recorder of a quasi-static run."""
    case = ctx.case
    spec = recorder_spec(case, setup.body, 1.0)
    return Recorder(
        setup.body,
        ctx.out,
        spec,
        ctx.provenance(),
        lambda: damage_field(setup.model),
        tensors=point_tensors(setup, spec),
        fields=exodus_values(case, setup, spec),
    )


def _record_equilibrium(ctx: RunContext, setup: Setup, u, results: dict, recorder=None, time=1.0) -> dict:
    """Record a quasi-static solution ``u`` as one state at ``time`` (s; ``recorder``: the
    run's, else a new one); the run's summary."""
    state = State(u, np.zeros_like(u), np.zeros_like(u), time, results["steps"])
    if setup.domain.size > 1:
        return _record_distributed_equilibrium(ctx, setup, state, results)
    if recorder is None:
        recorder = _equilibrium_recorder(ctx, setup)
    return _record_last(setup, recorder, state, results)


def _record_last(setup: Setup, recorder: Recorder, state: State, results: dict) -> dict:
    """Record ``state`` as the run's last (series, snapshot, final fields) and close
    ``recorder``; the run's summary, ``results`` added (one process)."""
    recorder.record_series(state)
    recorder.snapshot(state)
    summary = base_summary(setup)
    summary.update(results)
    summary["strain_energy_j"] = setup.model.strain_energy(state.u)
    recorder.finish(state)
    return summary


def _record_distributed_equilibrium(ctx: RunContext, setup: Setup, state: State, results: dict) -> dict:
    """``_record_equilibrium`` under MPI: ``state`` of the rank's part (ghost rows filled), gathered
    on rank 0, which records it as a serial run would (VTU snapshots in per-rank pieces); the
    summary (collective)."""
    d = setup.domain
    case, out = ctx.case, ctx.out
    spec = recorder_spec(case, setup.whole_body, 1.0)
    tensors = point_tensors(setup, spec)
    gathered = RootObservers(d, setup.model, tensors)
    info = ctx.provenance()
    info.update(d.provenance())
    if spec.vtu:
        VtuPieces(d, setup.body, out, lambda: damage_field(setup.model), tensors).write(state)
    whole_tensors = gathered.tensor_fields if tensors is not None else None
    recorder = d.on_root(
        Recorder, setup.whole_body, out, spec, info, gathered.damage, None, whole_tensors, None, True
    )
    gathered.call(state, lambda whole: (recorder.record_series(whole), recorder.snapshot(whole)), True)
    summary = base_summary(setup)
    summary.update(results)
    n = d.n_owned
    summary["strain_energy_j"] = float(d.dot(setup.model.energy_density(state.u)[:n], setup.body.volumes[:n]))
    gathered.call(state, lambda whole: recorder.finish(whole), True)
    return summary


def run_newton(ctx: RunContext, setup: Setup) -> dict:
    """Newton-Raphson equilibrium of a ``newton`` case, recorded as one state at t = 1 s; the
    run's summary."""
    case = ctx.case
    from peridyn.solvers.newton import newton

    s = case.solver
    end = s.time if s.time is not None else 1.0
    recorder = _equilibrium_recorder(ctx, setup)
    last: dict = {}  # the last load step's u and v (``_load_step_records``)
    on_step = _load_step_records(recorder, setup.loading, end / s.load_steps, last)
    result = newton(
        setup.model,
        setup.loading,
        load_steps=s.load_steps,
        time=end,
        tolerance=s.tolerance,
        max_iterations=s.newton_iterations,
        damage=setup.damage,
        max_breaking_rounds=s.breaking_rounds,
        linear_solver=s.linear_solver,
        absolute_tolerance=s.absolute_tolerance,
        on_step=on_step,
    )
    if not result.converged:
        step = len(result.steps)
        raise InputError(
            f"Newton load step {step}/{s.load_steps} did not converge (residual "
            f"{result.residual:.3g}, tolerance {s.tolerance:g}, {s.newton_iterations} iterations, "
            f"{s.breaking_rounds} breaking rounds): raise solver.load_steps or "
            "solver.newton_iterations"
        )
    results = {
        "steps": s.load_steps,
        "iterations": result.iterations,
        "residual": result.residual,
        "residual_history": [step.residuals for step in result.steps],
    }
    if s.then is None:
        return _record_equilibrium(ctx, setup, result.u, results, recorder, end)
    state = _explicit_stage(setup, recorder, s.then, result.u, last["v"], end, s.load_steps + 1)
    return _record_last(setup, recorder, state, results | {"steps": state.step, "time_s": state.time})


def _explicit_stage(setup: Setup, recorder: Recorder, stage, u, v, time: float, first_step: int) -> State:
    """Run ``stage`` (``ExplicitStage``) from displacement ``u`` and velocity ``v``
    (n_points, 3; m, m/s) at ``time`` (s), its first state numbered ``first_step``, writing the
    Exodus records due at its steps; its last state."""
    stepper = ExplicitSolver(
        setup.model,
        setup.loading,
        dt=stage.dt,
        damage=setup.damage,
        contact=setup.contact,
        prescribed_velocity=stage.prescribed_velocity,
    )
    state = stepper.continued_state(u, v, time, first_step)
    records = _ExodusRecords(recorder)
    records.observe(state)
    return stepper.run(state, stage.steps, [records])


class _ExodusRecords:
    """A time stepper's observer writing the Exodus records due at each step
    (``RecorderSpec.exodus_due``)."""

    def __init__(self, recorder: Recorder):
        self.recorder = recorder

    def observe(self, state: State, solver=None) -> None:
        if self.recorder.spec.exodus_due(state.step):
            self.recorder.write_exodus(state)


def _load_step_records(recorder: Recorder, loading, step_time: float, last: dict):
    """Newton's ``on_step`` writing the Exodus records that ``output.exodus`` asks at its load
    steps (with the state at t = 0 first), as Peridigm's quasi-static solver writes them: the
    load step as the step, velocity the displacement's change over the step's time
    ``step_time`` (s), acceleration zero; at t = 0 the initial conditions. ``last`` (IN/OUT,
    ``u`` and ``v``, (n_points, 3)) holds the last load step's displacement and velocity (an
    Exodus file written at the end only gets no records here)."""
    spec = recorder.spec
    u0, v0, zero = (np.zeros((loading.body.n_points, 3)) for _ in range(3))
    loading.apply_initial(u0, v0)
    if spec.exodus_every is not None:
        recorder.write_exodus(State(u0, v0, zero, 0.0, 0))
    last["u"] = u0

    def on_step(step, u):
        k = int(round(step.time / step_time))
        last["v"] = (u - last["u"]) / step_time
        if spec.exodus_every is not None and spec.exodus_due(k):
            recorder.write_exodus(State(u, last["v"], zero, step.time, k))
        last["u"] = u.copy()

    return on_step
