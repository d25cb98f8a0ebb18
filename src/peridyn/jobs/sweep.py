"""``peridyn sweep``: run every run of a sweep file and collect their results in one dataset.

Layout of the output folder ``OUT``:

- ``OUT/sweep.json``: the sweep (its file, spec and runs: id and parameters);
- ``OUT/runs/<run-id>/``: each run's own output folder (``results.h5`` or ``fatigue.json``,
  with provenance) and its record ``run.json`` (:mod:`peridyn.jobs.sweep_run`);
- ``OUT/dataset.nc``: the dataset (:mod:`peridyn.io.dataset`), rewritten as runs finish;
- ``OUT/figures/``: a scalar result against the first varied parameter (at the end).

A run whose record says ``complete`` for the same case hash is skipped (resume); a failed run
is recorded and the sweep goes on; Ctrl-C stops starting runs and keeps every finished one.
"""

from __future__ import annotations

import json
import time
from contextlib import nullcontext
from pathlib import Path

import numpy as np

from peridyn.errors import InputError, Interrupted
from peridyn.io.case_schema import case_unit
from peridyn.io.dataset import SeriesColumn, build_dataset, require_xarray, write_dataset
from peridyn.io.job_files import job_files, write_summary
from peridyn.io.provenance import provenance
from peridyn.io.results import Results
from peridyn.jobs.summary import finish_summary
from peridyn.jobs.sweep_memory import check_sweep_memory
from peridyn.jobs.sweep_run import (
    EXECUTORS,
    RunTask,
    execute,
    read_record,
    run_tasks,
    run_threads,
)
from peridyn.jobs.sweep_signals import Signals
from peridyn.jobs.sweep_spec import Sweep, expand

#: The dataset file in a sweep's output folder.
DATASET = "dataset.nc"
#: Least time between two rewrites of the dataset while runs finish, s (it is always written
#: at the end; every finished run is kept in its folder meanwhile).
REWRITE_INTERVAL = 5.0
#: Summary keys that are not results of the physics (paths, timings, schema).
NOT_RESULTS = {
    "output_dir",
    "plots",
    "schema_version",
    "kind",
    "seconds",
    "step_seconds",
    "peak_memory_bytes",
}
#: Dataset variables of every sweep that time its runs, not results: wall time (s) and the
#: moment each run ended (Unix time, s).
TIMINGS = ("seconds", "finished")
#: The most results drawn against a parameter when ``outputs.scalars`` does not choose them.
MAX_FIGURES = 12


class SweepInterrupted(Interrupted):
    """A sweep stopped by Ctrl-C (or SIGTERM in a run): ``completed`` of ``total`` runs are
    complete; ``resume`` says how to run the others."""

    def __init__(self, signal_name: str, completed: int, total: int, resume: str):
        super().__init__(signal_name, completed, resume)
        self.args = (
            f"sweep interrupted ({signal_name}): {completed} of {total} runs complete; "
            f"run the same command again to run the others: {resume}",
        )


