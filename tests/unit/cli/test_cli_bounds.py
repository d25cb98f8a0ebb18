"""Bounds on what a command reads and holds, and messages that fit the command: an endless or
huge case file, a Rayleigh-Lamb search beyond memory, advice of another command, a resume
hint that cannot work."""

from __future__ import annotations

import math
import time
import tracemalloc

import pytest

import peridyn.analysis.lamb as lamb
import peridyn.cli.run_cmd as run_cmd
from peridyn.cli import main
from peridyn.cli.errors import describe
from peridyn.errors import InputError
from peridyn.io.outdir import prepare_output
from peridyn.io.text_file import MAX_BYTES
from peridyn.jobs.run import _resume_hint

LAMB = ["lamb", "--E", "2e11", "--nu", "0.3", "--rho", "7800", "--thickness", "0.002"]


@pytest.mark.parametrize("command", ["run", "validate"])
def test_a_device_as_case_file_is_refused_at_once(command, capsys):
    """``peridyn run /dev/zero`` read until the memory ran out."""
    start = time.perf_counter()
    assert main([command, "/dev/zero"]) == 1
    assert time.perf_counter() - start < 5.0  # nothing read: the build alone takes longer
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1] == (
        f"peridyn {command}: error: /dev/zero: <file> = None: a YAML case file (a regular file, not a "
        "device or pipe)"
    )


def test_a_case_file_over_the_limit_is_refused(tmp_path, capsys):
    big = tmp_path / "big.yaml"
    big.write_bytes(b"#" * (MAX_BYTES + 1))
    assert main(["validate", str(big)]) == 1
    assert f"at most 16 MiB (this one holds {MAX_BYTES + 1} bytes)" in capsys.readouterr().err


def test_the_lamb_scan_estimate_bounds_its_measured_peak():
    """``SCAN_BYTES`` a scan point against tracemalloc's peak of the whole search at 100 MHz (6 801
    scan points, 197 modes): the estimate is above the peak and within a factor 2 of it."""
    plate = lamb._plate(2e11, 0.3, 7800, 0.002)
    points = lamb.scan_points(plate, 2 * math.pi * 1e8)
    assert points == len(lamb._scan_grid(plate, 2 * math.pi * 1e8))
    tracemalloc.start()
    lamb.lamb_modes(2e11, 0.3, 7800, 0.002, 1e8)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert 0.5 * lamb.SCAN_BYTES * points < peak < lamb.SCAN_BYTES * points


def test_lamb_beyond_memory_is_refused_before_allocating(monkeypatch, capsys):
    """``peridyn lamb --freq 1e12`` took 20 GB until the kernel killed it: now refused at once,
    with advice of lamb's own (no discretization spacing)."""
    monkeypatch.setattr(lamb.geometry, "memory_limit", lambda: 16e9)
    start = time.perf_counter()
    assert main([*LAMB, "--freq", "1e12"]) == 1
    assert time.perf_counter() - start < 5.0
    line = capsys.readouterr().err.strip().splitlines()[-1]
    assert line.startswith("peridyn lamb: error: the Rayleigh-Lamb modes at 1e+12 Hz in a 0.002 m plate")
    assert "32 GB, more than the 16 GB" in line and "spacing" not in line


def test_out_of_memory_advice_fits_the_command():
    assert "spacing" in describe(MemoryError(), "peridyn run")[0]
    assert "spacing" not in describe(MemoryError(), "peridyn lamb")[0]
    assert "spacing" not in describe(MemoryError(), "peridyn dispersion")[0]


def test_the_demo_gives_no_restart_hint(tmp_path):
    """``peridyn demo`` has no --restart: neither its interruption nor its refusal of an earlier
    run's folder may suggest it."""
    assert _resume_hint("") == ""
    assert _resume_hint("peridyn run c.yaml").endswith("--restart")
    (tmp_path / "results.h5").write_bytes(b"")
    with pytest.raises(InputError) as info:
        prepare_output(tmp_path, "results.h5", restartable=False)
    assert "--overwrite" in str(info.value) and "--restart" not in str(info.value)


def test_the_mpi_resume_hint_keeps_the_launcher(monkeypatch):
    """Under ``mpiexec -n 3`` the hint said ``peridyn run ... --restart``: a serial run."""

    class Three:
        size = 3

    monkeypatch.setattr(run_cmd, "world", lambda: Three())
    line = run_cmd.command_line(["run", "c.yaml", "--overwrite", "-o", "out"])
    assert line == "mpiexec -n 3 peridyn run c.yaml -o out"
    assert _resume_hint(line) == "mpiexec -n 3 peridyn run c.yaml -o out --restart"
