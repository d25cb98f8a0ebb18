"""``peridyn study`` runs its levels as a sweep (issue 21, item 5): the process pool gives the serial
study's results, a second study into the same folder runs no finished level again, and a level
that fails is reported and left out of the fits, or the study refuses when too few levels remain.

The levels are the 96 x 48 x 8 mm PMMA plate of tests/simulation/test_study.py at 4 mm spacing
(576 points, about a second each) with horizons of 1.4143, 2.001 and 3.001 spacings: a ``delta``
series (spacing fixed, horizon -> 0) of three levels. On two layers of points its modes do not
converge monotonically, so each fit reports why it has no limit (with the frequencies); the fits
with limits of a real study are checked in tests/simulation/test_study.py.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import peridyn
from peridyn.cli import main
from peridyn.errors import PeridynError
from peridyn.jobs.sweep_run import RECORD, THREAD_ENV, threads_per_worker

pytest.importorskip("xarray", reason="a study's levels are a sweep: it needs the sweep extra")
ROOT = Path(__file__).resolve().parents[2]
SRC = str(Path(peridyn.__file__).parents[1])
CASE = str(ROOT / "cases" / "pmma_plate.yaml")
LEVELS = [
    CASE,
    "--set",
    "geometry.size=[0.096,0.048,0.008]",
    "--spacing",
    "4e-3",
    "--horizon",
    "1.4143,2.001,3.001",
    "--series",
    "delta",
]
#: Keys that depend on the machine, the moment, the folder or the executor, not on the numbers.
VOLATILE = ("seconds", "output_dir", "plots", "peak_memory_bytes", "sweep")


def _study(argv) -> tuple[int, dict]:
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        status = main(["study", *argv, "--json"])
    return status, json.loads(out.getvalue())


def _numbers(summary: dict) -> dict:
    """The summary without what may differ between two equal studies (times, folders)."""
    kept = {k: v for k, v in summary.items() if k not in VOLATILE}
    kept["runs"] = [{k: v for k, v in r.items() if k != "seconds"} for r in summary["runs"]]
    return kept


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    out = tmp_path_factory.mktemp("study") / "serial"
    status, summary = _study([*LEVELS, "-o", str(out)])
    assert status == 0
    return out, summary


def test_the_levels_are_the_runs_of_a_sweep(serial):
    """Each level in its own folder with its record, all in the sweep's dataset; the study's
    modes of a level are those of the level's own modal run (modes.json there)."""
    from peridyn.io.dataset import load_sweep

    out, summary = serial
    assert summary["sweep"]["runs"] == summary["sweep"]["completed"] == 3
    records = [json.loads(p.read_text()) for p in out.glob(f"runs/*/{RECORD}")]
    assert len(records) == 3 and {r["status"] for r in records} == {"complete"}
    assert list(load_sweep(out / "dataset.nc")["status"].values) == ["complete"] * 3
    for run in summary["runs"]:
        record = next(
            r for r in records if r["parameters"]["discretization.horizon"] == run["horizon_factor"]
        )
        rows = json.loads((out / "runs" / record["run_id"] / "modes.json").read_text())
        assert run["modes"]["1st bending"] == next(
            r["frequency_hz"] for r in rows if r["label"] == "1st bending"
        )
    assert all(len(f["x"]) == 3 for f in summary["fits"] if f["mode"] == "1st bending")


@pytest.mark.slow  # about 20 s: a serial study in its own process and a pool of two spawned workers
def test_the_process_pool_gives_the_serial_results(tmp_path):
    """Each pool worker of two runs with cores // 2 numba and BLAS threads; the serial study is run
    with as many (the BLAS thread count changes the last bits of the eigensolver's frequencies),
    in its own process; the two summaries must then agree bit for bit."""
    threads = str(threads_per_worker(2))
    env = {**os.environ, "PYTHONPATH": SRC, **dict.fromkeys(THREAD_ENV, threads)}
    serial_out = tmp_path / "serial"
    command = [sys.executable, "-m", "peridyn", "study", *LEVELS, "-o", str(serial_out), "--json"]
    done = subprocess.run(command, env=env, capture_output=True, text=True, check=True)
    status, pooled = _study(
        [*LEVELS, "-o", str(tmp_path / "pool"), "--executor", "processes", "--workers", "2"]
    )
    assert status == 0 and pooled["sweep"]["executor"] == "processes"
    assert _numbers(pooled) == _numbers(json.loads(done.stdout))


def test_a_second_study_runs_no_finished_level_again(serial, capsys):
    """Another series over the same levels: only the analysis is done again."""
    out, summary = serial
    stamps = {p: p.stat().st_mtime_ns for p in out.glob("runs/*/*")}
    status, again = _study([*LEVELS[:-1], "delta,delta-m", "-o", str(out)])
    assert status == 0
    assert (again["sweep"]["skipped"], again["sweep"]["completed"]) == (3, 3)
    assert {p: p.stat().st_mtime_ns for p in stamps} == stamps  # no level was written again
    assert again["runs"] == summary["runs"]
    assert [f for f in again["fits"] if f["series"] == "delta"] == summary["fits"]
    assert "3 of 3 levels already complete" in capsys.readouterr().err


@pytest.fixture
def widest_fails(monkeypatch):
    """The modal solve of the 3.001 h level raises (as an eigensolver that does not converge)."""
    import peridyn.jobs.modal

    real = peridyn.jobs.modal.modal_analysis

    def failing(model, *args, **kwargs):
        if model.bonds.horizon > 2.5 * model.body.spacing:
            raise PeridynError("the eigensolver did not converge (test)")
        return real(model, *args, **kwargs)

    monkeypatch.setattr(peridyn.jobs.modal, "modal_analysis", failing)


def test_a_failed_level_is_reported_and_left_out_of_the_fits(widest_fails, tmp_path, capsys):
    argv = [*LEVELS[:6], "1.4143,2.001,3.001,2.401", *LEVELS[7:], "-o", str(tmp_path)]
    status = main(["study", *argv])
    captured = capsys.readouterr()
    assert status == 0
    assert "[3/4] spacing 4 mm, horizon 3.001 h: 576 points" not in captured.err  # no summary: failed
    assert "horizon 3.001 h: " in captured.err and "failed: the eigensolver did not converge" in captured.err
    assert "level spacing 4 mm, horizon 3.001 h left out: failed: the eigensolver" in captured.out
    assert "the fits use the other 3 levels" in captured.out
    summary = json.loads((tmp_path / "study.json").read_text())
    assert summary["skipped_runs"] == 1 and summary["sweep"]["failed"] == 1
    assert all(3.001 * 4e-3 not in f["x"] for f in summary["fits"])  # the failed horizon, m
    bending = next(f for f in summary["fits"] if f["mode"] == "1st bending")
    assert bending["x"] == [1.4143 * 4e-3, 2.001 * 4e-3, 2.401 * 4e-3]  # the three other levels, m


def test_too_few_levels_left_is_refused_naming_the_failed_one(widest_fails, tmp_path, capsys):
    status = main(["study", *LEVELS, "-o", str(tmp_path)])
    err = capsys.readouterr().err
    assert status == 1
    line = err.strip().splitlines()[-1]
    assert line.startswith("peridyn study: error: 1 of 3 levels did not complete, leaving no series")
    assert "spacing 4 mm, horizon 3.001 h: failed: the eigensolver did not converge (test)" in line
    assert not (tmp_path / "study.json").exists()
    assert json.loads((tmp_path / "status.json").read_text())["status"].startswith("failed: 1 of 3 levels")