def run_sweep(
    path,
    output_dir=None,
    executor: str = "serial",
    workers: int = 1,
    scheduler: str | None = None,
    overwrite: bool = False,
    progress=None,
    command: str | None = None,
    overrides=(),
    first: int | None = None,
    on_record=None,
    threads: int | None = None,
    job_files_of_its_own: bool = True,
) -> dict:
    """Run the sweep file ``path``; returns its summary.

    Parameters
    ----------
    path : path
        The sweep file (docs/sweeps.md).
    output_dir : path or None
        Default ``peridyn-out/<sweep name>``.
    executor : "serial", "processes" or "dask"
    workers : int
        Worker processes (``processes`` and a local dask cluster).
    scheduler : str or None
        Address of a running dask scheduler (``executor="dask"`` only).
    overwrite : bool
        Run again the runs already complete (default: skip them).
    progress : callable(total) -> bar with update(n) and close(), or None
    command : str or None
        The command line, for the resume hint of an interrupted sweep.
    overrides : sequence of "key.path=value"
        ``--set`` items for every run (after the sweep file's ``set``).
    first : int or None
        Run only the first ``first`` runs of the sweep (a trial).
    on_record : callable(record) or None
        Called in this process with each run's record as the run ends
        (:mod:`peridyn.jobs.sweep_run`), in the order the runs end.
    threads : int or None
        Threads per run (numba; with processes and a local dask cluster also BLAS and
        OpenMP). Default: ``cores // workers`` for processes and a local dask cluster, the
        process's own threads for serial, the workers' own setting on a ``scheduler``
        cluster (:func:`peridyn.jobs.sweep_run.run_threads`).
    job_files_of_its_own : bool
        Write the output contract's ``status.json``, ``provenance.json`` and ``summary.json``
        (``peridyn.io.job_files``) in the output folder; False for a sweep that is part of
        another job writing its own there (a convergence study: ``jobs.study.run_levels``).

    Returns
    -------
    dict
        ``runs``, ``completed``, ``failed``, ``skipped``, ``seconds``, ``dataset`` (path),
        ``output_dir``, ``figures`` and ``executor``, ``workers``, ``threads`` (None: not set).

    Raises
    ------
    SweepInterrupted
        Ctrl-C: the runs finished so far are in the dataset.
    """
    start = time.perf_counter()
    if executor not in EXECUTORS:
        raise InputError(f"executor must be one of {EXECUTORS}, got {executor!r}")
    if scheduler is not None and executor != "dask":
        raise InputError(
            f"--scheduler is the address of a dask scheduler: use it with --executor dask, not {executor}"
        )
    if not isinstance(workers, int) or workers < 1:
        raise InputError(f"workers must be a whole number >= 1, got {workers!r}")
    threads = run_threads(threads, executor, workers, scheduler)
    require_xarray()
    sweep = expand(path, overrides, first)
    check_sweep_memory(sweep, 1 if executor == "serial" else workers)
    out = Path(output_dir or Path("peridyn-out") / sweep.name)
    if out.exists() and not out.is_dir():
        raise InputError(f"output folder {str(out)!r} is a file, not a folder: choose another --output")
    (out / "runs").mkdir(parents=True, exist_ok=True)
    with job_files(out, provenance(path)) if job_files_of_its_own else nullcontext():
        _write_manifest(sweep, out)
        collector = Collector(sweep, out)
        reference_dir = _reference(sweep, out, overwrite)
        if reference_dir is not None:
            collector.add_reference(Path(reference_dir))
        tasks = []
        for run in sweep.runs:
            if not overwrite and collector.is_complete(run):
                collector.skipped += 1
                continue
            tasks.append(
                RunTask(
                    run.run_id,
                    run.index,
                    run.parameters,
                    run.case,
                    run.case_hash,
                    sweep.spec.command,
                    str(out / "runs" / run.run_id),
                    str(sweep.base.parent),
                    threads,
                    reference_dir,
                    tuple(sweep.spec.outputs.bloch),
                )
            )
        collector.write(final=True)  # every run pending or done: the dataset exists from the start
        bar = progress(len(tasks)) if progress is not None and tasks else None
        interrupted = None
        signals = Signals()

        def on_done(record: dict) -> bool:
            nonlocal interrupted
            with signals.deferred():
                collector.add(record)
                if on_record is not None:
                    on_record(record)
                if bar is not None:
                    bar.update(1)
                if record["status"].startswith("interrupted"):
                    interrupted = record["status"].partition("(")[2].rstrip(")") or "SIGINT"
                    return False
                collector.write(final=False)
            return True

        with signals:
            try:
                run_tasks(tasks, on_done, executor, workers, scheduler)
            except KeyboardInterrupt:
                interrupted = signals.name or "SIGINT"
            finally:
                with signals.deferred():
                    if bar is not None:
                        bar.close()
                    collector.read_finished()  # runs that workers finished after the interrupt
                    collector.write(final=True)
        counts = collector.counts()
        if interrupted is not None:
            raise SweepInterrupted(
                interrupted,
                counts["completed"],
                len(sweep.runs),
                command or f"run_sweep({str(path)!r}, ...)",
            )
        figures = draw_figures(sweep, collector.dataset(), out)
        summary = {
            "sweep": sweep.name,
            "runs": len(sweep.runs),
            **counts,
            "skipped": collector.skipped,
            "dataset": str(out / DATASET),
            "output_dir": str(out),
            "figures": [str(p) for p in figures],
            "executor": executor,
            "workers": 1 if executor == "serial" else workers,
            "threads": threads,
        }
        finish_summary(summary, "sweep", out, start, summary["figures"])
        if job_files_of_its_own:
            write_summary(out, summary)
    return summary


