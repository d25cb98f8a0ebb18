"""Fuzzing a run's faults: a disk that fills or fails (ENOSPC, EIO) at a random write, and
SIGINT, SIGTERM or SIGHUP at a random time of a real ``python -m peridyn run`` process.

The contract (docs/user-guide.md, "Errors" and "Signals"): the run ends with exit status 0 (it
finished first), 1 (the disk; one line ``PATH: reason``) or 128 + the signal, never a traceback
(a signal in the interpreter's own start, before peridyn is imported, ends it as Python does,
with nothing written);
the results file is closed and readable with a status that says how the run ended; no process of
the run outlives it; an earlier run in the same parent folder keeps every byte. Seeded: a
failure names its seed. Counts: ``pytest -s``.
"""

from __future__ import annotations

import errno
import io
import os
import random
import signal
import subprocess
import sys
import time
import warnings
from pathlib import Path

import h5py
import pytest
import yaml
from fuzz_contract import check_unchanged, fingerprint, report, tally
from fuzz_mutations import ROOT

import peridyn.io.exodus_write as exodus_write
import peridyn.io.reserve as reserve
from peridyn.cli import main
from peridyn.io.reserve import RESERVE_FILE
from peridyn.io.results import Results

#: HDF5's report of a failed write(2) (h5py 3, abridged), with the errno to inject.
HDF5_FAILURE = (
    "Can't synchronously write data (file write failed: errno = {number}, error message = '{text}')"
)
#: Exit statuses of a run ended by SIGHUP, SIGINT, SIGTERM (128 + the signal).
SIGNAL_STATUS = {signal.SIGHUP: 129, signal.SIGINT: 130, signal.SIGTERM: 143}


def tiny_case(folder: Path, time_s: float = 1.0e-6) -> Path:
    """The bar of cases/bar_pulse.yaml at 5 mm spacing for ``time_s``, a snapshot each step,
    Exodus output."""
    raw = yaml.safe_load((ROOT / "cases" / "bar_pulse.yaml").read_text())
    raw["discretization"]["spacing"] = 5.0e-3
    raw["solver"]["time"] = time_s
    raw["output"].update(plots=False, vtu=False, exodus=True, snapshot_every=1, snapshot_times=[])
    case = folder / "tiny.yaml"
    case.write_text(yaml.safe_dump(raw))
    return case


@pytest.fixture(scope="module")
def parent(tmp_path_factory) -> tuple[Path, Path]:
    """A folder holding an earlier finished run (``earlier``) and the case file."""
    root = tmp_path_factory.mktemp("faults")
    case = tiny_case(root)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert main(["run", str(case), "-o", str(root / "earlier"), "--no-progress"]) == 0
    return root, case


class _FailingFile(io.FileIO):
    """An Exodus file whose record writes fail with ``number`` from the ``after``-th on."""

    after, number = 0, errno.ENOSPC

    def write(self, data):
        if len(data) > 8:
            _FailingFile.after -= 1
            if _FailingFile.after < 0:
                raise OSError(_FailingFile.number, os.strerror(_FailingFile.number))
        return super().write(data)


def inject(monkeypatch, where: str, number: int, after: int) -> None:
    """Make the disk fail with ``number`` from the ``after``-th write of ``where`` on: the free
    space the results and snapshot writes check (``reserve``), HDF5's writes (``hdf5``), or the
    Exodus file's records (``exodus``)."""
    calls = [0]
    if where == "reserve":
        real = reserve.shutil.disk_usage

        class Shutil:
            @staticmethod
            def disk_usage(path):
                calls[0] += 1
                usage = real(path)
                return usage._replace(free=0) if calls[0] > after else usage

        monkeypatch.setattr(reserve, "shutil", Shutil)
    elif where == "hdf5":
        real_set = h5py.Dataset.__setitem__

        def failing(self, key, value):
            calls[0] += 1
            if calls[0] > after:
                raise OSError(HDF5_FAILURE.format(number=number, text=os.strerror(number)))
            return real_set(self, key, value)

        monkeypatch.setattr(h5py.Dataset, "__setitem__", failing)
    else:
        _FailingFile.after, _FailingFile.number = after, number
        monkeypatch.setattr(
            exodus_write,
            "open",
            lambda path, mode: io.BufferedRandom(_FailingFile(path, "r+")),
            raising=False,
        )


