"""A convergence study: modal runs of one case over a spacing x horizon grid, Richardson fits.

Each run (a level) is the case with ``discretization.spacing`` and ``discretization.horizon``
(a multiple of the spacing) overridden, solved as a ``modal`` run of a sweep
(:func:`run_levels`: :mod:`peridyn.jobs.sweep`, so the levels run on any of its executors,
each in its own folder, and a second study into the same folder skips the levels already
complete); the analysis reads the sweep's dataset (:func:`runs_from_dataset`).
Modes are matched across runs by type and order ("1st bending", ...; rigid and
unclassified modes are left out) and each series of runs is extrapolated with
:func:`peridyn.analysis.convergence.richardson`. The series (Freimanis 2019, section 6.1,
after Bobaru et al. 2009):

- ``delta-m``: horizon factor m = delta/h fixed, spacing h -> 0 (so delta -> 0 too); the
  fit variable is h;
- ``delta``: spacing fixed, horizon delta -> 0; the fit variable is delta (m);
- ``m``: horizon delta (m) fixed, spacing -> 0 (m grows); the fit variable is h. Runs are
  grouped by equal delta, so the grid must hold such runs (e.g. 2 mm x 3 and 3 mm x 2).
"""

from __future__ import annotations

import csv
import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from peridyn.analysis.convergence import ConvergenceError, richardson
from peridyn.discretization.bonds import horizon_metres
from peridyn.errors import CaseFileError, InputError
from peridyn.io.case import load_case, parse_yaml
from peridyn.io.job_files import write_summary
from peridyn.io.results import Results
from peridyn.jobs.summary import finish_summary
from peridyn.setup.recording import RESULTS

#: The kinds of series a study can fit, see the module docstring.
SERIES = ("delta-m", "delta", "m")
#: Mode types not matched across runs (no single mode to follow).
UNMATCHED_TYPES = ("rigid", "other")
#: Horizons (m) equal to this relative tolerance form one ``m`` series.
SAME_HORIZON = 1e-6
#: The study's sweep file in its folder (``peridyn sweep`` runs it too).
SWEEP_FILE = "study-sweep.yaml"
#: The sweep parameters of a level: its spacing (m) and horizon (a multiple of the spacing).
SPACING, HORIZON = "discretization.spacing", "discretization.horizon"
#: Prefix of a mode's frequency (Hz) in a modal sweep's dataset (``jobs.sweep.flatten_summary``).
FREQUENCY = "frequency_hz"


@dataclass
class StudyRun:
    """One level of the study: a modal run of the grid.

    ``modes`` maps a mode label ("1st bending") to its frequency in Hz (the lowest if the
    label occurs twice); ``bonds`` counts directed bonds; ``seconds`` is the level's run time
    (build, solve and its files); ``skipped`` holds the level's status (``failed: <reason>``)
    when it did not complete, and it is left out of the fits.
    """

    spacing: float
    horizon_factor: float
    points: int = 0
    bonds: int = 0
    seconds: float = 0.0
    modes: dict[str, float] = field(default_factory=dict)
    skipped: str | None = None
    notes: list[str] = field(default_factory=list)

    @property
    def horizon(self) -> float:
        """Horizon delta in metres."""
        return horizon_metres(None, self.horizon_factor, self.spacing)

    def to_dict(self) -> dict:
        return {
            "spacing_m": self.spacing,
            "horizon_factor": self.horizon_factor,
            "horizon_m": self.horizon,
            "points": self.points,
            "bonds": self.bonds,
            "seconds": self.seconds,
            "modes": self.modes,
            "skipped": self.skipped,
            "notes": self.notes,
        }

    @classmethod
    def from_dict(cls, row: dict) -> StudyRun:
        """The run a ``to_dict`` row (of ``study.json``) describes."""
        return cls(
            row["spacing_m"], row["horizon_factor"], row["points"], row["bonds"], row["seconds"],
            dict(row["modes"] or {}), row["skipped"], list(row["notes"]),
        )  # fmt: skip


