"""SIGINT/SIGTERM during the jobs without time steps (modal, static, fatigue, study): the job
stops at its solver's next safe point, says what it was doing, exits 130/143 and leaves its
status (issue 17, items 2 and 4). The signal is sent by the job's own process right after the
model is built, so that it lands in the solver."""

from __future__ import annotations

import json
import os
import signal
from pathlib import Path

import pytest

from peridyn.cli import main
from peridyn.io.outdir import read_status
from peridyn.io.results import Results

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture
def signal_after_build(monkeypatch):
    """Make the ``build`` of the given job module send ``sig`` to this process when it returns."""

    def arm(module: str, sig: int) -> None:
        import importlib

        jobs = importlib.import_module(module)
        real = jobs.build

        def build_then_signal(*args, **kwargs):
            setup = real(*args, **kwargs)
            os.kill(os.getpid(), sig)
            return setup

        monkeypatch.setattr(jobs, "build", build_then_signal)

    return arm


def _run(argv, capsys):
    status = main([*argv, "--json"])
    captured = capsys.readouterr()
    assert "Traceback" not in captured.err
    return status, json.loads(captured.out), captured.err.strip().splitlines()[-1]


@pytest.mark.parametrize(
    "case, sets, where",
    [
        ("pmma_plate.yaml", ["discretization.spacing=4e-3"], "computing the modes"),
        ("bar_tension_static.yaml", ["discretization.spacing=2e-3"], "relaxing to equilibrium"),
    ],
)
def test_modal_and_static_runs_stop_in_their_solver(case, sets, where, signal_after_build, capsys, tmp_path):
    signal_after_build("peridyn.jobs.run", signal.SIGINT)
    argv = ["run", str(ROOT / "cases" / case), "-o", str(tmp_path), "--set", "output.plots=false"]
    for s in sets:
        argv += ["--set", s]
    status, error, line = _run(argv, capsys)
    assert status == 130
    assert error["error"] == f"interrupted (SIGINT) while {where}"
    assert line == f"peridyn run: interrupted (SIGINT) while {where}"
    assert Results(tmp_path / "results.h5").status() == f"interrupted while {where}"


def test_a_fatigue_run_stops_between_cycle_blocks(signal_after_build, capsys, tmp_path):
    signal_after_build("peridyn.jobs.fatigue", signal.SIGTERM)
    argv = ["fatigue", str(ROOT / "cases" / "sen_fatigue_2d.yaml"), "-o", str(tmp_path)]
    status, error, _ = _run([*argv, "--set", "output.plots=false"], capsys)
    assert status == 143
    assert error["error"].startswith("interrupted (SIGTERM) while ")
    assert read_status(tmp_path) == error["error"].replace(" (SIGTERM)", "")
    assert not (tmp_path / "fatigue.json").exists()
