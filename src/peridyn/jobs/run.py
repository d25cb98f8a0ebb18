"""Run a built case and write its results: explicit, static, Newton and Newmark runs (modal
runs are ``jobs.modal``), recording, checkpoints, crack history and the stored summary.
``run_case`` is what ``peridyn run`` calls."""

from __future__ import annotations

import contextlib
import logging
import time
from pathlib import Path

import numpy as np

from peridyn import interrupts
from peridyn.discretization.body import Body
from peridyn.discretization.state import State
from peridyn.errors import InputError, Interrupted
from peridyn.io.case import Case
from peridyn.io.checkpoint import Checkpointer, load_checkpoint
from peridyn.io.hdf5 import HDF5Writer
from peridyn.io.lock import OutputLock
from peridyn.io.outdir import RUN_OUTPUTS, end_status, prepare_output
from peridyn.io.provenance import package_version, provenance
from peridyn.io.recorder import Probes, Recorder
from peridyn.io.reserve import RESERVE_FILE
from peridyn.io.run_log import run_log
from peridyn.io.vtu_pieces import VtuPieces
from peridyn.jobs.figure_worker import figure_worker_for, figures_of, submit
from peridyn.jobs.figures import draw_crack_figures, draw_run_figures, final_crack_paths
from peridyn.jobs.lamb_analysis import analyse
from peridyn.jobs.observers import crack_observer
from peridyn.jobs.summary import finish_summary, peak_memory_bytes
from peridyn.parallel.observers import RootObservers
from peridyn.physics.damage import damage_field
from peridyn.setup.build import Setup, build
from peridyn.setup.estimate import check_memory
from peridyn.setup.exodus_variables import GatheredVariables
from peridyn.setup.identity import case_identity
from peridyn.setup.recording import (
    RESULTS,
    check_output_fits,
    exodus_values,
    output_directory,
    point_tensors,
    recorder_spec,
)
from peridyn.setup.run_checks import check_run_plan
from peridyn.setup.solver_choice import (
    check_parallel,
    static_solver,
    step_count,
    time_stepper,
)
from peridyn.solvers.explicit_gpu import GPUExplicitSolver

logger = logging.getLogger(__name__)