def _reference(sweep: Sweep, out: Path, overwrite: bool) -> str | None:
    """The folder of the sweep's reference run (``OUT/reference``), run here first unless
    complete for its case; None without a reference.

    Raises
    ------
    InputError
        The reference run failed (every comparison needs it).
    """
    if sweep.reference is None:
        return None
    ref = sweep.reference
    base = (sweep.path.parent / sweep.spec.reference).resolve().parent
    folder = out / "reference"
    record = read_record(folder)
    if overwrite or record is None or record["case_hash"] != ref.case_hash or record["status"] != "complete":
        task = RunTask(
            ref.run_id, -1, {}, ref.case, ref.case_hash, sweep.spec.command, str(folder), str(base), None
        )
        record = execute(task)
    if record["status"] != "complete":
        raise InputError(
            f"the sweep's reference run ({sweep.spec.reference}) did not complete: {record['status']}"
        )
    return str(folder)


def _write_manifest(sweep: Sweep, out: Path) -> None:
    manifest = {
        "sweep_file": str(sweep.path),
        "base_case": str(sweep.base),
        "spec": sweep.spec.model_dump(mode="json"),
        "runs": [{"run_id": r.run_id, "parameters": r.parameters} for r in sweep.runs],
    }
    (out / "sweep.json").write_text(json.dumps(manifest, indent=1) + "\n")


