"""peridyn plot RUN_DIR: redraw the figures (and analyses) of a finished run from its HDF5,
with the crack figures (damage map and crack paths, crack length against time) of a run with
damage."""

from __future__ import annotations

import json
from pathlib import Path

from peridyn.cli.options import add_common_flags
from peridyn.errors import InputError


def register(sub) -> None:
    """Add the ``plot`` subcommand."""
    p = sub.add_parser("plot", help="redraw a run's figures from its results.h5", description=__doc__)
    p.add_argument("run_dir", help="output folder of a run (holds results.h5)")
    add_common_flags(p)
    p.set_defaults(func=run)


def run(args) -> dict:
    """Rebuild the run's case from its provenance and draw its figures again (with the crack
    paths of the final damage for a run with damage)."""
    from peridyn.io.case import validate_case
    from peridyn.io.results import Results
    from peridyn.jobs.build import add_actuators, build_body
    from peridyn.jobs.figures import draw_run_figures, redraw_crack_figures
    from peridyn.jobs.lamb_analysis import analyse

    out = Path(args.run_dir)
    results = out / "results.h5"
    if not results.is_file():
        raise InputError(f"{str(out)!r} holds no results.h5: not the output folder of a run")
    info = Results(results).provenance()
    if "case_json" not in info:
        raise InputError(
            f"{str(results)!r} does not record its case (written by an older peridyn): run the case again"
        )
    case = validate_case(json.loads(info["case_json"]), str(results))
    if case.solver.type == "modal":
        raise InputError("modal runs draw their figures with `peridyn modal`; nothing to redraw")
    base = Path(info.get("case_file", ".")).parent
    body, _ = add_actuators(case, build_body(case, base))
    analysis, figures = analyse(case, body, out, plots=True)
    cracks, crack_figures = redraw_crack_figures(case, body, out)
    paths = [str(p) for p in [*draw_run_figures(case, body, out), *figures, *crack_figures]]
    if not args.json:
        for path in paths:
            print(f"plot: {path}")
    result = {"output_dir": str(out), "plots": paths, **analysis}
    if cracks is not None:
        result["crack_paths"] = [c.summary() for c in cracks]
    return result
