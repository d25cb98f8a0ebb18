"""The monitoring job (``peridyn monitor CASE.yaml``, docs/monitoring.md): a fatigue life and, at
the interrogation points of its schedule, a pitch-catch interrogation of the damaged plate by a
PZT network; damage indices, images and the dataset of the whole life.

1. The fatigue case runs once (``peridyn.jobs.fatigue.run_fatigue_case``, in ``fatigue/``).
2. Its history gives the interrogation points and the crack at each (``peridyn.jobs.monitor_plan``).
3. Each interrogation fires every transducer in turn on the wave case with the fatigue damage of
   its cycle transferred into it (the case's ``transfer``: ``bonds`` or ``cut``; the transfer
   check repeats it by the other) (``peridyn.run_case``, one run per actuator in
   ``interrogations/kNN_tI/``), through the sweep executors (serial, processes, dask); a run
   whose folder holds a complete record of the same case is not run again, so an interrupted
   job resumes where it stopped. Under ``mpiexec -n N``
   the fatigue and the runs go one after the other, each on all ranks; rank 0 reads and writes
   the job's own files (the records kept, the dataset, figures and summary) and tells the others.
4. The signals are compared with the baseline's (``peridyn.jobs.monitor_assess``) and written as
   one dataset with figures and the summary (``peridyn.jobs.monitor_output``).
"""

from __future__ import annotations

import csv
import logging
import time
from contextlib import nullcontext
from pathlib import Path

import numpy as np

from peridyn import interrupts
from peridyn.analysis.shm.paths import network_paths
from peridyn.errors import CaseFileError, InputError
from peridyn.io.case import Case, load_case, validate_case
from peridyn.io.job_files import job_files
from peridyn.io.monitor_case import TRANSFERS, MonitorCase, load_monitor_case
from peridyn.io.outdir import prepare_output
from peridyn.io.provenance import provenance
from peridyn.io.results import Results
from peridyn.io.run_log import run_log
from peridyn.jobs.monitor_plan import (
    FatigueHistory,
    bonds_case,
    crack_lines,
    cut_case,
    damage_at,
    interrogation_steps,
)
from peridyn.jobs.sweep_run import (
    RunTask,
    numba_threads_kept,
    read_record,
    run_tasks,
    run_threads,
    set_threads,
)
from peridyn.parallel.domain import agree
from peridyn.setup.identity import case_identity

logger = logging.getLogger(__name__)

#: The job's summary file in its output folder (its presence: a finished job).
SUMMARY = "monitor.json"


@interrupts.deferred()
def run_monitor(
    case_path,
    output_dir=None,
    overrides=(),
    executor: str = "serial",
    workers: int = 1,
    scheduler: str | None = None,
    threads: int | None = None,
    overwrite: bool = False,
    comm=None,
) -> dict:
    """Run a monitoring case file; returns the summary (``monitor.json``; its ``monitoring``
    block: docs/monitoring.md).

    Parameters
    ----------
    case_path : path
        The monitoring case file (``peridyn.io.monitor_case``).
    output_dir : path or None
        Output folder (default: the case's ``output.directory`` or ``peridyn-out/<name>``).
    overrides : sequence of "key.path=value"
        Changes to the monitoring case before validation.
    executor, workers, scheduler, threads
        How the interrogation runs are run (``peridyn.jobs.sweep_run.run_tasks``); ``threads``
        given, the fatigue run too has that many numba threads.
    overwrite : bool
        Redo every run; otherwise a folder's finished fatigue and interrogation runs are kept
        (the job resumes) and only a finished job's folder is refused.
    comm : communicator or None
        ``peridyn.parallel.comm.world()`` under ``mpiexec -n N`` (N > 1).
    """
    start = time.perf_counter()
    mon, base = load_monitor_case(case_path, overrides)
    fatigue, wave = _cases(mon, base, case_path)
    if comm is not None and comm.size > 1 and (executor != "serial" or scheduler is not None):
        raise InputError(
            f"--executor {executor}{' --scheduler' if scheduler else ''} under mpiexec: each run goes "
            "over the MPI ranks, one after the other; run without --executor (serial) or without mpiexec"
        )
    root = comm is None or comm.rank == 0
    out = Path(output_dir or mon.output.directory or Path("peridyn-out") / mon.name)
    _on_root(comm, lambda: prepare_output(out, SUMMARY, overwrite, restartable=False))
    files = job_files(out, provenance(case_path, case=mon)) if root else nullcontext()
    with files, run_log(out, root):
        with numba_threads_kept():
            if threads is not None:
                set_threads(run_threads(threads, executor, workers, scheduler))
            history = _fatigue(fatigue, base / mon.fatigue_case, out / "fatigue", overwrite, comm)
        plan = _plan(mon, fatigue, history, (base / mon.fatigue_case).parent)
        tasks = _tasks(mon, wave, plan, out, base / mon.wave_case, executor, workers, scheduler, threads)
        _run(tasks, executor, workers, scheduler, overwrite, comm)

        def outputs() -> dict:
            from peridyn.jobs.monitor_output import write_outputs

            return write_outputs(mon, wave, plan, _signals(mon, plan, tasks), out, start)

        return _on_root(comm, outputs)  # every rank returns the summary


