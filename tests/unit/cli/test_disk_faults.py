"""A failing disk during a run (an I/O error, EIO) and a full disk while the Exodus output is
written: one line naming the file, the status saying so, the files closed and readable (the
ENOSPC of the results file is in tests/unit/cli/test_cli_signals.py)."""

from __future__ import annotations

import errno
import io
import os
import warnings
from pathlib import Path

import h5py
import pytest
import yaml

import peridyn.io.exodus_write as exodus_write
from peridyn.cli import main
from peridyn.io.exodus import read_exodus
from peridyn.io.reserve import RESERVE_FILE
from peridyn.io.results import Results

ROOT = Path(__file__).resolve().parents[3]
#: HDF5's report of a failed write(2) as h5py raises it (h5py 3, abridged; errno 5 is EIO).
HDF5_EIO = (
    "Can't synchronously write data (file write failed: time = Sun Nov 29 12:00:00 2026, filename = "
    "'{path}', file descriptor = 5, errno = 5, error message = 'Input/output error', buf = 0x1, "
    "total write size = 4096, bytes this sub-write = 4096, bytes actually written = "
    "18446744073709551615, offset = 0)"
)


@pytest.fixture
def tiny_case(tmp_path) -> Path:
    """The bar of cases/bar_pulse.yaml at 5 mm spacing (160 points, 4 steps), a snapshot each
    step, Exodus output, no figures."""
    raw = yaml.safe_load((ROOT / "cases" / "bar_pulse.yaml").read_text())
    raw["discretization"]["spacing"] = 5.0e-3
    raw["solver"]["time"] = 1.0e-6
    raw["output"].update(plots=False, vtu=False, exodus=True, snapshot_every=1, snapshot_times=[])
    case = tmp_path / "tiny.yaml"
    case.write_text(yaml.safe_dump(raw))
    return case


def _run(case: Path, out: Path, capsys) -> tuple[int, list[str]]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        status = main(["run", str(case), "-o", str(out), "--no-progress"])
    err = capsys.readouterr().err
    assert "Traceback" not in err and "Exception ignored" not in err, err
    return status, err.strip().splitlines()


def test_an_io_error_during_a_run_ends_it_with_one_line_and_its_status(
    tiny_case, tmp_path, capsys, monkeypatch
):
    """The disk fails the 3rd write of the results' series with EIO, as HDF5 reports it: exit 1,
    ``PATH: Input/output error``, the status ``failed: Input/output error (PATH)``, the reserve
    given back and the file closed with its checksums right."""
    out = tmp_path / "out"
    real = h5py.Dataset.__setitem__
    writes = []

    def failing(self, key, value):
        writes.append(self.name)
        if len(writes) == 3:
            raise OSError(HDF5_EIO.format(path=out / "results.h5"))
        return real(self, key, value)

    monkeypatch.setattr(h5py.Dataset, "__setitem__", failing)
    status, lines = _run(tiny_case, out, capsys)
    monkeypatch.undo()
    assert status == 1 and len(writes) >= 3
    assert lines[-1] == f"peridyn run: error: {out / 'results.h5'}: {os.strerror(errno.EIO)}"
    results = Results(out / "results.h5")  # opens: every dataset matches its checksum
    assert results.status() == f"failed: {os.strerror(errno.EIO)} ({out / 'results.h5'})"
    assert not (out / RESERVE_FILE).exists()


class _FullDisk(io.FileIO):
    """A file whose writes of more than 8 bytes fail with ENOSPC after ``ok`` of them."""

    ok = 0

    def write(self, data):
        if len(data) > 8:
            if _FullDisk.ok == 0:
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
            _FullDisk.ok -= 1
        return super().write(data)


def test_a_full_disk_while_the_exodus_output_is_written_keeps_its_steps(
    tiny_case, tmp_path, capsys, monkeypatch
):
    """The disk fills while the 3rd Exodus step is appended (two appends after the file's first
    step succeed, the third fails in write(2)): exit 1 naming results.e, the status saying so,
    results.e readable with its 3 whole steps (the failed one neither counted nor half-kept) and
    results.h5 closed."""
    out = tmp_path / "out"
    _FullDisk.ok = 2

    def opened(path, mode="r", *args, **kwargs):
        assert mode == "r+b"
        return io.BufferedRandom(_FullDisk(path, "r+"))

    monkeypatch.setattr(exodus_write, "open", opened, raising=False)
    status, lines = _run(tiny_case, out, capsys)
    monkeypatch.undo()
    exodus = out / "results.e"
    assert status == 1
    assert lines[-1] == f"peridyn run: error: {exodus}: {os.strerror(errno.ENOSPC)}"
    assert Results(out / "results.h5").status() == f"failed: {os.strerror(errno.ENOSPC)} ({exodus})"
    mesh = read_exodus(exodus)
    assert len(mesh.times) == 3
    assert not (out / RESERVE_FILE).exists()
