"""peridyn plot DIR: redraw the figures of a finished job from its files: a run's (and its
analyses) from its results.h5, with the crack figures (damage map and crack paths, crack length
against time) of a run with damage; a fatigue job's crack length against cycles
(crack_length.csv); a convergence study's study.png (study.json); a sweep's figures
(dataset.nc)."""

from __future__ import annotations

import json
from pathlib import Path

from peridyn.cli.options import add_common_flags
from peridyn.errors import InputError


def register(sub) -> None:
    """Add the ``plot`` subcommand."""
    what = "redraw the figures of a run, fatigue job, study or sweep"
    p = sub.add_parser("plot", help=what, description=__doc__)
    p.add_argument("run_dir", help="output folder of a run, fatigue job, study or sweep")
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
    for marker, redraw in (("fatigue.json", _fatigue), ("study.json", _study), ("dataset.nc", _sweep)):
        if not h5.is_file() and (out / marker).is_file():
            paths = [str(p) for p in redraw(out)]
            if not args.json:
                for path in paths:
                    print(f"plot: {path}")
            return {"output_dir": str(out), "plots": paths}
    if not h5.is_file():
        raise InputError(
            f"{str(out)!r} holds no results.h5, fatigue.json, study.json or dataset.nc: "
            "not the output folder of a run, fatigue job, study or sweep"
        )
    results = Results(h5)  # read once, handed to the analyses and figures
    info = results.provenance()
    if "case_json" not in info:
        raise InputError(
            f"{str(h5)!r} does not record its case (written by an older peridyn): run the case again"
        )
    case = validate_case(json.loads(info["case_json"]), str(h5))
    if case.solver.type == "modal":
        raise InputError("modal runs draw their figures with `peridyn modal`; nothing to redraw")
    base = Path(info.get("case_file", ".")).parent
    body, _ = add_actuators(case, build_body(case, base))
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