@interrupts.deferred()
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
    comm=None,
    figure_worker: bool = False,
    max_memory: float | None = None,
) -> dict:
    """Run a case and write its results; returns the summary (also stored in results.h5; keys
    in docs/user-guide.md, "Summaries and results files").

    The case and every argument are checked before anything of the case's size is allocated
    (its memory estimate, ``setup.estimate.check_memory``), the case is built and its time step
    and records checked (the model's stable step, the records against the free disk) before
    the output folder is touched; a folder holding an earlier run's results.h5 is refused
    unless ``overwrite`` or ``restart``.
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
        The command line that started the run, for the resume hint of ``Interrupted``; ""
        for a command that cannot be restarted (``peridyn demo``): no hint of ``--restart``.
    comm : communicator or None
        ``peridyn.parallel.comm.world()`` under ``mpiexec -n N`` (N > 1): each rank runs its
        part of the body (``peridyn.parallel``), rank 0 writes the one results.h5 with every
        record equal to a serial run's, and every rank returns the summary. An explicit run,
        or a static run with bond breaking or contact (dynamic relaxation on each rank's part),
        bit for bit; a static run without them (modified Newton with CG) and a modal run, to the
        solver tolerance. Checkpoints hold the whole body, so a run may restart on another
        number of ranks. None: one process.
    figure_worker : bool
        Draw the run figures in a second process while this one analyses the records
        (``peridyn.jobs.figure_worker``: one process on two or more numba threads, a body of
        ``MIN_POINTS`` or more). What ``peridyn run`` does; a script that asks for it must
        guard its own run with ``if __name__ == "__main__":``, as every program that starts
        processes by ``spawn`` must.
    max_memory : float or None
        Bytes the job may hold (default: the machine's, ``discretization.geometry.memory_limit``):
        a case whose estimated peak exceeds it is refused before it is built.

    Raises
    ------
    Interrupted
        SIGINT or SIGTERM (noted, then acted on at the next safe point: ``peridyn.interrupts``).
        During the time stepping the run stops after the current step, writes a checkpoint
        (when checkpointing, or after a minute of running) and closes its files with the
        status ``interrupted at step N``; a static, Newton or modal run stops within an
        iteration of its solver (status ``interrupted while ...``); during the build nothing
        has been written yet.
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
    parallel = comm is not None and comm.size > 1
    if parallel:
        check_parallel(case)
    check_memory(case, max_memory, base_dir)
    wanted = figure_worker and _draws_run_figures(case) and not parallel
    with figure_worker_for(case, base_dir, wanted) as worker, contextlib.ExitStack() as held:
        setup = build(case, base_dir, comm)
        domain = setup.domain
        solver = time_stepper(case, setup) if stepping else None
        out = output_directory(case, output_dir)
        spec = recorder_spec(case, setup.whole_body, solver.dt) if stepping else None
        if stepping:
            n_steps = step_count(case, solver)
            check_run_plan(case, solver.dt, n_steps)
            damage = setup.damage is not None
            domain.on_root(check_output_fits, spec, setup.whole_body, n_steps, solver.dt, out, damage)
        lock = domain.on_root(OutputLock, out)  # one run writes a folder at a time
        if lock is not None:
            held.callback(lock.release)
            held.callback((out / RESERVE_FILE).unlink, missing_ok=True)  # a recorder's ``Reserve``
        domain.on_root(prepare_output, out, RESULTS, overwrite, restart, RUN_OUTPUTS, command != "")
        held.enter_context(run_log(out, domain.is_root))
        logger.info(f"case {case.name!r} ({case.solver.type}, {setup.whole_body.n_points} points) into {out}")
        written = not restart  # a restart writes once its checkpoint is accepted (the recorder's part)
        try:
            summary, plots = _solve(
                case, setup, solver, spec, out, case_path, checkpoint_every, restart, progress, start
            )
            written = True
            _finish(case, setup, out, summary, plots, start, worker)
            logger.info(f"case {case.name!r} complete in {time.perf_counter() - start:.1f} s")
        except Exception as exc:
            logger.warning(f"case {case.name!r}: {end_status(exc)}")
            if written and domain.is_root:
                (out / RESERVE_FILE).unlink(missing_ok=True)  # room for the status on a full disk
                try:
                    _set_status(out / RESULTS, setup.whole_body, end_status(exc))
                except Exception:  # noqa: BLE001 - e.g. the full disk that failed the run: its error is the one to report
                    pass
            if isinstance(exc, Interrupted):
                hint = _resume_hint(command) if exc.resume else ""
                raise Interrupted(exc.signal_name, exc.step, hint, exc.where) from None
            raise
        return domain.comm.bcast(summary)


def _resume_hint(command: str | None) -> str:
    """How to continue an interrupted run."""
    if command is None:
        return "run_case(..., restart=True) with the same case and output folder"
    if not command:
        return ""
    return command if "--restart" in command.split() else f"{command} --restart"


def _solve(case, setup, solver, spec, out, case_path, checkpoint_every, restart, progress, start):
    """The solver's part of ``run_case``: its summary and the figures it drew (``spec``: the
    recorder's, for a time-stepping run)."""
    if case.solver.type == "static":
        return _run_static(case, setup, out, case_path), []
    if case.solver.type == "newton":
        return _run_newton(case, setup, out, case_path), []
    if case.solver.type == "modal":
        from peridyn.jobs.modal import run_modal

        return run_modal(case, setup, out, case_path)
    summary = _run_explicit(
        case, setup, solver, spec, out, case_path, checkpoint_every, restart, progress, start
    )
    return summary, []


def _draws_run_figures(case: Case) -> bool:
    """Whether the run ends with ``draw_run_figures`` (a modal run draws its own)."""
    return case.output.plots and case.solver.type != "modal"


