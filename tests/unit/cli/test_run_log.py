"""A job tells where it is: Python logging records of the ``peridyn`` loggers, a heartbeat line at a
steady interval when no progress bar is shown (stderr not a terminal), and ``run.log`` in the
output folder with the job's start, heartbeat and end, stamped in UTC."""

from __future__ import annotations

import logging
import re
from pathlib import Path

from peridyn.cli import main
from peridyn.cli.logs import Heartbeat

BAR = str(Path(__file__).resolve().parents[3] / "cases" / "bar_pulse.yaml")
#: The bar pulse on a coarse grid for 2 us: 13 steps, about a second.
SHORT = ["--set", "discretization.spacing=2.5e-3", "--set", "solver.time=2e-6", "--set", "output.plots=false"]


def test_heartbeat_logs_at_its_interval_with_the_time_left(caplog):
    """A fake clock advancing 10 s a step and a 30 s interval: lines after steps 3, 6 and 9 of
    10, each with the share done and the time left at the rate so far."""
    now = [0.0]

    def clock():
        return now[0]

    beat = Heartbeat(10, "bar", 30.0, clock)
    with caplog.at_level(logging.INFO, logger="peridyn"):
        for _ in range(10):
            now[0] += 10.0
            beat.update(1)
        beat.close()
    lines = [r.getMessage() for r in caplog.records if r.name == "peridyn.cli.logs"]
    assert lines == [
        "bar: step 3 of 10 (30 %), 30 s, about 70 s left",
        "bar: step 6 of 10 (60 %), 60 s, about 40 s left",
        "bar: step 9 of 10 (90 %), 90 s, about 10 s left",
    ]


def test_a_run_writes_run_log_with_its_start_heartbeat_and_end(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("PERIDYN_HEARTBEAT_SECONDS", "0")  # a line after every step
    out = tmp_path / "bar"
    assert main(["run", BAR, "-o", str(out), *SHORT]) == 0
    err = capsys.readouterr().err
    assert "bar_pulse: step 13 of 13 (100 %)" in err
    log = (out / "run.log").read_text().splitlines()
    stamp = r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ"
    assert all(re.match(rf"{stamp} (INFO|WARNING) peridyn\.[a-z_.]+: ", line) for line in log), log
    assert re.search(r"INFO peridyn\.jobs\.run: case 'bar_pulse' \(explicit, 1280 points\) into ", log[0])
    beats = [line for line in log if "peridyn.cli.logs: bar_pulse: step" in line]
    assert len(beats) == 13
    assert "INFO peridyn.jobs.run: case 'bar_pulse' complete in" in log[-1]
    # a second run into the folder appends to the log
    assert main(["run", BAR, "-o", str(out), "--overwrite", *SHORT]) == 0
    assert len((out / "run.log").read_text().splitlines()) == 2 * len(log)
