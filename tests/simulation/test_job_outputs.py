"""Every job kind leaves the same three files in its output folder, the output contract of
``peridyn.io.job_files``: ``status.json``, ``provenance.json`` (what made the results) and
``summary.json`` (its summary, whose ``kind`` names the job); and ``peridyn plot`` redraws the
figures of the folder of any of them. Small versions of the shipped cases, seconds each."""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path

import pytest
import yaml

import peridyn
from peridyn.cli import main
from peridyn.io.job_files import read_job

ROOT = Path(__file__).resolve().parents[2]
CASES = ROOT / "cases"
#: The PMMA plate of tests/simulation/test_study.py, whose spacings divide its sides.
PLATE = ["--set", "geometry.size=[0.096,0.048,0.008]", "--set", "output.plots=true"]


def _sweep_file(folder: Path) -> str:
    """Two runs of the coarse bar of cases/bar_pulse.yaml, 2 us each."""
    path = folder / "tiny.yaml"
    spec = {
        "base": str(CASES / "bar_pulse.yaml"),
        "set": {
            "discretization.spacing": 2.5e-3,
            "output.snapshot_times": [],
            "output.lines": {},
            "output.plots": False,
            "solver.time": 2e-6,
        },
        "vary": {"product": {"material.E": [150e9, 200e9]}},
        "outputs": {"figures": False},
    }
    path.write_text(yaml.safe_dump(spec))
    return str(path)


#: The command line of each job kind (its output folder added by the test).
JOBS = {
    "run": lambda tmp: ["run", str(CASES / "bar_pulse.yaml"), "--set", "discretization.spacing=2.5e-3",
                        "--set", "solver.time=2e-6", "--no-progress"],
    "modal": lambda tmp: ["modal", str(CASES / "pmma_plate.yaml"), *PLATE, "--set",
                          "discretization.spacing=4e-3", "--modes", "8"],
    "fatigue": lambda tmp: ["fatigue", str(CASES / "sen_fatigue_2d.yaml"), "--set",
                            "fatigue.mapping=[{steps: 3, tau: 1.0e-6}]", "--set", "fatigue.paris=null",
                            "--no-progress"],
    "study": lambda tmp: ["study", str(CASES / "pmma_plate.yaml"), *PLATE, "--spacing",
                          "0.004,0.0026666666666666666,0.002", "--horizon", "1.4143", "--modes", "8"],
    "sweep": lambda tmp: ["sweep", _sweep_file(tmp), "--no-progress"],
}  # fmt: skip


@pytest.mark.parametrize("kind", list(JOBS))
def test_every_job_leaves_its_status_provenance_and_summary(kind, tmp_path, capsys):
    out = tmp_path / "out"
    stdout = io.StringIO()
    with contextlib.redirect_stdout(stdout):
        assert main([*JOBS[kind](tmp_path), "-o", str(out), "--json"]) == 0
    printed = json.loads(stdout.getvalue())
    job = read_job(out)
    assert job["status"] == "complete"
    assert job["provenance"]["peridyn_version"] == peridyn.__version__
    assert job["provenance"]["command_line"]  # the command that made the results
    assert job["provenance"]["case_file"] == JOBS[kind](tmp_path)[1]  # the case (sweep) file given
    assert job["summary"]["kind"] == kind
    assert job["summary"]["output_dir"] == printed["output_dir"] == str(out)
    assert {k: v for k, v in job["summary"].items() if k != "comparison"} == {
        k: v for k, v in printed.items() if k in job["summary"]
    }
    capsys.readouterr()
    assert main(["plot", str(out), "--json"]) == 0, capsys.readouterr().err
    redrawn = json.loads(capsys.readouterr().out)["plots"]
    assert all(Path(p).stat().st_size > 0 for p in redrawn)


@pytest.mark.parametrize(
    "job, message",
    [("modal", "a modal job needs solver.type: modal, not 'explicit'"), ("bloch", "a job is one of")],
)
def test_the_job_dispatch_refuses_what_it_cannot_run(job, message, tmp_path):
    """``run_job`` names the job it cannot run, before building or writing anything."""
    from peridyn.errors import InputError
    from peridyn.io.case import load_case
    from peridyn.jobs.dispatch import run_job

    with pytest.raises(InputError, match=message):
        run_job(job, load_case(CASES / "bar_pulse.yaml"), tmp_path / "out")
    assert not (tmp_path / "out").exists()