def _finish(case, setup, out, summary, plots, start, worker=None) -> None:
    """Analyses, figures and the stored summary after the solve; the status becomes complete
    (on rank 0, with the damage of the whole body). ``worker``: a figure worker
    (``figure_worker_for``) that draws the run figures while this process analyses."""
    d = setup.domain
    phi = d.gather(damage_field(setup.model)) if setup.damage is not None else None
    d.on_root(_finish_on_root, case, setup.whole_body, out, summary, plots, start, phi, worker)


def _finish_on_root(case, body, out, summary, plots, start, phi, worker=None) -> None:
    """``_finish`` on rank 0: ``body`` the whole body, ``phi`` its damage (None without damage)."""
    draw = _draws_run_figures(case)
    pending = submit(worker, draw_run_figures, case, body, out) if draw else None
    analysis, figures = analyse(case, body, out, plots=case.output.plots)
    summary.update(analysis)
    paths = final_crack_paths(case, body, phi) if phi is not None else None
    if paths is not None:
        summary["crack_paths"] = [p.summary() for p in paths]
    if draw:
        plots = [*figures_of(pending, draw_run_figures, case, body, out), *figures]
        if paths is not None:
            plots += draw_crack_figures(body, out, paths, summary)
    finish_summary(summary, "modal" if case.solver.type == "modal" else "run", out, start, plots)
    store_summary(out / RESULTS, body, summary, status="complete")


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
    """Points, directed bonds, broken bonds and largest damage of the whole body (collective)."""
    d = setup.domain
    n = d.n_owned
    phi = damage_field(setup.model)
    if setup.storage == "lattice":  # one process
        bonds, broken = setup.bonds.n_bonds, setup.bonds.n_broken()
    else:
        owned_bonds = int(setup.bonds.offsets[n])  # the owned points' families come first
        bonds, broken = d.count(owned_bonds), d.count((~setup.bonds.intact[:owned_bonds]).sum())
    return {
        "points": setup.whole_body.n_points,
        "bonds": bonds,
        "broken_bonds": broken,
        "max_damage": float(d.max(phi[:n].max())),
        "storage": setup.storage,
    }


def bond_state(setup: Setup) -> tuple[np.ndarray, np.ndarray]:
    """(array, offsets): the bonds' state that a checkpoint saves and a restart writes back in
    place, with its CSR family ``offsets``: the intact mask of bond lists, or the broken words
    of a lattice (flat, ``offsets`` [0, their number]: one process)."""
    if setup.storage == "lattice":
        words = setup.bonds.broken.reshape(-1)
        return words, np.array([0, len(words)])
    return setup.bonds.intact, setup.bonds.offsets


#: Seconds of running after which an interrupted run writes a checkpoint even unasked.
CHECKPOINT_AFTER_S = 60.0


