"""Run a built case and write its results: explicit, static, Newton and Newmark runs (modal
runs are ``jobs.modal``), recording, checkpoints, crack history and the stored summary.
``run_case`` is what ``peridyn run`` calls."""

from __future__ import annotations

import hashlib
import json
import sys
import time
from pathlib import Path

import numpy as np

from peridyn.discretization import geometry
from peridyn.discretization.body import Body
from peridyn.discretization.state import State
from peridyn.errors import CaseFileError, InputError, Interrupted
from peridyn.io.case import Case
from peridyn.io.checkpoint import Checkpointer, load_checkpoint
from peridyn.io.hdf5 import HDF5Writer
from peridyn.io.outdir import failure_status, prepare_output
from peridyn.io.provenance import package_version, provenance
from peridyn.io.recorder import LineProbe, Recorder, RecorderSpec
from peridyn.jobs.build import Setup, build, pad3
from peridyn.jobs.figures import draw_crack_figures, draw_run_figures, final_crack_paths
from peridyn.jobs.lamb_analysis import analyse
from peridyn.jobs.summary import finish_summary
from peridyn.physics.absorbing import layer_damping
from peridyn.physics.damage import damage_field
from peridyn.physics.transducers import pzt_sensor_weights
from peridyn.solvers import ExplicitSolver, relax

#: The results file in a run's output folder.
RESULTS = "results.h5"


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
    overwrite: bool = False,
    command: str | None = None,
) -> dict:
    """Run a case and write its results; returns the summary (also stored in results.h5; keys
    in docs/user-guide.md, "Summaries and results files").

    The case is built and every argument checked before the output folder is touched; a
    folder holding an earlier run's results.h5 is refused unless ``overwrite`` or ``restart``.
    results.h5 carries the run's status (``peridyn.io.outdir``).

    Parameters
    ----------
    checkpoint_every : int or None
        Steps between checkpoints (``<output>/checkpoint.h5``), >= 1.
    restart : bool
        Continue from ``<output>/checkpoint.h5`` (results after it are dropped and rewritten);
        the checkpoint must have been made by this case (``case_hash``), dt and peridyn version.
    progress : callable(total) -> bar with update(n) and close(), or None
    overwrite : bool
        Replace an earlier run's results in the output folder.
    command : str or None
        The command line that started the run, for the resume hint of ``Interrupted``.

    Raises
    ------
    Interrupted
        SIGINT or SIGTERM during the time stepping: the run stops after the current step,
        writes a checkpoint (when checkpointing, or after a minute of running) and closes
        its files with the status ``interrupted at step N``.
    """
    start = time.perf_counter()
    stepping = case.solver.type in ("explicit", "newmark")
    if checkpoint_every is not None and (not stepping or checkpoint_every < 1):
        raise InputError(
            f"--checkpoint-every must be a whole number of steps >= 1 for an explicit or newmark "
            f"run, got {checkpoint_every} for a {case.solver.type} run"
        )
    if restart and not stepping:
        raise InputError(f"--restart continues an explicit or newmark run, not a {case.solver.type} run")
    setup = build(case, base_dir)
    solver = _time_stepper(case, setup) if stepping else None
    out = prepare_output(output_directory(case, output_dir), RESULTS, overwrite, restart)
    written = not restart  # a restart writes once its checkpoint is accepted (the recorder's part)
    try:
        summary, plots = _solve(
            case, setup, solver, out, case_path, checkpoint_every, restart, progress, start
        )
        written = True
        _finish(case, setup, out, summary, plots, start)
    except Interrupted as exc:
        raise Interrupted(exc.signal_name, exc.step, _resume_hint(command) if exc.resume else "") from None
    except Exception as exc:
        if written:
            try:
                _set_status(out / RESULTS, setup.body, failure_status(exc))
            except Exception:  # noqa: BLE001 - e.g. the full disk that failed the run: its error is the one to report
                pass
        raise
    return summary


def _resume_hint(command: str | None) -> str:
    """How to continue an interrupted run."""
    if command is None:
        return "run_case(..., restart=True) with the same case and output folder"
    return command if "--restart" in command.split() else f"{command} --restart"


def _solve(case, setup, solver, out, case_path, checkpoint_every, restart, progress, start):
    """The solver's part of ``run_case``: its summary and the figures it drew."""
    if case.solver.type == "static":
        return _run_static(case, setup, out, case_path), []
    if case.solver.type == "newton":
        return _run_newton(case, setup, out, case_path), []
    if case.solver.type == "modal":
        from peridyn.jobs.modal import run_modal

        return run_modal(case, setup, out, case_path)
    summary = _run_explicit(case, setup, solver, out, case_path, checkpoint_every, restart, progress, start)
    return summary, []


