"""Every shipped case file validates, builds and runs (shortened) from the command line."""

import json
from pathlib import Path

import pytest

from peridyn.cli import main

ROOT = Path(__file__).resolve().parents[2]
CASES = sorted((ROOT / "cases").glob("*.yaml"))
SHORTEN = {
    "explicit": ["--set", "solver.time=0.3e-6"],
    "static": ["--set", "solver.tolerance=1e-3"],
    "modal": ["--set", "solver.modes=8"],
}


@pytest.mark.parametrize("path", CASES, ids=[p.stem for p in CASES])
def test_case_runs(path, tmp_path, capsys):
    from peridyn.io.case import load_case

    case = load_case(path)
    args = [
        "run",
        str(path),
        "--json",
        "--no-progress",
        "-o",
        str(tmp_path),
        "--set",
        "output.plots=false",
        *SHORTEN[case.solver.type],
    ]
    assert main(args) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["points"] > 0 and (tmp_path / "results.h5").is_file()


def test_demo_runs_shortened(tmp_path, capsys, monkeypatch):
    """The README's main job, with the packaged case cut to a few steps."""
    from peridyn.cli import demo_cmd, run_cmd

    original = run_cmd.run

    def short(ns):
        ns.overrides = ["solver.time=0.2e-6"]
        return original(ns)

    monkeypatch.setattr(run_cmd, "run", short)
    assert main(["demo", "--json", "--no-progress", "-o", str(tmp_path)]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert {Path(p).name for p in summary["plots"]} >= {"sensors.png", "bscan_x_axis.png", "displacement.png"}
    assert demo_cmd.DEMO_CASE.endswith(".yaml")