def _cases(mon: MonitorCase, base: Path, path) -> tuple[Case, Case]:
    """The fatigue and wave cases, checked against each other and the network."""
    fatigue = load_case(base / mon.fatigue_case)
    wave = load_case(base / mon.wave_case)
    src = str(path)
    if fatigue.fatigue is None:
        raise CaseFileError(src, "fatigue_case", mon.fatigue_case, "a case with a fatigue block")
    if fatigue.geometry.type != "rectangle":
        raise CaseFileError(src, "fatigue_case", mon.fatigue_case, "a 2D (rectangle) fatigue case")
    if fatigue.fatigue.tip.start is None or fatigue.fatigue.tip.axis == "z":
        raise CaseFileError(
            src, "fatigue_case", mon.fatigue_case, "fatigue.tip.start and an in-plane tip.axis"
        )
    if wave.geometry.type != "plate" or wave.solver.type != "explicit":
        raise CaseFileError(src, "wave_case", mon.wave_case, "an explicit run of a plate")
    if not np.isclose(wave.discretization.spacing, fatigue.discretization.spacing):
        raise CaseFileError(
            src, "wave_case", mon.wave_case, "the fatigue case's spacing (one in-plane grid for both)"
        )
    size = np.asarray(wave.geometry.size[:2])
    xy = np.asarray(mon.transducers.centers)
    if np.any(xy < 0) or np.any(xy > size):
        raise CaseFileError(
            src, "transducers.centers", xy.tolist(), f"centres on the plate (0..{size.tolist()} m)"
        )
    return fatigue, wave


def _fatigue(fatigue: Case, path: Path, folder: Path, overwrite: bool, comm) -> FatigueHistory:
    """Run the fatigue case into ``folder`` (or keep its finished run of the same case) and read
    its history and broken bonds (under MPI: rank 0 decides and reads, every rank gets them)."""
    from peridyn.jobs.fatigue import BROKEN_BONDS, run_fatigue_case

    stamp = folder / "case_hash.txt"
    digest = case_identity(fatigue, run_length=True)[1]

    def finished() -> bool:
        return (
            (folder / "fatigue.json").exists()
            and (folder / BROKEN_BONDS).exists()
            and stamp.exists()
            and stamp.read_text().strip() == digest
        )

    if overwrite or not _on_root(comm, finished):
        run_fatigue_case(fatigue, output_dir=folder, base_dir=path.parent, overwrite=True, comm=comm)
        _on_root(comm, stamp.write_text, digest + "\n")
    else:
        logger.info(f"fatigue run in {folder} kept (finished, same case)")
    return _on_root(comm, read_history, folder)


def _on_root(comm, fn, *args):
    """``fn(*args)`` on rank 0 (on the one process without MPI), its result on every rank; an
    error there is raised on every rank."""
    if comm is None or comm.size == 1:
        return fn(*args)
    return comm.bcast(agree(comm, lambda: fn(*args) if comm.rank == 0 else None))


def read_history(folder: Path) -> FatigueHistory:
    """The fatigue run's ``crack_length.csv``, ``damage.vtu`` and ``broken_bonds.csv`` in ``folder``."""
    import meshio

    from peridyn.jobs.fatigue import BROKEN_BONDS

    with open(folder / "crack_length.csv") as fh:
        rows = list(csv.DictReader(fh))
    with open(folder / BROKEN_BONDS) as fh:
        bonds = list(csv.DictReader(fh))
    mesh = meshio.read(folder / "damage.vtu")
    first = np.asarray(mesh.point_data["first_break_cycle"], dtype=float)
    return FatigueHistory(
        cycles=np.array([float(r["cycles"]) for r in rows]),
        crack_length=np.array([float(r["crack_length_m"]) for r in rows]),
        points=np.asarray(mesh.points[:, :2], dtype=float),
        first_break=np.where(first < 0, np.inf, first),
        broken_pairs=np.array(
            [[int(r["point_a"]), int(r["point_b"])] for r in bonds], dtype=np.int64
        ).reshape(-1, 2),
        break_cycle=np.array([float(r["cycles"]) for r in bonds]),
    )