def _finish(case, setup, out, summary, plots, start) -> None:
    """Analyses, figures and the stored summary after the solve; the status becomes complete."""
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
    store_summary(out / RESULTS, setup.body, summary, status="complete")


def case_identity(case: Case, run_length: bool = False) -> tuple[str, str]:
    """The validated case (after ``--set``) as JSON text without its output folder and, unless
    ``run_length`` (a sweep's runs differ by it), without its run length (``solver.steps``,
    ``solver.time``: a restart may extend a run), and the SHA-256 of that text."""
    data = case.model_dump(mode="json")
    if not run_length:
        for key in ("steps", "time"):
            data["solver"].pop(key, None)
    data["output"].pop("directory", None)
    text = json.dumps(data, sort_keys=True)
    return text, hashlib.sha256(text.encode()).hexdigest()


def _set_status(results: Path, body: Body, status: str) -> None:
    """Set the status of a results file (created if the job failed before writing one)."""
    with HDF5Writer(results, body.points[:, : body.dim], body.volumes, {}, mode="a") as h5:
        h5.set_status(status)


def store_summary(results, body: Body, summary: dict, status: str | None = None) -> None:
    """(Re)write the run summary in ``/summary/json`` of a results file, and its status when
    given."""
    with HDF5Writer(results, body.points[:, : body.dim], body.volumes, {}, mode="a") as h5:
        h5.write_summary(summary)
        if status is not None:
            h5.set_status(status)


def _base_summary(setup: Setup) -> dict:
    phi = damage_field(setup.model)
    return {
        "points": setup.body.n_points,
        "bonds": setup.bonds.n_bonds,
        "broken_bonds": int((~setup.bonds.intact).sum()),
        "max_damage": float(phi.max()),
    }


def _time_stepper(case, setup):
    """The solver of an explicit or newmark case (velocity Verlet or implicit Newmark)."""
    if case.solver.type == "newmark":
        return _newmark_solver(case, setup)
    s = case.solver
    return ExplicitSolver(
        setup.model,
        setup.loading,
        dt=s.dt,
        safety=s.safety,
        damping=explicit_damping(case, setup.body),
        damage=setup.damage,
        contact=setup.contact,
    )


#: Seconds of running after which an interrupted run writes a checkpoint even unasked.
CHECKPOINT_AFTER_S = 60.0


def _run_explicit(case, setup, solver, out, case_path, checkpoint_every, restart, progress, start) -> dict:
    """Time integration by ``solver`` with recording, checkpoints and the status."""
    s = case.solver
    n_steps = s.steps if s.steps is not None else int(np.ceil(s.time / solver.dt - 1e-9))
    ckpt_path = out / "checkpoint.h5"
    case_json, digest = case_identity(case)
    meta = {"case_hash": digest, "case": case_json, "dt": float(solver.dt), "version": package_version()}
    cracks = _crack_observer(case, setup, n_steps)
    parts = {
        name: part
        for name, part in (("damage", setup.damage), ("contact", setup.contact), ("cracks", cracks))
        if part is not None
    }
    if restart:
        state, intact, saved = load_checkpoint(ckpt_path, setup.body.n_points, setup.bonds.n_bonds, meta)
        setup.bonds.intact[:] = intact
        for name, part in parts.items():
            part.restore_state(saved.get(name, {}))
        resume = (state.step, state.time)
        print(
            f"restarting from the checkpoint at step {state.step} (t = {state.time:.6g} s)", file=sys.stderr
        )
    else:
        state, resume = solver.initial_state(), None
    spec = recorder_spec(case, setup.body, solver.dt)
    recorder = Recorder(setup.body, out, spec, provenance(case_path, case=case), setup.model, resume)
    checkpointer = Checkpointer(ckpt_path, checkpoint_every or n_steps + 1, setup.bonds.intact, meta, parts)
    try:
        if resume is None:
            recorder.record_series(state)
            recorder.snapshot(state)
        observers = [recorder, *([cracks] if cracks is not None else [])]
        if checkpoint_every:
            observers.append(checkpointer)
        remaining = n_steps - state.step
        bar = progress(remaining) if progress is not None else None
        try:
            solver.run(state, remaining, observers, bar)
        finally:
            if bar is not None:
                bar.close()
    except Interrupted as exc:
        saved = bool(checkpoint_every) or time.perf_counter() - start > CHECKPOINT_AFTER_S
        if saved:
            checkpointer.save(state)
        recorder.close(f"interrupted at step {exc.step}")
        raise Interrupted(exc.signal_name, exc.step, "resume" if saved else "") from None
    except BaseException as exc:
        recorder.close(failure_status(exc))
        raise
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
