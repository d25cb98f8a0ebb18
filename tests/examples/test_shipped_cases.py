"""Every shipped case file validates, builds and runs (shortened) from the command line, and
its summary has the common keys with their documented meanings (docs/user-guide.md,
"Summaries and results files")."""

import json
import time
from pathlib import Path

import numpy as np
import pytest

from peridyn.cli import main
from peridyn.io.case import load_case
from peridyn.io.hdf5 import SCHEMA_VERSION
from peridyn.io.results import Results
from peridyn.jobs.summary import peak_memory_bytes
from peridyn.setup.build import build

ROOT = Path(__file__).resolve().parents[2]
CASES = sorted((ROOT / "cases").glob("*.yaml"))
FATIGUE_CASES = [p for p in CASES if load_case(p).fatigue is not None]
SHORTEN = {
    "explicit": ["--set", "solver.time=0.3e-6"],
    "static": ["--set", "solver.tolerance=1e-3"],
    "modal": ["--set", "solver.modes=8"],
}
#: Three fatigue steps, no Paris fit (as benchmarks/case_summaries.py shortens them).
FATIGUE_SHORT = ["--set", "fatigue.mapping=[{steps: 3, tau: 1.0e-6}]", "--set", "fatigue.paris=null"]


def _job(args: list[str], out: Path, capsys) -> tuple[dict, float]:
    """Run a command with ``--json`` into ``out``, figures off; its summary and wall time (s)."""
    start = time.perf_counter()
    status = main([*args, "--json", "--no-progress", "-o", str(out), "--set", "output.plots=false"])
    elapsed = time.perf_counter() - start
    assert status == 0
    return json.loads(capsys.readouterr().out), elapsed


def _check_common_keys(summary: dict, kind: str, out: Path, elapsed: float) -> None:
    """The keys every summary has (docs/user-guide.md): schema, kind, the output folder, no
    figures with plots off, the job's time within the command's wall time, and a peak memory
    no larger than this process's peak since."""
    assert summary["schema_version"] == SCHEMA_VERSION and summary["kind"] == kind
    assert summary["output_dir"] == str(out) and summary["plots"] == []
    assert 0.0 < summary["seconds"] <= elapsed
    assert 0 < summary["peak_memory_bytes"] <= peak_memory_bytes()


@pytest.mark.parametrize("path", CASES, ids=[p.stem for p in CASES])
def test_case_runs(path, tmp_path, capsys):
    """Each case runs; its summary (stored in results.h5 as printed) has the common keys and
    counts the points of the stored geometry; a time-stepping run's ``step_seconds`` (its time
    loop, docs/user-guide.md) is part of its ``seconds``."""
    case = load_case(path)
    summary, elapsed = _job(["run", str(path), *SHORTEN[case.solver.type]], tmp_path, capsys)
    _check_common_keys(summary, "modal" if case.solver.type == "modal" else "run", tmp_path, elapsed)
    if case.solver.type in ("explicit", "newmark"):
        assert 0.0 < summary["step_seconds"] < summary["seconds"]
    else:
        assert "step_seconds" not in summary
    results = Results(tmp_path / "results.h5")
    assert results.schema_version == SCHEMA_VERSION and results.summary() == summary
    assert summary["points"] == len(results.array("geometry/points"))
    assert 0 <= summary.get("broken_bonds", 0) <= summary["bonds"]


@pytest.mark.parametrize("path", FATIGUE_CASES, ids=[p.stem for p in FATIGUE_CASES])
def test_fatigue_summary_counts_bonds_as_a_run_does(path, tmp_path, capsys):
    """A fatigue job's summary has the common keys, and its bond counts are directed as a run's
    are: ``bonds`` equals the run's of the same case and ``Bonds.n_bonds`` of the built case;
    ``broken_bonds`` is the bonds broken by the cycles plus those the pre-cracks cut (not
    intact once built); the history's last count is the summary's."""
    fatigue, elapsed = _job(["fatigue", str(path), *FATIGUE_SHORT], tmp_path / "fatigue", capsys)
    _check_common_keys(fatigue, "fatigue", tmp_path / "fatigue", elapsed)
    assert json.loads((tmp_path / "fatigue" / "fatigue.json").read_text()) == fatigue
    case = load_case(path)
    run, _ = _job(["run", str(path), *SHORTEN[case.solver.type]], tmp_path / "run", capsys)
    setup = build(case, path.parent)
    assert fatigue["bonds"] == run["bonds"] == setup.bonds.n_bonds
    assert fatigue["points"] == run["points"] == setup.body.n_points
    pre_cracked = int(np.count_nonzero(~setup.bonds.intact))
    assert fatigue["broken_bonds"] == fatigue["fatigue_broken_bonds"] + pre_cracked
    history = np.loadtxt(tmp_path / "fatigue" / "crack_length.csv", delimiter=",", skiprows=1, ndmin=2)
    assert history[-1, 2] == fatigue["fatigue_broken_bonds"]


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