def study_sweep(case_path, spacings, horizon_factors, n_modes: int | None = None, overrides=()) -> dict:
    """The sweep file (as a dict) whose runs are the study's levels.

    A ``modal`` sweep of the case over the product of ``discretization.horizon`` (outer) and
    ``discretization.spacing`` (inner), with ``set``: ``output.plots`` false (the study draws
    its own figure; an override may turn the modes' figures back on), then ``overrides``
    ("key=value", values read as YAML, as ``--set`` reads them), then ``solver.modes`` (when
    ``n_modes`` is given) and ``discretization.horizon_m`` null, so that the horizon is the
    multiple of the spacing.
    """
    settings: dict = {"output.plots": False}
    for item in overrides:
        key, sep, text = item.partition("=")
        if not sep:
            raise CaseFileError(str(case_path), item, None, "an override of the form key.path=value")
        settings.pop(key.strip(), None)  # the last one given wins, as it does for --set
        settings[key.strip()] = parse_yaml(text)
    if n_modes is not None:
        settings.pop("solver.modes", None)
        settings["solver.modes"] = n_modes
    settings.pop("discretization.horizon_m", None)
    settings["discretization.horizon_m"] = None
    return {
        "name": f"{Path(case_path).stem}-study",
        "description": "the levels of a peridyn study (spacing x horizon)",
        "base": str(Path(case_path).resolve()),
        "command": "modal",
        "set": settings,
        "vary": {
            "product": {
                HORIZON: [float(m) for m in horizon_factors],
                SPACING: [float(h) for h in spacings],
            }
        },
        "outputs": {"figures": False},
    }


def run_levels(
    case_path,
    spacings,
    horizon_factors,
    out,
    n_modes: int | None = None,
    overrides=(),
    executor: str = "serial",
    workers: int = 1,
    scheduler: str | None = None,
    overwrite: bool = False,
    progress=None,
    command: str | None = None,
    threads: int | None = None,
) -> tuple[list[StudyRun], dict]:
    """Solve the modal problem of every (spacing, horizon factor) level as a sweep.

    The sweep file :func:`study_sweep` is written to ``out/`` :data:`SWEEP_FILE` and run by
    :func:`peridyn.jobs.sweep.run_sweep` into ``out`` (each level in ``out/runs/<id>/``, the
    dataset ``out/dataset.nc``); a level already complete there for the same case is not run
    again unless ``overwrite``. A level that fails is recorded and the others go on.

    Parameters
    ----------
    case_path : str or Path
        A case file (any solver type; it is run as ``modal``).
    spacings : sequence of float, m
    horizon_factors : sequence of float
        Horizons as multiples of the spacing.
    out : path
        The study's folder.
    n_modes : int or None
        Modes per run (rigid included); None keeps the case's ``solver.modes``.
    overrides : sequence of "key=value"
        Applied to every run before the spacing and horizon.
    executor, workers, scheduler, overwrite, command, threads
        As for :func:`peridyn.jobs.sweep.run_sweep`.
    progress : callable(str) or None
        Receives one line per level as it ends.

    Returns
    -------
    (runs, sweep summary)
        The levels in sweep order (:func:`runs_from_dataset`) and ``run_sweep``'s summary.

    Raises
    ------
    peridyn.jobs.sweep.SweepInterrupted
        Ctrl-C: the levels finished so far are kept; the same command runs the others.
    """
    from peridyn.io.dataset import load_sweep
    from peridyn.jobs.sweep import run_sweep

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    spec = study_sweep(case_path, spacings, horizon_factors, n_modes, overrides)
    path = out / SWEEP_FILE
    try:
        path.write_text(json.dumps(spec, indent=1) + "\n")  # JSON is YAML: floats read back bit for bit
    except (TypeError, ValueError) as exc:
        raise InputError(f"--set: a value the study cannot write to its sweep file ({exc})") from None
    total = len(spacings) * len(horizon_factors)
    ended = []

    def report(record: dict) -> None:
        ended.append(record)
        params = record["parameters"]
        summary = record.get("summary") or {}
        points = f"{summary['points']} points, " if "points" in summary else ""
        progress(
            f"[{len(ended)}/{total}] spacing {params[SPACING] * 1e3:g} mm, horizon {params[HORIZON]:g} h: "
            f"{points}{record['seconds']:.1f} s, {record['status']}"
        )

    summary = run_sweep(
        path,
        out,
        executor=executor,
        workers=workers,
        threads=threads,
        scheduler=scheduler,
        overwrite=overwrite,
        command=command,
        on_record=None if progress is None else report,
        job_files_of_its_own=False,  # the study's folder: its own status, provenance and summary
    )
    case = load_case(case_path, overrides)
    return runs_from_dataset(load_sweep(summary["dataset"]), out, case), summary