class Plan:
    """The interrogations: fatigue steps, cycles (n_int,), crack lengths (n_int,) m, the crack
    of each (``lines``: its polylines, (m, 2) m, branches included, from the fatigue model's
    damage at that cycle; ``cracks``: the main one, None before the crack grew), the damage
    transfer of the interrogations (``route``: bonds or cut) and of their check (``check``: the
    other), and the interrogations that the check repeats (``checked``: each after the crack
    first grew, when the case asks for it). ``base_dir``: the fatigue case's folder."""

    def __init__(self, mon: MonitorCase, fatigue: Case, history: FatigueHistory, base_dir: Path):
        from peridyn.setup.build import build

        f = fatigue.fatigue
        s = mon.schedule
        self.history = history
        self.tip = f.tip
        self.spacing = fatigue.discretization.spacing
        self.steps = interrogation_steps(
            history.cycles,
            history.crack_length,
            s.every_cycles,
            s.every_crack_growth,
            s.max_interrogations,
            s.until_crack_length,
        )
        self.cycles = history.cycles[self.steps]
        self.crack_length = history.crack_length[self.steps]
        phi = damage_at(build(fatigue, base_dir).model, history, self.cycles)
        self.lines = [
            crack_lines(history.points, p, self.spacing, f.tip) if a > 0 else []
            for p, a in zip(phi, self.crack_length, strict=True)
        ]
        self.cracks = [lines[0] if lines else None for lines in self.lines]
        self.transducers = np.asarray(mon.transducers.centers, dtype=float)
        self.paths = network_paths(len(self.transducers))
        grown = [k for k, crack in enumerate(self.cracks) if k > 0 and crack is not None]
        self.checked = grown if mon.check_transfer else []
        self.route, self.check = mon.transfer, TRANSFERS[mon.transfer]

    def wave_case(self, fired: Case, name: str, k: int, route: str) -> Case:
        """The wave case ``fired`` with the damage of interrogation ``k`` transferred by ``route``
        (bonds or cut), renamed ``name``."""
        if route == "bonds":
            return bonds_case(fired, name, self.history, self.cycles[k], self.spacing)
        return cut_case(fired, name, self.lines[k])


def _plan(mon, fatigue, history, base_dir) -> Plan:
    plan = Plan(mon, fatigue, history, base_dir)
    logger.info(
        f"{len(plan.steps)} interrogations at {plan.cycles.tolist()} cycles, crack "
        f"{(plan.crack_length * 1e3).round(2).tolist()} mm"
    )
    return plan


def network_case(mon: MonitorCase, wave: Case, actuator: int) -> Case:
    """The wave case with transducer ``actuator`` fired and every transducer recorded."""
    t = mon.transducers
    data = wave.model_dump(mode="python")
    data["actuators"] = {
        f"t{actuator}": {
            "type": "pzt_radial",
            "center": t.centers[actuator],
            "size": t.size,
            "shape": t.shape,
            "amplitude": t.amplitude,
            "signal": t.signal(),
        }
    }
    data["output"]["pzt_sensors"] = {
        f"t{j}": {"center": c, "size": t.size, "shape": t.shape} for j, c in enumerate(t.centers)
    }
    data["output"]["plots"] = False
    data["analysis"] = None
    return validate_case(data, wave.name)


def _tasks(mon, wave, plan: Plan, out: Path, wave_path: Path, executor, workers, scheduler, threads):
    """``{(label, actuator): RunTask}``: label ``k`` for interrogation k (folders ``kNN_tI``),
    ``("check", k)`` for its transfer check (folders ``<check route>_kNN_tI``)."""
    n = len(plan.transducers)
    fired = [network_case(mon, wave, i) for i in range(n)]
    per_run = run_threads(threads, executor, workers, scheduler)
    tasks = {}
    labels = list(range(len(plan.cracks))) + [("check", k) for k in plan.checked]
    for label in labels:
        for i in range(n):
            if isinstance(label, tuple):
                name = f"{mon.name}_{plan.check}_k{label[1]:02d}_t{i}"
                case = plan.wave_case(fired[i], name, label[1], plan.check)
            else:
                name = f"{mon.name}_k{label:02d}_t{i}"
                case = plan.wave_case(fired[i], name, label, plan.route)
            folder = out / "interrogations" / name.removeprefix(f"{mon.name}_")
            tasks[(label, i)] = RunTask(
                run_id=folder.name,
                index=len(tasks),
                parameters={"interrogation": str(label), "actuator": i},
                case=case,
                case_hash=case_identity(case, run_length=True)[1],
                command="run",
                run_dir=str(folder),
                base_dir=str(wave_path.parent),
                threads=per_run,
            )
    return tasks


