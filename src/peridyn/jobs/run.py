"""Run a case and write its results: explicit and Newmark runs (the time loop with recording
and checkpoints: ``jobs.explicit_run``), static and Newton runs (``jobs.equilibrium``), modal
runs (``jobs.modal``); then the analyses, figures, crack paths and the stored summary, status
and provenance. ``run_case`` is what ``peridyn run`` and ``peridyn modal`` call
(``jobs.dispatch``)."""

from __future__ import annotations

import contextlib
import logging
import time

from peridyn import interrupts
from peridyn.discretization.body import Body
from peridyn.errors import InputError, Interrupted
from peridyn.io.case import Case
from peridyn.io.hdf5 import HDF5Writer
from peridyn.io.job_files import write_provenance, write_summary
from peridyn.io.lock import OutputLock
from peridyn.io.outdir import RUN_OUTPUTS, end_status, prepare_output, write_status
from peridyn.io.reserve import RESERVE_FILE
from peridyn.io.results import Results
from peridyn.io.run_log import run_log
from peridyn.jobs.context import RunContext
from peridyn.jobs.equilibrium import run_newton, run_static
from peridyn.jobs.explicit_run import run_explicit
from peridyn.jobs.figure_worker import figure_worker_for, figures_of, submit
from peridyn.jobs.figures import draw_crack_figures, draw_run_figures, final_crack_paths
from peridyn.jobs.lamb_analysis import analyse
from peridyn.jobs.summary import finish_summary
from peridyn.physics.damage import damage_field
from peridyn.setup.build import Setup, build
from peridyn.setup.estimate import check_memory
from peridyn.setup.recording import (
    RESULTS,
    check_output_fits,
    output_directory,
    recorder_spec,
)
from peridyn.setup.run_checks import check_run_plan
from peridyn.setup.solver_choice import (
    check_parallel,
    step_count,
    time_stepper,
)

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
        spec = domain.from_root(recorder_spec, case, setup.whole_body, solver.dt) if stepping else None
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
        ctx = RunContext(case, out, case_path, start, progress, checkpoint_every, restart, command)
        written = not restart  # a restart writes once its checkpoint is accepted (the recorder's part)
        if written and domain.is_root:
            write_provenance(out, ctx.provenance())
            write_status(out, "running")
        try:
            summary, plots = _solve(ctx, setup, solver, spec)
            written = True
            _finish(ctx, setup, summary, plots, worker)
            logger.info(f"case {case.name!r} complete in {time.perf_counter() - start:.1f} s")
        except Exception as exc:
            logger.warning(f"case {case.name!r}: {end_status(exc)}")
            if written and domain.is_root:
                (out / RESERVE_FILE).unlink(missing_ok=True)  # room for the status on a full disk
                try:
                    _record_end(ctx, setup.whole_body, end_status(exc))
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


def _solve(ctx: RunContext, setup: Setup, solver, spec) -> tuple[dict, list]:
    """The solver's part of ``run_case``: its summary and the figures it drew (``solver`` and
    ``spec``: the time stepper and the recorder's, for a time-stepping run)."""
    kind = ctx.case.solver.type
    if kind == "static":
        return run_static(ctx, setup), []
    if kind == "newton":
        return run_newton(ctx, setup), []
    if kind == "modal":
        from peridyn.jobs.modal import run_modal

        return run_modal(ctx.case, setup, ctx.out, ctx.case_path)
    return run_explicit(ctx, setup, solver, spec), []


def _draws_run_figures(case: Case) -> bool:
    """Whether the run ends with ``draw_run_figures`` (a modal run draws its own)."""
    return case.output.plots and case.solver.type != "modal"


def _finish(ctx: RunContext, setup: Setup, summary: dict, plots, worker=None) -> None:
    """Analyses, figures and the stored summary after the solve; the status becomes complete
    (on rank 0, with the damage of the whole body). ``worker``: a figure worker
    (``figure_worker_for``) that draws the run figures while this process analyses."""
    d = setup.domain
    phi = d.gather(damage_field(setup.model)) if setup.damage is not None else None
    d.on_root(_finish_on_root, ctx, setup.whole_body, summary, plots, phi, worker)


def _finish_on_root(ctx: RunContext, body, summary: dict, plots, phi, worker=None) -> None:
    """``_finish`` on rank 0: ``body`` the whole body, ``phi`` its damage (None without damage)."""
    case, out = ctx.case, ctx.out
    draw = _draws_run_figures(case)
    results = Results(ctx.results) if draw or case.analysis is not None else None  # read once
    pending = submit(worker, draw_run_figures, case, body, results) if draw else None
    analysis, figures = analyse(case, body, results, plots=case.output.plots)
    summary.update(analysis)
    paths = final_crack_paths(case, body, phi) if phi is not None else None
    if paths is not None:
        summary["crack_paths"] = [p.summary() for p in paths]
    if draw:
        plots = [*figures_of(pending, draw_run_figures, case, body, results), *figures]
        if paths is not None:
            plots += draw_crack_figures(body, results, paths, summary)
    finish_summary(summary, "modal" if case.solver.type == "modal" else "run", out, ctx.start, plots)
    _record_end(ctx, body, "complete", summary)


def _record_end(ctx: RunContext, body: Body, status: str, summary: dict | None = None) -> None:
    """The end of a run in its folder (rank 0): its ``status`` and ``summary`` (None: a job that
    did not complete) in results.h5 (created if the job failed before writing one) and in the
    output contract's files (``peridyn.io.job_files``; a restart's provenance too, written once
    its checkpoint was accepted)."""
    with HDF5Writer(ctx.results, body.points[:, : body.dim], body.volumes, {}, mode="a") as h5:
        if summary is not None:
            h5.write_summary(summary)
        h5.set_status(status)
    if ctx.restart:
        write_provenance(ctx.out, ctx.provenance())
    if summary is not None:
        write_summary(ctx.out, summary)
    write_status(ctx.out, status)