class Collector:
    """The records of a sweep's runs, read from their folders or reported as they finish, and
    the dataset they make."""

    def __init__(self, sweep: Sweep, out: Path):
        self.sweep, self.out = sweep, out
        self.records: dict[str, dict] = {}
        self.series: dict[str, dict] = {}
        self.reference_series: dict[str, tuple] = {}
        self.skipped = 0
        self._written = -np.inf
        self.read_finished()

    def read_finished(self) -> None:
        """Take the records in the run folders of the runs not known to be complete."""
        for run in self.sweep.runs:
            if self.is_complete(run):
                continue
            record = read_record(self.out / "runs" / run.run_id)
            if record is not None and record.get("case_hash") == run.case_hash:
                try:
                    self.add(record)
                except InputError:  # its results file is gone or unreadable: the run runs again
                    self.records.pop(run.run_id, None)

    def is_complete(self, run) -> bool:
        """Whether ``run`` has a complete record for its case."""
        record = self.records.get(run.run_id)
        return record is not None and record["status"] == "complete"

    def add(self, record: dict) -> None:
        """Take a run's record (and read its series when it is complete)."""
        self.records[record["run_id"]] = record
        self.series[record["run_id"]] = {}
        if record["status"] == "complete":
            self.series[record["run_id"]] = self._read_series(self.out / "runs" / record["run_id"])

    def add_reference(self, folder: Path) -> None:
        """Take the series of the sweep's (complete) reference run in ``folder``."""
        self.reference_series = {
            name: (times, values) for name, (times, values, _, _) in self._read_series(folder).items()
        }

    def _read_series(self, folder: Path) -> dict:
        """``{name: (times, values, entry names)}`` of the ``outputs.series`` of the run in
        ``folder``."""
        if not self.sweep.spec.outputs.series:
            return {}
        results = Results(folder / "results.h5")
        out = {}
        for name in self.sweep.spec.outputs.series:
            _, times, values = results.series(name)
            out[name] = (times, values, results.series_attrs(name).get("names"), results.series_about(name))
        return out

    def counts(self) -> dict:
        """``completed`` and ``failed`` runs."""
        statuses = [r["status"] for r in self.records.values()]
        return {
            "completed": sum(s == "complete" for s in statuses),
            "failed": sum(s.startswith("failed") for s in statuses),
            "failed_runs": [
                {"run_id": r["run_id"], "status": r["status"]}
                for r in self.records.values()
                if r["status"].startswith("failed")
            ],
        }

    def write(self, final: bool) -> None:
        """Rewrite the dataset (at most every :data:`REWRITE_INTERVAL` s unless ``final``)."""
        if not final and time.monotonic() - self._written < REWRITE_INTERVAL:
            return
        write_dataset(self.dataset(), self.out / DATASET)
        self._written = time.monotonic()

    def dataset(self):
        """The dataset of every run of the sweep, in sweep order (runs not yet done have the
        status ``pending`` and no results)."""
        runs = self.sweep.runs
        records = [self.records.get(r.run_id) for r in runs]
        coords = {"run_id": [r.run_id for r in runs]}
        for name in self.sweep.spec.parameter_names():
            coords[name] = [r.parameters.get(name) for r in runs]  # derived_by: not in every run
        flat = [flatten_summary(rec["summary"]) if rec and rec.get("summary") else {} for rec in records]
        names = self.sweep.spec.outputs.scalars
        if names is None:
            names = list(dict.fromkeys(k for row in flat for k in row))
        table = {
            "status": [rec["status"] if rec else "pending" for rec in records],
            "error": [rec["error"] if rec else "" for rec in records],
            "seconds": [rec["seconds"] if rec else None for rec in records],
            "finished": [rec.get("finished") if rec else None for rec in records],
        }
        for name in names:
            table[name] = [row.get(name) for row in flat]
        series = {}
        for name in self.sweep.spec.outputs.series:
            got = [self.series.get(r.run_id, {}).get(name) for r in runs]
            first = next((g for g in got if g is not None), None)
            series[name] = SeriesColumn(
                times=[None if g is None else g[0] for g in got],
                values=[None if g is None else g[1] for g in got],
                entry_names=first[2] if first else None,
                about=first[3] if first else {},
            )
        attrs = {
            "sweep": self.sweep.name,
            "sweep_file": str(self.sweep.path),
            "base_case": str(self.sweep.base),
            "command": self.sweep.spec.command,
            "parameters": json.dumps(self.sweep.spec.parameter_names()),
        }
        about = {name: (case_unit(name), f"parameter {name}") for name in self.sweep.spec.parameter_names()}
        about.update({name: (summary_unit(name), name.replace("_", " ")) for name in names})
        about.update(SWEEP_COLUMNS)
        return build_dataset(coords, table, series, attrs, self.reference_series, about)


#: Units and long names of the columns every sweep dataset has (text: no unit).
SWEEP_COLUMNS = {
    "run_id": (None, "run: the first hex digits of the SHA-256 of its case"),
    "status": (None, "status of the run"),
    "error": (None, "error of a failed run"),
    "seconds": ("s", "wall-clock time of the run"),
    "finished": ("s", "when the run ended, Unix time"),
}

#: A summary key's unit by its last word (docs/user-guide.md, "Summaries and results files").
SUMMARY_UNIT_SUFFIXES = {"_s": "s", "_j": "J", "_hz": "Hz", "_m": "m", "_rad_m": "rad/m", "_bytes": "byte"}