def fuzz_disk(n: int, parent: tuple[Path, Path], monkeypatch, capsys) -> None:
    """``n`` runs of the tiny case, each with its disk failing at a random write."""
    root, case = parent
    counts = tally("disk faults")
    before = fingerprint(root / "earlier")
    for seed in range(n):
        rng = random.Random(seed)
        where = rng.choice(["reserve", "hdf5", "hdf5", "exodus"])
        number = errno.ENOSPC if where == "reserve" else rng.choice([errno.ENOSPC, errno.EIO])
        after = rng.randrange(12)
        what = f"seed {seed}: {os.strerror(number)} at {where} write {after + 1}"
        out = root / f"run-{seed}"
        with monkeypatch.context() as m:
            inject(m, where, number, after)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                status = main(["run", str(case), "-o", str(out), "--no-progress"])
        err = capsys.readouterr().err
        counts["examples"] += 1
        if "Traceback" in err or "Exception ignored" in err or status not in (0, 1):
            counts["tracebacks"] += 1
            raise AssertionError(f"{what}: status {status}\n{err}")
        lines = err.strip().splitlines()
        assert all(line.startswith("peridyn") for line in lines), f"{what}: {err}"
        assert not (out / RESERVE_FILE).exists(), f"{what}: the reserve was left"
        if status == 1:
            counts["failed cleanly"] += 1
            assert lines[-1].endswith(f": {os.strerror(number)}") and f"{out}" in lines[-1], (
                f"{what}: {lines[-1]}"
            )
            if (out / "results.h5").exists():  # closed, readable, saying why
                assert Results(out / "results.h5").status().startswith(f"failed: {os.strerror(number)}"), what
        else:
            counts["finished"] += 1
            assert Results(out / "results.h5").status() == "complete", what
        check_unchanged("disk faults", before, root / "earlier", what)
    print("\n" + report("disk faults"))


def test_a_disk_failing_at_a_random_write_ends_the_run_cleanly(parent, monkeypatch, capsys):
    fuzz_disk(3, parent, monkeypatch, capsys)


@pytest.mark.slow
def test_a_disk_failing_at_a_random_write_ends_the_run_cleanly_many(parent, monkeypatch, capsys):
    fuzz_disk(60, parent, monkeypatch, capsys)


def _tagged(tag: str) -> list[int]:
    """Ids of the live processes whose environment holds ``PERIDYN_FUZZ_TAG=tag``."""
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                if f"PERIDYN_FUZZ_TAG={tag}".encode() in (entry / "environ").read_bytes().split(b"\0"):
                    found.append(int(entry.name))
            except OSError:  # gone, or not ours to read
                pass
    return found


def fuzz_signals(n: int, parent: tuple[Path, Path]) -> None:
    """``n`` runs of a 40-step bar in a process, each sent a random signal at a random time."""
    root, _ = parent
    folder = root / "signalled"
    folder.mkdir(exist_ok=True)
    case = tiny_case(folder, time_s=1.0e-5)
    counts = tally("signals")
    before = fingerprint(root / "earlier")
    for seed in range(n):
        rng = random.Random(seed)
        sig = rng.choice(list(SIGNAL_STATUS))
        delay = rng.uniform(1.5, 8.0)  # after the interpreter's start (below 1 s; peridyn's own)
        tag = f"{os.getpid()}-{seed}"
        out = root / f"signalled-{seed}"
        what = f"seed {seed}: {sig.name} after {delay:.2f} s"
        env = {**os.environ, "PYTHONPATH": str(ROOT / "src"), "PERIDYN_FUZZ_TAG": tag}
        proc = subprocess.Popen(
            [sys.executable, "-m", "peridyn", "run", str(case), "-o", str(out), "--no-progress"],
            env=env,
            stderr=subprocess.PIPE,
            stdout=subprocess.DEVNULL,
            text=True,
        )
        time.sleep(delay)
        proc.send_signal(sig)
        try:
            _, err = proc.communicate(timeout=60)
        except subprocess.TimeoutExpired:
            proc.kill()
            counts["hangs"] += 1
            raise AssertionError(f"{what}: no end 60 s after the signal") from None
        counts["examples"] += 1
        time.sleep(0.2)  # children see their parent gone
        left = _tagged(tag)
        for pid in left:
            os.kill(pid, signal.SIGKILL)
        if left:
            counts["orphans"] += 1
            raise AssertionError(f"{what}: processes {left} outlived the run")
        if proc.returncode == -sig and not out.exists():  # before peridyn's handlers: nothing begun
            counts["ended before starting"] += 1
            continue
        if "Traceback" in err or proc.returncode not in (0, SIGNAL_STATUS[sig]):
            counts["tracebacks"] += 1
            raise AssertionError(f"{what}: exit {proc.returncode}\n{err}")
        if (out / "results.h5").exists():
            status = Results(out / "results.h5").status()
            ok = status == "complete" if proc.returncode == 0 else status.startswith("interrupted")
            assert ok, f"{what}: exit {proc.returncode} with the status {status!r}"
        counts["finished" if proc.returncode == 0 else "interrupted"] += 1
        check_unchanged("signals", before, root / "earlier", what)
    print("\n" + report("signals"))


def test_a_signal_at_a_random_time_ends_the_run_cleanly(parent):
    fuzz_signals(1, parent)


@pytest.mark.slow
def test_a_signal_at_a_random_time_ends_the_run_cleanly_many(parent):
    fuzz_signals(12, parent)