def runs_from_dataset(ds, out, case) -> list[StudyRun]:
    """The study's levels from its sweep's dataset (:mod:`peridyn.io.dataset`), in its order.

    A complete level's ``modes`` are the dataset's ``frequency_hz.<type>.<order>`` (rigid and
    unclassified modes left out; a second mode of one type and order, ``...<index>``, is noted
    and left out: the first is the lower); ``points`` and ``bonds`` are its own, ``seconds``
    its run's time. A level that did not complete gets its status as ``skipped``.

    Parameters
    ----------
    ds : xarray.Dataset
        The dataset of :func:`run_levels`'s sweep (dimension ``run``).
    out : path
        The study's folder (the levels' ``runs/<id>/results.h5`` give the grid notes).
    case : Case
        The study's case with its overrides (geometry of the grid notes).
    """
    from peridyn.jobs.modal import mode_label

    names = [n for n in ds.data_vars if n.startswith(FREQUENCY + ".") and ds[n].dims == ("run",)]
    runs = []
    for i in range(ds.sizes["run"]):
        run = StudyRun(float(ds[SPACING].values[i]), float(ds[HORIZON].values[i]))
        run.seconds = float(ds["seconds"].values[i])
        status = str(ds["status"].values[i])
        if status != "complete":
            run.skipped = status
            runs.append(run)
            continue
        run.points = int(ds["points"].values[i])
        run.bonds = int(ds["bonds"].values[i])
        points = Results(Path(out) / "runs" / str(ds["run_id"].values[i]) / RESULTS).array("geometry/points")
        run.notes += _geometry_notes(case, points, run.spacing)
        found = []
        for name in names:
            value = float(ds[name].values[i])
            _, kind, order, *second = name.split(".")
            if np.isnan(value) or kind in UNMATCHED_TYPES:
                continue
            found.append((value, mode_label({"type": kind, "order": int(order)}), bool(second)))
        for value, label, second in sorted(found):
            if second:
                run.notes.append(f"two modes classified {label}: kept the lower one")
            else:
                run.modes[label] = value
        runs.append(run)
    return runs


def _geometry_notes(case, points, spacing: float) -> list[str]:
    """Warn when a box's sides are not whole multiples of the spacing (the grid rounds them).

    ``points`` (n_points, 3) m: the level's grid; ``spacing`` m: its cell side."""
    if case.geometry.type != "box":
        return []
    grid = np.ptp(points, axis=0) + np.full(3, spacing)
    size = np.asarray(case.geometry.size, dtype=float)
    if np.allclose(grid, size, rtol=1e-6, atol=0.0):
        return []
    dims = " x ".join(f"{v * 1e3:.4g}" for v in grid)
    return [
        f"the grid spans {dims} mm, not the case's "
        f"{' x '.join(f'{v * 1e3:.4g}' for v in size)} mm: the spacing does not divide the box, "
        "so this run models another body"
    ]


def fit_series(
    runs: list[StudyRun], series=("delta-m",), references=None, finest: int | None = None
) -> list[dict]:
    """Richardson fits of every mode over every series of runs.

    Returns one dict per (series, group, mode): ``series``, ``group`` (what is held fixed),
    ``variable`` (``spacing_m`` or ``horizon_m``), ``x`` and ``frequencies_hz`` (finest
    first), and either ``value_hz``, ``order``, ``gci``, ``rms_residual_hz`` or, when no
    value exists, ``error``: why (fewer than three runs with the mode; an oscillating,
    stagnating or diverging sequence, with its numbers).
    With ``references`` (label -> Hz), ``reference_hz`` and the relative errors of the
    extrapolated and of the finest value are added. With ``finest``, only that many of the
    finest runs of each series enter the fit (the asymptotic range, Freimanis 2019 section 6.1);
    ``fitted_runs`` says how many did.
    """
    if finest is not None and finest < 3:
        raise InputError(f"finest = {finest}: a Richardson fit needs at least three runs")
    unknown = [s for s in series if s not in SERIES]
    if unknown:
        raise InputError(f"unknown convergence series {unknown}: expected some of {', '.join(SERIES)}")
    solved = [r for r in runs if r.skipped is None]
    labels = _labels_in_order(solved)
    fits = []
    for kind in series:
        for group, members, variable in _groups(solved, kind):
            for label in labels:
                having = [r for r in members if label in r.modes]
                if not having:
                    continue
                x = np.array([r.spacing if variable == "spacing_m" else r.horizon for r in having])
                f = np.array([r.modes[label] for r in having])
                order = np.argsort(x)
                row = {
                    "series": kind,
                    "group": group,
                    "mode": label,
                    "variable": variable,
                    "x": x[order].tolist(),
                    "frequencies_hz": f[order].tolist(),
                }
                try:
                    fit = richardson(x[order][:finest], f[order][:finest])
                except ConvergenceError as exc:
                    row["error"] = str(exc)
                except InputError as exc:
                    row["error"] = f"{len(having)} run(s) with this mode: {exc}"
                else:
                    row.update(
                        fitted_runs=len(fit.spacings),
                        value_hz=fit.value,
                        order=fit.order,
                        gci=fit.gci,
                        coefficient=fit.coefficient,
                        rms_residual_hz=fit.rms_residual,
                    )
                if references and label in references:
                    ref = references[label]
                    row["reference_hz"] = ref
                    row["finest_error"] = row["frequencies_hz"][0] / ref - 1
                    row["value_error"] = row["value_hz"] / ref - 1 if "value_hz" in row else None
                fits.append(row)
    return fits