def _run_explicit(
    case, setup, solver, spec, out, case_path, checkpoint_every, restart, progress, start
) -> dict:
    """Time integration by ``solver`` with recording by ``spec`` (``recorder_spec``),
    checkpoints and the status."""
    d = setup.domain
    n_steps = step_count(case, solver)
    ckpt_path = out / "checkpoint.h5"
    case_json, digest = case_identity(case)
    meta = {"case_hash": digest, "case": case_json, "dt": float(solver.dt), "version": package_version()}
    spec = recorder_spec(case, setup.whole_body, solver.dt)
    tensors = point_tensors(setup, spec)
    gathered = RootObservers(d, setup.model, tensors)
    cracks = crack_observer(case, setup, n_steps, gathered.damage)
    parts = {
        name: part
        for name, part in (("damage", setup.damage), ("contact", setup.contact), ("cracks", cracks))
        if part is not None
    }
    whole_bonds = d.bond_offsets(bond_state(setup)[1])
    if restart:
        state = _restart(ckpt_path, setup, meta, parts, whole_bonds, n_steps, out / RESULTS)
        resume = (state.step, state.time)
        logger.info(f"restarting from the checkpoint at step {state.step} (t = {state.time:.6g} s)")
    else:
        state, resume = solver.initial_state(), None
    info = provenance(case_path, case=case)
    if d.size > 1:
        info.update(d.provenance())
    pieces = None  # under MPI, each rank writes its piece of the VTU snapshots
    if d.size > 1 and spec.vtu:
        pieces = VtuPieces(
            d, setup.body, out, lambda: damage_field(setup.model), tensors, spec.vtu_compression
        )
    if d.size > 1 and tensors is not None:
        tensors = gathered.tensor_fields
    fields = exodus_values(case, setup, spec)
    probes = Probes.of(setup.whole_body, spec)  # every rank: under MPI, gathered at a series record
    recorder = d.on_root(
        Recorder,
        setup.whole_body,
        out,
        spec,
        info,
        gathered.damage,
        resume,
        tensors,
        fields,
        d.size > 1,
        probes,
    )
    checkpointer, gather_checkpoint = _checkpointer(
        ckpt_path,
        checkpoint_every or n_steps + 1,
        setup,
        meta,
        parts,
        whole_bonds,
        [recorder.flush] if recorder is not None else [],
        recorder.h5.identity if recorder is not None else None,
    )
    watched = [recorder, *([cracks] if cracks is not None else [])]
    due = [spec.whole_due, *([cracks.due] if cracks is not None else [])]  # the series: ``series``
    if d.size > 1 and checkpoint_every:  # saved on rank 0 from the gathered state
        watched, due = [*watched, checkpointer], [*due, checkpointer.due]
    prepare = gather_checkpoint
    if pieces is not None:
        prepare = [*prepare, (spec.snapshot_due, pieces.write)]
    collect = fields.collect if isinstance(fields, GatheredVariables) else lambda state: None
    if isinstance(fields, GatheredVariables):
        prepare = [*prepare, (spec.exodus_due, collect)]
    damage_due = [spec.snapshot_due, spec.exodus_due, *([cracks.due] if cracks is not None else [])]
    record = recorder.record_series if recorder is not None else None
    try:
        if resume is None:
            if pieces is not None:
                pieces.write(state)
            collect(state)
            gathered.call(state, lambda whole: (recorder.record_series(whole), recorder.snapshot(whole)))
        observers = [gathered]
        if checkpoint_every and d.size == 1:
            observers.append(checkpointer)
        remaining = n_steps - state.step
        bar = progress(remaining) if progress is not None else None
        traffic = d.comm.traffic.copy()
        loop_start = time.perf_counter()
        try:
            series = (spec.series_due, probes.u_points, probes.v_points, record)
            # the GPU backend's state is on the device: a series-only step reads the probe points only
            device_probes = solver.probe_values if isinstance(solver, GPUExplicitSolver) else None
            gathered.attach(watched, due, prepare, damage_due, series, device_probes)
            solver.run(state, remaining, observers, bar)
        finally:
            gathered.detach()
            if bar is not None:
                bar.close()
        loop_seconds = time.perf_counter() - loop_start
        step_seconds = d.max(loop_seconds)
    except Interrupted as exc:  # under MPI: on every rank after the same step
        saved = bool(checkpoint_every) or time.perf_counter() - start > CHECKPOINT_AFTER_S
        saved = bool(d.max(int(saved)))  # the ranks' clocks differ: all save if one would
        if saved and d.size == 1:
            checkpointer.save(state)
        elif saved:
            for _, gather in gather_checkpoint:
                gather(state)
            gathered.call(state, checkpointer.save)
        if recorder is not None:
            recorder.close(f"interrupted at step {exc.step}")
        raise Interrupted(exc.signal_name, exc.step, "resume" if saved else "") from None
    except BaseException as exc:
        if recorder is not None:
            recorder.close(end_status(exc))
        raise
    try:
        collect(state)  # the end-of-run snapshot's Exodus record
        if not spec.snapshot_due(state.step):
            if pieces is not None:
                pieces.write(state)
            gathered.call(state, lambda whole: recorder.snapshot(whole))
    except BaseException as exc:  # e.g. a full disk: the records held are written, the file closed
        if recorder is not None:
            recorder.close(end_status(exc))
        raise
    n = d.n_owned
    summary = _base_summary(setup)
    summary.update(
        {
            "steps": state.step,
            "time_s": state.time,
            "dt_s": solver.dt,
            "stable_dt_s": solver.stable_dt,
            "kinetic_energy_j": solver.kinetic_energy(state),
            "strain_energy_j": float(d.dot(setup.model.energy_density(state.u)[:n], setup.body.volumes[:n])),
            "step_seconds": step_seconds,
        }
    )
    if d.size > 1:
        summary["mpi"] = {
            **{key: info[key] for key in d.provenance_keys},
            "per_rank": d.traffic_per_rank(traffic, remaining, loop_seconds),
        }
        peaks = d.comm.allgather(peak_memory_bytes())  # so far: the build and the time loop
        for rank, peak in zip(summary["mpi"]["per_rank"], peaks, strict=True):
            rank["peak_memory_bytes"] = peak
    if setup.contact is not None:
        summary["contact_rebuilds"] = setup.contact.rebuilds
    if cracks is not None:
        summary["crack_length_history"] = cracks.history()  # rank 0's is the one returned
    gathered.call(state, lambda whole: recorder.finish(whole), True)
    return summary


