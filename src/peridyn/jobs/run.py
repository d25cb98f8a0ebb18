"""Run a built case and write its results: explicit, static, Newton and Newmark runs (modal
runs are ``jobs.modal``), recording, checkpoints, crack history and the stored summary.
``run_case`` is what ``peridyn run`` calls."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from peridyn.discretization import geometry
from peridyn.discretization.body import Body
from peridyn.discretization.state import State
from peridyn.errors import CaseFileError, InputError
from peridyn.io.case import Case
from peridyn.io.checkpoint import Checkpointer, load_checkpoint
from peridyn.io.hdf5 import HDF5Writer
from peridyn.io.provenance import provenance
from peridyn.io.recorder import LineProbe, Recorder, RecorderSpec
from peridyn.jobs.build import Setup, build, pad3
from peridyn.jobs.figures import draw_crack_figures, draw_run_figures, final_crack_paths
from peridyn.jobs.lamb_analysis import analyse
from peridyn.jobs.summary import finish_summary
from peridyn.physics.absorbing import layer_damping
from peridyn.physics.damage import damage_field
from peridyn.physics.transducers import pzt_sensor_weights
from peridyn.solvers import ExplicitSolver, relax


def recorder_spec(case: Case, body: Body, dt: float) -> RecorderSpec:
    """What the case asks to record, with snapshot times turned into steps."""
    out = case.output
    planes = {name: body.node_set(set_name) for name, set_name in out.planes.items()}
    return RecorderSpec(
        every=out.every,
        snapshot_every=out.snapshot_every,
        snapshot_steps=[int(round(t / dt)) for t in out.snapshot_times],
        sensors={k: pad3(v) for k, v in out.sensors.items()},
        lines={k: LineProbe(pad3(v.start), pad3(v.end), v.points) for k, v in out.lines.items()},
        planes=planes,
        pzt_sensors={k: _pzt_weights(body, v) for k, v in out.pzt_sensors.items()},
        series_dtype=out.series_dtype,
        vtu=out.vtu,
    )


def _pzt_weights(body: Body, sensor) -> tuple[np.ndarray, np.ndarray]:
    """Point indices and (n, 2) weights of a PZT sensor patch on its layer."""
    idx = np.flatnonzero(geometry.layer(body, sensor.layer))
    weights = pzt_sensor_weights(body.points[idx], sensor.center, sensor.size, sensor.shape)
    used = np.any(weights != 0, axis=1)
    return idx[used], weights[used]


def output_directory(case: Case, override=None) -> Path:
    """The run's output folder: the override, the case's ``output.directory`` or peridyn-out/NAME."""
    if override is not None:
        return Path(override)
    return Path(case.output.directory or Path("peridyn-out") / case.name)


def run_case(
    case: Case,
    output_dir=None,
    case_path=None,
    checkpoint_every: int | None = None,
    restart: bool = False,
    progress=None,
    base_dir=".",
) -> dict:
    """Run a case and write its results; returns the summary (also stored in results.h5; keys
    in docs/user-guide.md, "Summaries and results files").

    Parameters
    ----------
    checkpoint_every : int or None
        Steps between checkpoints (``<output>/checkpoint.h5``).
    restart : bool
        Continue from ``<output>/checkpoint.h5`` (results after it are dropped and rewritten).
    progress : callable(total) -> bar with update(n) and close(), or None
    """
    start = time.perf_counter()
    setup = build(case, base_dir)
    out = output_directory(case, output_dir)
    out.mkdir(parents=True, exist_ok=True)
    plots = []
    if case.solver.type == "static":
        summary = _run_static(case, setup, out, case_path)
    elif case.solver.type == "newton":
        summary = _run_newton(case, setup, out, case_path)
    elif case.solver.type == "newmark":
        summary = _run_explicit(
            case,
            setup,
            out,
            case_path,
            checkpoint_every,
            restart,
            progress,
            solver=_newmark_solver(case, setup),
        )
    elif case.solver.type == "modal":
        from peridyn.jobs.modal import run_modal

        summary, plots = run_modal(case, setup, out, case_path)
    else:
        summary = _run_explicit(case, setup, out, case_path, checkpoint_every, restart, progress)
    analysis, figures = analyse(case, setup.body, out, plots=case.output.plots)
    summary.update(analysis)
    paths = (
        final_crack_paths(case, setup.body, damage_field(setup.model)) if setup.damage is not None else None
    )
    if paths is not None:
        summary["crack_paths"] = [p.summary() for p in paths]
    if case.output.plots and case.solver.type != "modal":  # a modal run draws its own
        plots = [*draw_run_figures(case, setup.body, out), *figures]
        if paths is not None:
            plots += draw_crack_figures(setup.body, out, paths, summary)
    finish_summary(summary, "modal" if case.solver.type == "modal" else "run", out, start, plots)
    store_summary(out / "results.h5", setup.body, summary)
    return summary


def store_summary(results, body: Body, summary: dict) -> None:
    """(Re)write the run summary in ``/summary/json`` of a results file."""
    with HDF5Writer(results, body.points[:, : body.dim], body.volumes, {}, mode="a") as h5:
        h5.write_summary(summary)


def _base_summary(setup: Setup) -> dict:
    phi = damage_field(setup.model)
    return {
        "points": setup.body.n_points,
        "bonds": setup.bonds.n_bonds,
        "broken_bonds": int((~setup.bonds.intact).sum()),
        "max_damage": float(phi.max()),
    }


def _run_explicit(case, setup, out, case_path, checkpoint_every, restart, progress, solver=None) -> dict:
    """Time integration by ``solver`` (default: velocity Verlet from the case) with recording."""
    s = case.solver
    if solver is None:
        solver = ExplicitSolver(
            setup.model,
            setup.loading,
            dt=s.dt,
            safety=s.safety,
            damping=explicit_damping(case, setup.body),
            damage=setup.damage,
            contact=setup.contact,
        )
    n_steps = s.steps if s.steps is not None else int(np.ceil(s.time / solver.dt - 1e-9))
    ckpt_path = out / "checkpoint.h5"
    if restart:
        state, intact = load_checkpoint(ckpt_path, setup.body.n_points, setup.bonds.n_bonds)
        setup.bonds.intact[:] = intact
        resume = (state.step, state.time)
    else:
        state, resume = solver.initial_state(), None
    spec = recorder_spec(case, setup.body, solver.dt)
    recorder = Recorder(setup.body, out, spec, provenance(case_path, case=case), setup.model, resume)
    if resume is None:
        recorder.record_series(state)
        recorder.snapshot(state)
    observers = [recorder]
    cracks = _crack_observer(case, setup, n_steps)
    if cracks is not None:
        observers.append(cracks)
    if checkpoint_every:
        observers.append(Checkpointer(ckpt_path, checkpoint_every, setup.bonds.intact))
    remaining = n_steps - state.step
    bar = progress(remaining) if progress is not None else None
    try:
        solver.run(state, remaining, observers, bar)
    finally:
        if bar is not None:
            bar.close()
    if state.step not in spec.snapshot_steps and not (
        spec.snapshot_every and state.step % spec.snapshot_every == 0
    ):
        recorder.snapshot(state)
    summary = _base_summary(setup)
    summary.update(
        {
            "steps": state.step,
            "time_s": state.time,
            "dt_s": solver.dt,
            "stable_dt_s": solver.stable_dt,
            "kinetic_energy_j": solver.kinetic_energy(state),
            "strain_energy_j": setup.model.strain_energy(state.u),
        }
    )
    if setup.contact is not None:
        summary["contact_rebuilds"] = setup.contact.rebuilds
    if cracks is not None:
        summary["crack_length_history"] = cracks.history()
    recorder.finish(state)
    return summary


def explicit_damping(case: Case, body: Body):
    """``solver.damping`` (1/s), plus the absorbing layers' per-point damping when the case
    has them: a number or an (n_points,) array for ``ExplicitSolver``."""
    if case.absorbing is None:
        return case.solver.damping
    a = case.absorbing
    try:
        return case.solver.damping + layer_damping(body.points, a.width, a.damping, a.faces)
    except InputError as exc:
        raise CaseFileError(case.name, "absorbing", a.model_dump(), str(exc)) from None


def _crack_observer(case, setup, n_steps):
    """Crack length against time, sampled at the snapshots (or 100 times a run) of a case
    with damage; None without damage."""
    if setup.damage is None:
        return None
    from peridyn.jobs.observers import CrackLengthObserver

    every = case.output.snapshot_every or max(1, n_steps // 100)
    return CrackLengthObserver(setup.model, every)


def _run_static(case, setup, out, case_path) -> dict:
    s = case.solver
    u = None
    iterations = 0
    for k in range(1, s.load_steps + 1):
        result = relax(
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
    return _record_equilibrium(
        case,
        setup,
        out,
        case_path,
        u,
        {"steps": s.load_steps, "iterations": iterations, "residual": result.residual},
    )


def _record_equilibrium(case, setup, out, case_path, u, results: dict) -> dict:
    """Record a quasi-static solution ``u`` as one state at t = 1 s; the run's summary."""
    state = State(u, np.zeros_like(u), np.zeros_like(u), 1.0, results["steps"])
    spec = recorder_spec(case, setup.body, 1.0)
    recorder = Recorder(setup.body, out, spec, provenance(case_path, case=case), setup.model)
    recorder.record_series(state)
    recorder.snapshot(state)
    summary = _base_summary(setup)
    summary.update(results)
    summary["strain_energy_j"] = setup.model.strain_energy(u)
    recorder.finish(state)
    return summary


