"""The command line in a real process: a real SIGINT, a real full disk, a closed pipe; one line
each and no Python traceback (issue 17, item 1)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from peridyn.cli import main

ROOT = Path(__file__).resolve().parents[3]
LAMB = ["lamb", "--E", "2e11", "--nu", "0.3", "--rho", "7800", "--thickness", "0.002", "--freq", "1e5"]


def _peridyn(args: list[str], **kwargs) -> subprocess.Popen:
    """``python -m peridyn ARGS`` from the repository root with this checkout's package."""
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    return subprocess.Popen([sys.executable, "-m", "peridyn", *args], cwd=ROOT, env=env, text=True, **kwargs)


def _no_traceback(err: str) -> None:
    assert "Traceback" not in err and "Exception ignored" not in err, err


def test_sigint_while_the_bonds_are_searched_is_one_line_and_exit_130(tmp_path):
    """SIGINT a second after the run's banner: the 160 000-point bar is still being built (its bond
    search alone takes several seconds here), outside any step loop. Python's raising handler
    killed the process here (SIGSEGV inside the parallel bond search); the job's handler only notes
    the signal and the build stops after its phase (``peridyn.interrupts``)."""
    proc = _peridyn(
        ["run", "cases/bar_pulse.yaml", "-o", str(tmp_path), "--set", "discretization.spacing=5e-4"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    banner = proc.stderr.readline()
    assert "case 'bar_pulse'" in banner, banner
    time.sleep(1.0)
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=60)
    _no_traceback(err)
    assert proc.returncode == 130
    assert err.splitlines() == ["peridyn run: interrupted (SIGINT) while building the model"]
    assert out == ""


def test_stdout_on_a_full_device_is_one_line(tmp_path):
    """/dev/full as stdout: the JSON summary cannot be written (ENOSPC)."""
    with open("/dev/full", "w") as full:
        proc = _peridyn([*LAMB, "--json"], stdout=full, stderr=subprocess.PIPE)
        _, err = proc.communicate(timeout=120)
    _no_traceback(err)
    assert proc.returncode == 1
    assert err.splitlines() == [f"peridyn lamb: error: <stdout>: {os.strerror(28)}"]


def test_a_closed_pipe_is_one_line():
    """The reader of stdout went away before the table was written (EPIPE)."""
    proc = _peridyn(LAMB, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    proc.stdout.close()
    err = proc.stderr.read()
    proc.wait(timeout=120)
    _no_traceback(err)
    assert proc.returncode == 1 and err.splitlines() == [f"peridyn lamb: error: <stdout>: {os.strerror(32)}"]


@pytest.fixture
def tiny_disk(tmp_path):
    """A 64 KiB tmpfs (needs the right to mount: skipped elsewhere; the monkeypatched writer of
    test_cli_errors.py covers the same path everywhere)."""
    mount = tmp_path / "tiny"
    mount.mkdir()
    made = subprocess.run(
        ["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(mount)], capture_output=True, check=False
    )
    if made.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {made.stderr.decode().strip()}")
    try:
        yield mount
    finally:
        subprocess.run(["umount", str(mount)], check=True)


def _run_on(disk: Path, capsys) -> tuple[int, str]:
    """``peridyn run`` of the shortened bar into ``disk``/out: the exit status and stderr's last line."""
    argv = ["run", "cases/bar_pulse.yaml", "-o", str(disk / "out"), "--set", "solver.time=0.3e-6"]
    cwd = os.getcwd()
    os.chdir(ROOT)
    try:
        status = main([*argv, "--set", "output.plots=false"])
    finally:
        os.chdir(cwd)
    err = capsys.readouterr().err
    _no_traceback(err)
    return status, err.splitlines()[-1]


def test_a_run_that_cannot_fit_on_the_disk_is_refused_before_writing(tiny_disk, capsys):
    """The bar's records (about 10 MB with its snapshots) cannot fit on a 64 KiB disk: refused
    before the output folder is made (``jobs.run.check_output_fits``)."""
    status, line = _run_on(tiny_disk, capsys)
    assert status == 1 and "GB of results, more than the" in line
    assert not (tiny_disk / "out").exists()


def test_a_full_disk_during_a_run_names_the_file(tiny_disk, capsys, monkeypatch):
    """The disk fills during the run (another process may fill it after the check): one line,
    PATH: reason, the path a file of the output folder. The up-front check is switched off to
    get there."""
    import peridyn.jobs.run

    monkeypatch.setattr(peridyn.jobs.run, "check_output_fits", lambda *args: None)
    status, line = _run_on(tiny_disk, capsys)
    assert status == 1
    assert line.startswith(f"peridyn run: error: {tiny_disk / 'out'}/")
    assert line.endswith(f": {os.strerror(28)}")


@pytest.fixture
def small_disk(tmp_path):
    """A 14 MiB tmpfs: room for the bar's first snapshot and records, not for its last snapshot
    (skipped where mounting is not allowed; test_a_run_ends_cleanly_on_an_injected_enospc
    covers the same path everywhere)."""
    mount = tmp_path / "small"
    mount.mkdir()
    made = subprocess.run(
        ["mount", "-t", "tmpfs", "-o", "size=14m", "tmpfs", str(mount)], capture_output=True, check=False
    )
    if made.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {made.stderr.decode().strip()}")
    try:
        yield mount
    finally:
        subprocess.run(["umount", str(mount)], check=True)


#: A run with the up-front disk check switched off, as a process (a crash is its exit status).
FULL_DISK_RUN = """
import sys
import peridyn.jobs.run
from peridyn.cli import main

peridyn.jobs.run.check_output_fits = lambda *args: None
sys.exit(main(["run", "cases/bar_pulse.yaml", "-o", sys.argv[1], "--set", "solver.time=2e-6",
               "--set", "output.plots=false", "--no-progress"]))
"""


def test_a_disk_that_fills_during_a_run_ends_it_cleanly(small_disk):
    """A full disk during a run: segfault (exit 139), tracebacks, status stuck at ``running``.
    Now exit 1 with one line, the records held written, the status saying so, the file
    readable (its checksums agree)."""
    from peridyn.io.outdir import read_status
    from peridyn.io.results import Results

    out = small_disk / "out"
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    done = subprocess.run(
        [sys.executable, "-c", FULL_DISK_RUN, str(out)], cwd=ROOT, env=env, capture_output=True, text=True
    )
    _no_traceback(done.stderr)
    assert done.returncode == 1, done.stderr
    line = done.stderr.strip().splitlines()[-1]
    assert line.startswith(f"peridyn run: error: {out}/") and line.endswith(os.strerror(28))
    results = Results(out / "results.h5")
    assert results.status().startswith(f"failed: {os.strerror(28)} ({out}/")
    assert results.n_records("sensor_u") == 16  # every 2 steps from 0 to 30: none lost
    assert sorted(p.name for p in out.iterdir()) == [
        "provenance.json",
        "results.h5",
        "run.log",
        "snapshots",
        "snapshots.pvd",
        "status.json",
    ]
    assert read_status(out) == results.status()  # the output contract's status says the same


def test_a_run_ends_cleanly_on_an_injected_enospc(tmp_path, capsys, monkeypatch):
    """The same without a small disk: the disk reports no room from the 5th write on."""
    import shutil as real_shutil

    import peridyn.io.reserve as reserve
    import peridyn.jobs.run
    from peridyn.io.results import Results

    monkeypatch.setattr(peridyn.jobs.run, "check_output_fits", lambda *args: None)
    calls = []

    class Shutil:
        @staticmethod
        def disk_usage(path):
            calls.append(path)
            usage = real_shutil.disk_usage(path)
            return usage._replace(free=0) if len(calls) >= 5 else usage

    monkeypatch.setattr(reserve, "shutil", Shutil)
    status, line = _run_on(tmp_path, capsys)
    assert status == 1 and line.endswith(f": {os.strerror(28)}")
    results = Results(tmp_path / "out" / "results.h5")
    assert results.status().startswith(f"failed: {os.strerror(28)} (")


def test_a_closed_stdout_or_stderr_runs_the_command(tmp_path):
    """``>&-`` gave an internal error and two tracebacks; ``2>&-`` must not stop a command either."""
    import json
    import shlex

    base = f"{shlex.quote(sys.executable)} -m peridyn"
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    for redirect in (">&-", "2>&-", ">&- 2>&-"):
        done = subprocess.run(
            f"{base} {' '.join(LAMB)} --json {redirect}", shell=True, cwd=ROOT, env=env, capture_output=True
        )
        assert done.returncode == 0, (redirect, done.stderr)
        _no_traceback(done.stderr.decode())
        if redirect == "2>&-":
            assert [m["mode"] for m in json.loads(done.stdout)["modes"]][:2] == ["S0", "A0"]
    failed = subprocess.run(
        f"{base} validate missing.yaml >&-", shell=True, cwd=ROOT, env=env, capture_output=True
    )
    assert failed.returncode == 1
    lines = failed.stderr.decode().splitlines()
    assert len(lines) == 1 and lines[0].startswith("peridyn validate: error: missing.yaml: ")


def test_a_broken_stderr_keeps_the_json_error_on_stdout():
    """The reader of stderr went away (EPIPE): the error is still one JSON object on stdout."""
    import json

    proc = _peridyn(["validate", "missing.yaml", "--json"], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    proc.stderr.close()
    out, _ = proc.communicate(timeout=120)
    assert proc.returncode == 1
    assert "missing.yaml" in json.loads(out)["error"]