def summary_unit(name: str) -> str:
    """The unit of a flattened summary key (``flatten_summary``): by its suffix (``time_s``: s,
    ``strain_energy_j``: J, ``frequency_hz.bending.1``: Hz, ...), else "1" (counts, ratios)."""
    head = name.split(".", 1)[0]
    suffix = max((s for s in SUMMARY_UNIT_SUFFIXES if head.endswith(s)), key=len, default=None)
    return SUMMARY_UNIT_SUFFIXES[suffix] if suffix else "1"


def flatten_summary(summary: dict) -> dict:
    """A job summary's scalar results by dotted name: nested mappings joined with ``.``, the
    modes of a modal job as ``frequency_hz.<type>.<order>`` (rigid modes left out; a second
    mode of one type and order gets ``.<index>`` appended), its comparison with the reference
    as ``frequency_change.<reference mode label>`` and ``mac.<label>``; lists and the keys of
    :data:`NOT_RESULTS` are left out."""
    out: dict = {}
    for key, value in summary.items():
        if key in NOT_RESULTS:
            continue
        if key == "modes" and isinstance(value, list):
            for row in value:
                if row["type"] == "rigid":
                    continue
                name = f"frequency_hz.{row['type']}.{row['order']}"
                out[name if name not in out else f"{name}.{row['index']}"] = row["frequency_hz"]
        elif key == "comparison" and isinstance(value, list):
            for row in value:
                label = row["reference_label"].replace(" ", "_")
                out[f"frequency_change.{label}"] = row["frequency_change"]
                out[f"mac.{label}"] = row["mac"]
        elif isinstance(value, dict):
            out.update({f"{key}.{k}": v for k, v in flatten_summary(value).items()})
        elif value is None or isinstance(value, bool | int | float | str):
            out[key] = value
    return out


def draw_figures(sweep: Sweep, ds, out: Path) -> list[Path]:
    """Each chosen scalar result against the first varied parameter (``outputs.scalars``, else
    up to :data:`MAX_FIGURES` numeric results that vary), when the sweep varies a number and
    its ``outputs.figures`` is on."""
    if not sweep.runs or not sweep.spec.outputs.figures:
        return []
    numeric = [
        n for n in sweep.spec.parameter_names() if np.issubdtype(ds[n].dtype, np.number) and ds[n].size
    ]
    if not numeric:
        return []
    chosen = sweep.spec.outputs.scalars
    if chosen is None:
        chosen = [
            n
            for n in ds.data_vars
            if ds[n].dims == ("run",)
            and n not in TIMINGS
            and np.issubdtype(ds[n].dtype, np.number)
            and _varies(ds[n].values)
        ][:MAX_FIGURES]
    from peridyn.plotting.sweep import plot_against

    x = numeric[0]
    others = _independent_of(sweep, x, numeric)
    (out / "figures").mkdir(exist_ok=True)
    return [
        plot_against(ds, x, name, others, out / "figures" / f"{name.replace(' ', '_')}.png")
        for name in chosen
        if name in ds and np.issubdtype(ds[name].dtype, np.number) and np.isfinite(ds[name].values).any()
    ]


def _independent_of(sweep: Sweep, x: str, numeric: list[str]) -> list[str]:
    """The varied parameters that tell the lines of a figure against ``x`` apart: those of the
    other blocks; in a product block, the block's others; in a zip or list block, its text
    values (a damage type; the numbers there move with ``x``). Derived ones follow the rest."""
    names = []
    for block in sweep.spec.vary:
        if x not in block.names():
            names += block.names()
        elif block.product is not None:
            names += [n for n in block.names() if n != x]
        else:
            names += [n for n in block.names() if n not in numeric]
    return names


def _varies(values: np.ndarray) -> bool:
    """Whether the finite entries of ``values`` take more than one value."""
    finite = values[np.isfinite(values)]
    return finite.size > 0 and finite.max() > finite.min()
