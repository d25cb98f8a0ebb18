"""The time loop of an explicit or Newmark run: recording, checkpoints and restarts, under MPI
the records gathered on rank 0 (``run_explicit``, called by ``run_case``)."""

from __future__ import annotations

import logging
import time

import numpy as np

from peridyn.discretization.state import State
from peridyn.errors import InputError, Interrupted
from peridyn.io.checkpoint import Checkpointer, load_checkpoint
from peridyn.io.outdir import end_status
from peridyn.io.provenance import package_version
from peridyn.io.recorder import Probes, Recorder
from peridyn.io.vtu_pieces import VtuPieces
from peridyn.jobs.context import RunContext
from peridyn.jobs.observers import crack_observer
from peridyn.jobs.summary import base_summary, peak_memory_bytes
from peridyn.parallel.observers import RootObservers
from peridyn.physics.damage import damage_field
from peridyn.setup.build import Setup
from peridyn.setup.exodus_variables import GatheredVariables
from peridyn.setup.identity import case_identity
from peridyn.setup.recording import exodus_values, point_tensors
from peridyn.setup.solver_choice import step_count
from peridyn.solvers.explicit_gpu import GPUExplicitSolver

logger = logging.getLogger(__name__)


def bond_state(setup: Setup) -> tuple[np.ndarray, np.ndarray]:
    """(array, offsets): the bonds' state that a checkpoint saves and a restart writes back in
    place, with its CSR family ``offsets``: the intact mask of bond lists, or the broken words
    of a lattice (flat, ``offsets`` [0, their number]; under MPI the rank's
    ``parallel.lattice_domain.LatticeDomain`` places them in the whole grid)."""
    if setup.storage == "lattice":
        words = setup.bonds.broken.reshape(-1)
        return words, np.array([0, len(words)])
    return setup.bonds.intact, setup.bonds.offsets


#: Seconds of running after which an interrupted run writes a checkpoint even unasked.
CHECKPOINT_AFTER_S = 60.0


def run_explicit(ctx: RunContext, setup: Setup, solver, spec) -> dict:
    """Time integration of ``setup`` by ``solver`` with recording by ``spec``
    (``setup.recording.recorder_spec``), checkpoints and the status; the run's summary."""
    case, out, checkpoint_every = ctx.case, ctx.out, ctx.checkpoint_every
    d = setup.domain
    n_steps = step_count(case, solver)
    ckpt_path = out / "checkpoint.h5"
    case_json, digest = case_identity(case)
    meta = {"case_hash": digest, "case": case_json, "dt": float(solver.dt), "version": package_version()}
    tensors = point_tensors(setup, spec)
    gathered = RootObservers(d, setup.model, tensors)
    cracks = crack_observer(case, setup, n_steps, gathered.damage)
    parts = {
        name: part
        for name, part in (("damage", setup.damage), ("contact", setup.contact), ("cracks", cracks))
        if part is not None
    }
    whole_bonds = d.bond_offsets(bond_state(setup)[1])
    if ctx.restart:
        state = _restart(ckpt_path, setup, meta, parts, whole_bonds, n_steps, ctx.results)
        resume = (state.step, state.time)
        logger.info(f"restarting from the checkpoint at step {state.step} (t = {state.time:.6g} s)")
    else:
        state, resume = solver.initial_state(), None
    info = ctx.provenance()
    if d.size > 1:
        info.update(d.provenance())
    pieces = None  # under MPI, each rank writes its piece of the VTU snapshots
    if d.size > 1 and spec.vtu:
        pieces = VtuPieces(
            d, setup.body, out, lambda: damage_field(setup.model), tensors, spec.vtu_compression
        )
    if d.size > 1 and tensors is not None:
        tensors = gathered.tensor_fields
    # the explicit solver's own force (Peridigm's order: from its deformed positions); Newmark's: None
    fields = exodus_values(case, setup, spec, getattr(solver, "internal_force", None))
    probes = d.from_root(Probes.of, setup.whole_body, spec)  # every rank's: gathered at a series record
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
    # a record without an Exodus one reads the probe points and u: under MPI rank 0 gathers
    # those only (``RootObservers.record``), not the whole state
    lean = not (spec.exodus or spec.exodus_more)
    try:
        if resume is None:
            if pieces is not None:
                pieces.write(state)
            collect(state)
            if lean:
                gathered.record(state, recorder, probes)
            else:
                gathered.call(state, lambda whole: (recorder.record_series(whole), recorder.snapshot(whole)))
        observers = [gathered]
        if checkpoint_every and d.size == 1:
            observers.append(checkpointer)
        remaining = n_steps - state.step
        bar = ctx.progress(remaining) if ctx.progress is not None else None
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
        saved = bool(checkpoint_every) or time.perf_counter() - ctx.start > CHECKPOINT_AFTER_S
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
            if lean:
                gathered.snapshot(state, recorder)
            else:
                gathered.call(state, lambda whole: recorder.snapshot(whole))
    except BaseException as exc:  # e.g. a full disk: the records held are written, the file closed
        if recorder is not None:
            recorder.close(end_status(exc))
        raise
    n = d.n_owned
    summary = base_summary(setup)
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
    gathered.finish(state, recorder)
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
    values, offsets = bond_state(setup)
    none_broken = values.dtype == bool  # all True in an intact mask, all zero in broken words
    whole_intact = np.full(int(whole_bonds[-1]), none_broken, dtype=values.dtype) if d.is_root else None
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
        intact = d.gather_bonds(values, offsets, whole_bonds)
        if d.is_root:
            whole_intact[:] = intact
        if setup.contact is not None:
            setup.contact.gather_built()

    return checkpointer, [(checkpointer.due, gather_whole)]