def check_enough_levels(runs: list[StudyRun], series=("delta-m",)) -> None:
    """Refuse a study whose failed levels leave no series group with the three solved levels a
    Richardson fit needs (a study that asked for fewer levels is fitted as asked, each fit
    saying why it has no limit).

    Raises
    ------
    InputError
        Naming the failed levels and why each failed.
    """
    failed = [r for r in runs if r.skipped is not None]
    solved = [r for r in runs if r.skipped is None]
    wanted = max((len(members) for kind in series for _, members, _ in _groups(runs, kind)), default=0)
    fittable = max((len(members) for kind in series for _, members, _ in _groups(solved, kind)), default=0)
    if failed and wanted >= 3 > fittable:
        reasons = "; ".join(
            f"spacing {r.spacing * 1e3:g} mm, horizon {r.horizon_factor:g} h: {r.skipped}" for r in failed
        )
        raise InputError(
            f"{len(failed)} of {len(runs)} levels did not complete, leaving no series with the three "
            f"levels a Richardson fit needs ({reasons}); the completed levels are kept: run the study "
            "again to retry the others"
        )


def _labels_in_order(runs: list[StudyRun]) -> list[str]:
    """Mode labels of all runs, ordered by their frequency in the finest run having them."""
    best: dict[str, tuple[float, float]] = {}
    for r in runs:
        for label, freq in r.modes.items():
            if label not in best or r.spacing < best[label][0]:
                best[label] = (r.spacing, freq)
    return sorted(best, key=lambda label: best[label][1])


def _groups(runs: list[StudyRun], kind: str):
    """(group label, runs, fit variable) of one kind of series."""
    if kind == "delta-m":
        for m in sorted({r.horizon_factor for r in runs}):
            yield f"horizon {m:g} h", [r for r in runs if r.horizon_factor == m], "spacing_m"
    elif kind == "delta":
        for h in sorted({r.spacing for r in runs}):
            yield f"spacing {h * 1e3:g} mm", [r for r in runs if r.spacing == h], "horizon_m"
    else:
        horizons: list[float] = []
        for r in sorted(runs, key=lambda r: r.horizon):
            if not horizons or r.horizon > horizons[-1] * (1 + SAME_HORIZON):
                horizons.append(r.horizon)
        for d in horizons:
            members = [r for r in runs if abs(r.horizon - d) <= SAME_HORIZON * d]
            yield f"horizon {d * 1e3:.4g} mm", members, "spacing_m"


def write_study(
    out: Path, runs: list[StudyRun], fits: list[dict], meta: dict, start: float, plots=()
) -> dict:
    """Write ``runs.csv`` (one row per run and mode), ``study.csv`` (one row per fit) and
    ``study.json`` (everything, also the output contract's ``summary.json``:
    ``peridyn.io.job_files``); returns the JSON summary (docs/user-guide.md, "Summaries and
    results files"). ``start``: ``time.perf_counter()`` when the study started; ``plots``: the
    figures drawn."""
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "runs.csv", "w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(
            [
                "spacing_m",
                "horizon_factor",
                "horizon_m",
                "points",
                "seconds",
                "mode",
                "frequency_hz",
                "skipped",
            ]
        )
        for r in runs:
            for label, freq in r.modes.items() if r.modes else [("", "")]:
                writer.writerow(
                    [
                        r.spacing,
                        r.horizon_factor,
                        r.horizon,
                        r.points,
                        round(r.seconds, 3),
                        label,
                        freq,
                        r.skipped or "",
                    ]
                )
    columns = [
        "series",
        "group",
        "mode",
        "variable",
        "x",
        "frequencies_hz",
        "fitted_runs",
        "value_hz",
        "order",
        "gci",
        "coefficient",
        "rms_residual_hz",
        "reference_hz",
        "finest_error",
        "value_error",
        "error",
    ]
    with open(out / "study.csv", "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=columns)
        writer.writeheader()
        for row in fits:
            writer.writerow(
                {
                    k: (
                        " ".join(f"{v:.10g}" for v in row[k])
                        if isinstance(row.get(k), list)
                        else row.get(k, "")
                    )
                    for k in columns
                }
            )
    summary = {
        **meta,
        "runs": [r.to_dict() for r in runs],
        "fits": fits,
        "skipped_runs": sum(r.skipped is not None for r in runs),
    }
    finish_summary(summary, "study", out, start, plots)
    (out / "study.json").write_text(json.dumps(summary, indent=1))
    write_summary(out, summary)
    return summary
