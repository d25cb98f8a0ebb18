"""peridyn plot DIR: redraw the figures of a finished job from its files: a run's (and its
analyses) from its results.h5, with the crack figures (damage map and crack paths, crack length
against time) of a run with damage; a modal run's modes.png; a fatigue job's crack length
against cycles (crack_length.csv); a convergence study's study.png (study.json); a sweep's
figures (dataset.nc); a monitoring job's figures (monitoring.nc, docs/monitoring.md). The job's
kind is its summary.json's (docs/user-guide.md)."""

from __future__ import annotations

import json
from pathlib import Path

from peridyn.cli.options import add_common_flags
from peridyn.errors import InputError


def register(sub) -> None:
    """Add the ``plot`` subcommand."""
    what = "redraw the figures of a run, fatigue job, study, sweep or monitoring job"
    p = sub.add_parser("plot", help=what, description=__doc__)
    p.add_argument("run_dir", help="output folder of a run, fatigue job, study, sweep or monitoring job")
    add_common_flags(p)
    p.set_defaults(func=run)


def run(args) -> dict:
    """Rebuild the run's case from its provenance and draw its figures again (with the crack
    paths of the final damage for a run with damage)."""
    from peridyn.io.case import validate_case
    from peridyn.io.results import Results
    from peridyn.jobs.figures import draw_run_figures, redraw_crack_figures
    from peridyn.jobs.lamb_analysis import analyse
    from peridyn.setup.build import add_actuators, build_body

    out = Path(args.run_dir)
    h5 = out / "results.h5"
    kind = job_kind(out)
    redraw = {"fatigue": _fatigue, "study": _study, "sweep": _sweep, "monitor": _monitor}.get(kind)
    if redraw is not None:
        paths = [str(p) for p in redraw(out)]
        if not args.json:
            for path in paths:
                print(f"plot: {path}")
        return {"output_dir": str(out), "plots": paths}
    results = Results(h5)  # read once, handed to the analyses and figures
    info = results.provenance()
    if "case_json" not in info:
        raise InputError(
            f"{str(h5)!r} does not record its case (written by an older peridyn): run the case again"
        )
    case = validate_case(json.loads(info["case_json"]), str(h5))
    base = Path(info.get("case_file", ".")).parent
    body, _ = add_actuators(case, build_body(case, base))
    if case.solver.type == "modal":
        from peridyn.jobs.modal import redraw_mode_shapes

        paths = [str(redraw_mode_shapes(body, results))]
        if not args.json:
            print(f"plot: {paths[0]}")
        return {"output_dir": str(out), "plots": paths}
    analysis, figures = analyse(case, body, results, plots=True)
    cracks, crack_figures = redraw_crack_figures(case, body, results)
    paths = [str(p) for p in [*draw_run_figures(case, body, results), *figures, *crack_figures]]
    if not args.json:
        for path in paths:
            print(f"plot: {path}")
    result = {"output_dir": str(out), "plots": paths, **analysis}
    if cracks is not None:
        result["crack_paths"] = [c.summary() for c in cracks]
    return result


#: The file that marks each kind of job's folder written before the output contract's
#: ``summary.json`` (``peridyn.io.job_files``), and the kind it marks.
MARKERS = {"results.h5": "run", "fatigue.json": "fatigue", "study.json": "study", "dataset.nc": "sweep"}


def job_kind(out: Path) -> str:
    """The kind of the job whose output folder is ``out`` (``run``, ``modal``, ``fatigue``,
    ``study``, ``sweep``, ``monitor``): its ``summary.json``'s ``kind``, else the file that marks it.

    Raises
    ------
    InputError
        ``out`` is not the output folder of a job.
    """
    from peridyn.io.job_files import SUMMARY_FILE

    summary = out / SUMMARY_FILE
    if summary.is_file():
        try:
            return str(json.loads(summary.read_text())["kind"])
        except (ValueError, KeyError, TypeError) as exc:
            raise InputError(f"{str(summary)!r} is not a job summary ({exc})") from None
    for marker, kind in MARKERS.items():
        if (out / marker).is_file():
            return kind
    raise InputError(
        f"{str(out)!r} holds no results.h5, fatigue.json, study.json or dataset.nc (nor a job's "
        "summary.json): not the output folder of a run, fatigue job, study or sweep"
    )


def _fatigue(out: Path) -> list[Path]:
    """Crack length against cycles from ``crack_length.csv``."""
    import numpy as np

    from peridyn.plotting.fatigue import plot_crack_length

    history = np.loadtxt(out / "crack_length.csv", delimiter=",", skiprows=1, ndmin=2)
    return [plot_crack_length(history[:, 0], history[:, 1], out / "crack_length.png")]


def _study(out: Path) -> list[Path]:
    """The delta-m convergence figure from ``study.json``."""
    from peridyn.jobs.study import StudyRun
    from peridyn.plotting.convergence import plot_convergence

    study = json.loads((out / "study.json").read_text())
    runs = [StudyRun.from_dict(row) for row in study["runs"]]
    plot_convergence(runs, study["fits"], out / "study.png", title=f"{study['case']}: delta-m convergence")
    return [out / "study.png"]


def _sweep(out: Path) -> list[Path]:
    """The sweep's figures from ``dataset.nc`` and its sweep file (still where it was)."""
    from peridyn.io.dataset import load_sweep
    from peridyn.jobs.sweep import draw_figures
    from peridyn.jobs.sweep_spec import expand

    ds = load_sweep(out / "dataset.nc")
    return draw_figures(expand(ds.attrs["sweep_file"]), ds, out)


def _monitor(out: Path) -> list[Path]:
    """A monitoring job's figures from ``monitoring.nc``."""
    from peridyn.jobs.monitor_output import redraw_figures

    return redraw_figures(out)