def _restart(
    path, setup: Setup, meta: dict, parts: dict, whole_bonds: np.ndarray, n_steps: int, results
) -> State:
    """The state of the checkpoint at ``path`` (this rank's points), with the bonds' intact mask
    and the parts' states restored; a checkpoint at or past the run's last step ``n_steps`` is
    refused (before the recorder reopens, and would rewrite, results.h5). Checkpoints hold the
    whole body in serial numbering, so a run may restart on another number of ranks. A rank's
    damage skin covers its part only and is not saved under MPI: it starts again with a full
    stretch test (the same bonds break, see ``peridyn.physics.damage``). The results file
    ``results`` must be the one the checkpoint was saved with (``check_results``)."""
    d = setup.domain
    state, intact, saved = d.agree(
        load_checkpoint, path, setup.whole_body.n_points, int(whole_bonds[-1]), meta, results
    )
    if state.step >= n_steps:
        raise InputError(
            f"--restart: the checkpoint is at step {state.step} and the run ends at step {n_steps}: "
            "nothing is left to run (a longer solver.time or solver.steps continues it)"
        )
    if d.size > 1:
        ids = d.global_ids
        state = State(state.u[ids], state.v[ids], state.a[ids], state.time, state.step)
    bond_state(setup)[0][:] = d.scatter_bonds(intact, setup.bonds, whole_bonds)
    for name, part in parts.items():
        part.restore_state(saved.get(name, {}) if d.size == 1 or name != "damage" else {})
    return state


def _checkpointer(
    path,
    every: int,
    setup: Setup,
    meta: dict,
    parts: dict,
    whole_bonds: np.ndarray,
    before_save=(),
    results=None,
):
    """The run's ``Checkpointer`` and what must be gathered before it saves (``RootObservers``):
    under MPI it writes, on rank 0, the whole body's state and intact mask in serial numbering
    and the parts that hold whole-body state (the contact list's build displacement, gathered;
    not a rank's damage skin). ``before_save``: the calls made before every save (the
    recorder's ``flush``, on rank 0); ``results``: the identity of the results file
    (``HDF5Writer.identity``, on rank 0)."""
    d = setup.domain
    if d.size == 1:
        return Checkpointer(path, every, bond_state(setup)[0], meta, parts, before_save, results), []
    whole_intact = np.ones(int(whole_bonds[-1]), dtype=bool) if d.is_root else None
    checkpointer = Checkpointer(
        path,
        every,
        whole_intact,
        meta,
        {k: v for k, v in parts.items() if k != "damage"},
        before_save,
        results,
    )

    def gather_whole(state):  # the state itself is gathered by RootObservers.call
        intact = d.gather_bonds(setup.bonds.intact, setup.bonds.offsets, whole_bonds)
        if d.is_root:
            whole_intact[:] = intact
        if setup.contact is not None:
            setup.contact.gather_built()

    return checkpointer, [(checkpointer.due, gather_whole)]


def _run_static(case, setup, out, case_path) -> dict:
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
    return _record_equilibrium(case, setup, out, case_path, u, results)