def _run(tasks: dict, executor, workers, scheduler, overwrite: bool, comm) -> None:
    """Run the tasks whose folders hold no complete record of the same case (under MPI: as rank
    0 reads the records)."""

    def unfinished() -> list[str]:
        todo = []
        for task in tasks.values():
            record = read_record(task.run_dir)
            if overwrite or not (
                record and record["status"] == "complete" and record["case_hash"] == task.case_hash
            ):
                todo.append(task.run_id)
        return todo

    by_id = {task.run_id: task for task in tasks.values()}
    todo = [by_id[run_id] for run_id in _on_root(comm, unfinished)]
    logger.info(f"{len(tasks) - len(todo)} of {len(tasks)} interrogation runs kept; {len(todo)} to run")
    failed = []

    def done(record: dict) -> bool:
        logger.info(f"interrogation run {record['run_id']}: {record['status']} ({record['seconds']:.1f} s)")
        if record["status"] != "complete":
            failed.append(f"{record['run_id']}: {record['error'] or record['status']}")
        return not failed

    def done_then_check(record: dict) -> bool:
        keep_going = done(record)
        interrupts.check()  # SIGINT/SIGTERM: no more runs start, the finished ones are kept
        return keep_going

    if comm is not None and comm.size > 1:
        _run_ranks(todo, comm, done)
    else:
        run_tasks(todo, done_then_check, executor, workers, scheduler)
    if failed:
        raise InputError(f"an interrogation run failed ({failed[0]}); its run.json holds the error")


def _run_ranks(todo, comm, done) -> None:
    """The runs one after the other, each on all ranks (``run_case`` with ``comm``); rank 0
    writes the records. After each run every rank checks for a stop signal and the ranks agree
    (the largest signal number noted on any rank), so all stop together, none left waiting in
    the next run's first collective."""
    from peridyn.jobs.run import run_case
    from peridyn.jobs.sweep_run import write_record

    for task in todo:
        begin = time.perf_counter()
        Path(task.run_dir).mkdir(parents=True, exist_ok=True)
        summary = run_case(task.case, task.run_dir, base_dir=task.base_dir, overwrite=True, comm=comm)
        if comm.rank == 0:
            record = {
                "run_id": task.run_id,
                "index": task.index,
                "parameters": task.parameters,
                "case_hash": task.case_hash,
                "command": task.command,
                "status": "complete",
                "error": "",
                "summary": summary,
                "seconds": time.perf_counter() - begin,
                "finished": time.time(),
            }
            write_record(task.run_dir, record)
            done(record)
        interrupts.check(
            where="between interrogation runs", agree=lambda signum: comm.allreduce(signum, "max")
        )


def _signals(mon: MonitorCase, plan: Plan, tasks: dict) -> dict:
    """``{"times": (n_t,) s, "signals": (n_int, n_paths, n_t), "check": (n_checked, n_paths,
    n_t), the checked interrogations by the check's route (``Plan.checked``, ``Plan.check``)}``: each path's
    signal the mean of its two directions (reciprocity), unit of ``pzt_signal`` (mean in-plane
    strain under the sensor)."""
    n = len(plan.transducers)

    def interrogation(label) -> tuple[np.ndarray, np.ndarray]:
        by_actuator = []
        times = None
        for i in range(n):
            _, t, data = Results(Path(tasks[(label, i)].run_dir) / "results.h5").series("pzt_signal")
            times = t if times is None else times
            by_actuator.append(np.asarray(data, dtype=float))
        signals = np.stack([0.5 * (by_actuator[i][:, j] + by_actuator[j][:, i]) for i, j in plan.paths])
        return times, signals

    series = [interrogation(k) for k in range(len(plan.steps))]
    times = series[0][0]
    return {
        "times": np.asarray(times, dtype=float),
        "signals": np.stack([s for _, s in series]),
        "check": np.stack([interrogation(("check", k))[1] for k in plan.checked]) if plan.checked else None,
    }