def _newmark_solver(case, setup):
    """The implicit Newmark solver of a ``newmark`` case."""
    from peridyn.solvers.newmark import NewmarkSolver

    s = case.solver
    return NewmarkSolver(
        setup.model,
        setup.loading,
        dt=s.dt,
        tolerance=s.displacement_tolerance,
        max_iterations=s.newton_iterations,
        damping=s.damping,
        damage=setup.damage,
        linear_solver=s.linear_solver,
    )


def _run_newton(case, setup, out, case_path) -> dict:
    """Newton-Raphson equilibrium of a ``newton`` case, recorded as one state at t = 1 s."""
    from peridyn.solvers.newton import newton

    s = case.solver
    result = newton(
        setup.model,
        setup.loading,
        load_steps=s.load_steps,
        tolerance=s.tolerance,
        max_iterations=s.newton_iterations,
        damage=setup.damage,
        max_breaking_rounds=s.breaking_rounds,
        linear_solver=s.linear_solver,
    )
    if not result.converged:
        step = len(result.steps)
        raise InputError(
            f"Newton load step {step}/{s.load_steps} did not converge (residual "
            f"{result.residual:.3g}, tolerance {s.tolerance:g}, {s.newton_iterations} iterations, "
            f"{s.breaking_rounds} breaking rounds): raise solver.load_steps or "
            "solver.newton_iterations"
        )
    return _record_equilibrium(
        case,
        setup,
        out,
        case_path,
        result.u,
        {
            "steps": s.load_steps,
            "iterations": result.iterations,
            "residual": result.residual,
            "residual_history": [step.residuals for step in result.steps],
        },
    )