def _equilibrium_recorder(case, setup, out, case_path) -> Recorder:
    """The recorder of a quasi-static run."""
    spec = recorder_spec(case, setup.body, 1.0)
    return Recorder(
        setup.body,
        out,
        spec,
        provenance(case_path, case=case),
        lambda: damage_field(setup.model),
        tensors=point_tensors(setup, spec),
        fields=exodus_values(case, setup, spec),
    )


def _record_equilibrium(case, setup, out, case_path, u, results: dict, recorder=None, time=1.0) -> dict:
    """Record a quasi-static solution ``u`` as one state at ``time`` (s; ``recorder``: the
    run's, else a new one); the run's summary."""
    state = State(u, np.zeros_like(u), np.zeros_like(u), time, results["steps"])
    if setup.domain.size > 1:
        return _record_distributed_equilibrium(case, setup, out, case_path, state, results)
    if recorder is None:
        recorder = _equilibrium_recorder(case, setup, out, case_path)
    recorder.record_series(state)
    recorder.snapshot(state)
    summary = _base_summary(setup)
    summary.update(results)
    summary["strain_energy_j"] = setup.model.strain_energy(u)
    recorder.finish(state)
    return summary


def _record_distributed_equilibrium(case, setup, out, case_path, state: State, results: dict) -> dict:
    """``_record_equilibrium`` under MPI: ``state`` of the rank's part (ghost rows filled), gathered
    on rank 0, which records it as a serial run would (VTU snapshots in per-rank pieces); the
    summary (collective)."""
    d = setup.domain
    spec = recorder_spec(case, setup.whole_body, 1.0)
    tensors = point_tensors(setup, spec)
    gathered = RootObservers(d, setup.model, tensors)
    info = provenance(case_path, case=case)
    info.update(d.provenance())
    if spec.vtu:
        VtuPieces(d, setup.body, out, lambda: damage_field(setup.model), tensors).write(state)
    whole_tensors = gathered.tensor_fields if tensors is not None else None
    recorder = d.on_root(
        Recorder, setup.whole_body, out, spec, info, gathered.damage, None, whole_tensors, None, True
    )
    gathered.call(state, lambda whole: (recorder.record_series(whole), recorder.snapshot(whole)), True)
    summary = _base_summary(setup)
    summary.update(results)
    n = d.n_owned
    summary["strain_energy_j"] = float(d.dot(setup.model.energy_density(state.u)[:n], setup.body.volumes[:n]))
    gathered.call(state, lambda whole: recorder.finish(whole), True)
    return summary


def _run_newton(case, setup, out, case_path) -> dict:
    """Newton-Raphson equilibrium of a ``newton`` case, recorded as one state at t = 1 s."""
    from peridyn.solvers.newton import newton

    s = case.solver
    end = s.time if s.time is not None else 1.0
    recorder = _equilibrium_recorder(case, setup, out, case_path)
    on_step = _load_step_records(recorder, setup.loading, end / s.load_steps)
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
        recorder,
        end,
    )


def _load_step_records(recorder: Recorder, loading, step_time: float):
    """Newton's ``on_step`` writing the Exodus records that ``output.exodus`` asks at its load
    steps (with the state at t = 0 first), as Peridigm's quasi-static solver writes them: the
    load step as the step, velocity the displacement's change over the step's time
    ``step_time`` (s), acceleration zero; at t = 0 the initial conditions. None when the
    Exodus file is written at the end only."""
    spec = recorder.spec
    if spec.exodus_every is None:
        return None
    u0, v0, zero = (np.zeros((loading.body.n_points, 3)) for _ in range(3))
    loading.apply_initial(u0, v0)
    recorder.write_exodus(State(u0, v0, zero, 0.0, 0))
    last = {"u": u0}

    def on_step(step, u):
        k = int(round(step.time / step_time))
        if spec.exodus_due(k):
            v = (u - last["u"]) / step_time
            recorder.write_exodus(State(u, v, zero, step.time, k))
        last["u"] = u.copy()

    return on_step
