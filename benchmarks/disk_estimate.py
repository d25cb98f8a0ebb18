"""Disk estimate (``RecorderSpec.output_bytes``) against the bytes a run writes: three spacings of
the bar and the 2D plate, one Markdown table row each (benchmarks/RESULTS.md). Run from the
repository root: ``python benchmarks/disk_estimate.py``."""

import tempfile
import warnings
from pathlib import Path

from peridyn.io.case import load_case
from peridyn.jobs.run import run_case
from peridyn.setup.build import build
from peridyn.setup.recording import recorder_spec
from peridyn.setup.solver_choice import step_count, time_stepper

#: (case file, spacing in m, overrides)
RUNS = [
    *(("cases/bar_pulse.yaml", s, ["solver.time=4e-6"]) for s in ("2e-3", "1e-3", "7e-4")),
    *(("cases/plate2d_precrack_pull.yaml", s, []) for s in ("1e-3", "5e-4", "2.5e-4")),
]


def row(case_file: str, spacing: str, overrides: list) -> str:
    """The table row of one run: points, steps, estimate and bytes written (MB), their ratio."""
    case = load_case(case_file, [*overrides, "output.plots=false", f"discretization.spacing={spacing}"])
    setup = build(case, "cases")
    solver = time_stepper(case, setup)
    n_steps = step_count(case, solver)
    body = setup.whole_body
    spec = recorder_spec(case, body, solver.dt)
    estimate = spec.output_bytes(body.n_points, n_steps, body.dim, setup.damage is not None)
    out = Path(tempfile.mkdtemp())
    run_case(case, out, base_dir="cases")
    written = sum(p.stat().st_size for p in out.rglob("*") if p.is_file())
    cells = [Path(case_file).stem, spacing, body.n_points, n_steps]
    cells += [f"{estimate / 1e6:.2f}", f"{written / 1e6:.2f}", f"{estimate / written:.2f}"]
    return "| " + " | ".join(map(str, cells)) + " |"


if __name__ == "__main__":
    warnings.simplefilter("ignore")  # the bar's snapshot times after its shortened end
    for run in RUNS:
        print(row(*run), flush=True)
